//! Skipped tests that a person sees.
//!
//! A test that needs what the machine may lack (a GPU adapter, a display) returns early and so
//! passes; libtest then drops everything it printed with `print!` / `eprint!`, so an
//! `eprintln!("SKIPPED …")` is never shown and the test reads as run. [`report_skip`] makes the
//! skip visible in two ways:
//!
//! * it writes `SKIPPED <test>: <reason>` to the process's standard error with
//!   `std::io::stderr().write_all`. libtest's capture only redirects the `print!` family, not
//!   writes to the stderr handle, so the line appears in the output of a plain `cargo test`
//!   among the `test … ok` lines. (Should a future libtest capture these writes too, the line
//!   would be hidden again; the log below does not depend on it.)
//! * when `FACET_SKIP_LOG` names a file, it appends the same line to it (creating it), one
//!   `write` per line in append mode, so that tests running in parallel threads and processes
//!   do not mix their lines. `.ci/run` points it at a fresh file and prints the file after
//!   `cargo test`; by hand: `FACET_SKIP_LOG=/tmp/skips.txt cargo test --workspace`, then read
//!   the file (an empty or missing file: nothing skipped). A file that cannot be written
//!   fails the test rather than losing the skip.
//!
//! Whether a skip should fail instead (`FACET_REQUIRE_GPU=1`, `FACET_REQUIRE_DISPLAY=1`) is
//! the caller's decision, made before it calls this.

use std::io::Write;

/// The environment variable naming the file that skips are appended to.
pub const SKIP_LOG_VAR: &str = "FACET_SKIP_LOG";

/// Reports that `test` did not run because of `reason`: a `SKIPPED <test>: <reason>` line on
/// the terminal (uncaptured, see the module doc) and in the `FACET_SKIP_LOG` file if that is
/// set. Panics if the log file cannot be written.
pub fn report_skip(test: &str, reason: &str) {
    let reason = reason.replace('\n', " ");
    let line = format!("SKIPPED {test}: {reason}\n");
    // Best effort: a closed stderr must not turn a skip into a failure.
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
    if let Some(path) = std::env::var_os(SKIP_LOG_VAR).filter(|p| !p.is_empty()) {
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .and_then(|mut f| f.write_all(line.as_bytes()))
            .unwrap_or_else(|e| {
                panic!(
                    "{test}: {SKIP_LOG_VAR}={}: cannot record the skip ({e})",
                    std::path::Path::new(&path).display()
                )
            });
    }
}
