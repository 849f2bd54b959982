//! The harness: PRNG, panic capture, the watched worker.

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Once;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::{Duration, Instant};

/// One call of a loader that takes longer than this is a hang.
pub const CALL_BUDGET: Duration = Duration::from_secs(5);

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, deterministic, good enough to pick mutations.
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }

    /// True with probability `percent` / 100.
    pub fn percent(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }

    pub fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[self.below(xs.len())]
    }
}

thread_local! {
    /// Set on the worker threads: their panics are recorded instead of printed.
    static CAPTURE: Cell<bool> = const { Cell::new(false) };
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
}

/// A panic hook that records the message and location of a worker's panic (thousands of
/// caught panics would otherwise flood the output) and leaves other threads' panics alone.
fn install_panic_capture() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if CAPTURE.get() {
                LAST_PANIC.with_borrow_mut(|s| *s = info.to_string().replace('\n', " "));
            } else {
                default(info)
            }
        }));
    });
}

/// A loader under test with its seeds and the current mutated input.
pub trait Target: Send + 'static {
    /// Makes the next case's input from the seeds; returns how it was made.
    fn mutate(&mut self, rng: &mut SplitMix64) -> String;
    /// The loader on the current input. `Ok(true)`: accepted and sane; `Ok(false)`: refused
    /// with an error naming the path; `Err`: what is wrong.
    fn call(&mut self) -> Result<bool, String>;
    /// The current input as saved with a failure (MERL saves its recipe instead of 35 MB).
    fn input(&self) -> Vec<u8>;
    /// Undoes an in-place mutation.
    fn restore(&mut self) {}
}

#[derive(Default)]
struct Summary {
    cases: usize,
    accepted: usize,
    refused: usize,
    setup: Duration,
    run: Duration,
    /// Distinct failures by signature: (count, first example).
    failures: BTreeMap<String, (usize, String)>,
}

enum Msg {
    Case(usize, String),
    Done(Summary),
}

/// Where failing inputs are saved.
pub fn save_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("loader_mutation");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// What makes two failures the same: the panic's location, else the problem up to its first
/// `=`, `(`, `[` or a backquote (names), without digits.
fn signature(problem: &str) -> String {
    if let Some(at) = problem.find("panicked at ") {
        let rest = &problem[at..];
        return rest[..rest.find(": ").unwrap_or(rest.len())].to_string();
    }
    let head = &problem[..problem.find(['=', '(', '[', '`']).unwrap_or(problem.len())];
    head.chars()
        .filter(|c| !c.is_ascii_digit())
        .take(120)
        .collect()
}

/// Runs `cases` mutated inputs of the target that `setup` builds (on the worker, timed apart)
/// and fails the test with every distinct problem found; a case that does not return within
/// twice [`CALL_BUDGET`] fails it as a hang.
pub fn campaign<T: Target>(
    name: &'static str,
    seed: u64,
    cases: usize,
    setup: impl FnOnce() -> T + Send + 'static,
) {
    install_panic_capture();
    // Longer or other runs, to explore: LOADER_MUTATION_SCALE=10, LOADER_MUTATION_SEED=7.
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let cases = cases * env("LOADER_MUTATION_SCALE").unwrap_or(1) as usize;
    let seed = seed ^ env("LOADER_MUTATION_SEED").unwrap_or(0);
    let save_case: Option<usize> = std::env::var("LOADER_MUTATION_SAVE").ok().and_then(|v| {
        let (n, c) = v.split_once(':')?;
        (n == name).then(|| c.parse().ok())?
    });
    let trace = std::env::var_os("LOADER_MUTATION_TRACE").is_some();
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name(format!("mutate-{name}"))
        .stack_size(8 << 20) // a main thread's, where the loaders run in the CLI
        .spawn(move || {
            let t0 = Instant::now();
            let mut target = setup();
            let mut s = Summary {
                setup: t0.elapsed(),
                ..Summary::default()
            };
            let t1 = Instant::now();
            let mut rng = SplitMix64(seed);
            CAPTURE.set(true);
            for case in 0..cases {
                let how = target.mutate(&mut rng);
                if tx.send(Msg::Case(case, how.clone())).is_err() {
                    return;
                }
                if trace {
                    eprintln!("{name} case {case}: {how}");
                }
                if save_case == Some(case) {
                    let file = save_dir().join(format!("{name}-case{case}.bin"));
                    std::fs::write(&file, target.input()).unwrap();
                    eprintln!("{name} case {case} ({how}) saved to {}", file.display());
                }
                let start = Instant::now();
                let verdict = catch_unwind(AssertUnwindSafe(|| target.call()));
                let took = start.elapsed();
                let problem = match verdict {
                    Ok(Ok(true)) => {
                        s.accepted += 1;
                        None
                    }
                    Ok(Ok(false)) => {
                        s.refused += 1;
                        None
                    }
                    Ok(Err(p)) => Some(p),
                    Err(_) => Some(LAST_PANIC.with_borrow_mut(std::mem::take)),
                };
                let problem = problem.or_else(|| {
                    (took > CALL_BUDGET)
                        .then(|| format!("took {took:.1?}, over the {CALL_BUDGET:?} budget"))
                });
                if let Some(problem) = problem {
                    let entry = s
                        .failures
                        .entry(signature(&problem))
                        .or_insert((0, String::new()));
                    entry.0 += 1;
                    if entry.0 == 1 {
                        let file = save_dir().join(format!("{name}-case{case}.bin"));
                        std::fs::write(&file, target.input()).unwrap();
                        entry.1 = format!(
                            "case {case} ({how}): {problem}\n    input: {}",
                            file.display()
                        );
                    }
                }
                s.cases += 1;
                target.restore();
            }
            s.run = t1.elapsed();
            let _ = tx.send(Msg::Done(s));
        })
        .unwrap();
    let mut current: Option<(usize, String)> = None;
    let s = loop {
        // Building the seeds may wait for another loader's (the MERL table is shared).
        let wait = match current {
            None => Duration::from_secs(600),
            Some(_) => 2 * CALL_BUDGET,
        };
        match rx.recv_timeout(wait) {
            Ok(Msg::Case(i, how)) => current = Some((i, how)),
            Ok(Msg::Done(s)) => break s,
            Err(RecvTimeoutError::Timeout) => {
                let (i, how) = current.unwrap_or((0, "building the seeds".into()));
                panic!(
                    "{name}: case {i} ({how}) has not returned after {wait:?}: a hang \
                     (LOADER_MUTATION_SAVE={name}:{i} saves its input)"
                );
            }
            Err(RecvTimeoutError::Disconnected) => panic!("{name}: the worker died"),
        }
    };
    println!(
        "{name}: {} cases ({} accepted, {} refused) in {:.1?}, seeds built in {:.1?}",
        s.cases, s.accepted, s.refused, s.run, s.setup
    );
    if !s.failures.is_empty() {
        let mut report = format!("{name}: {} distinct failure(s):\n", s.failures.len());
        for (count, example) in s.failures.values() {
            let _ = writeln!(report, "  ×{count}: {example}");
        }
        panic!("{report}");
    }
}

/// `Ok(false)` when the error's message names `path`, else what is wrong with it.
pub fn refused(path: &Path, e: impl std::fmt::Display) -> Result<bool, String> {
    facet_oracles::names_path(path, e).map(|()| false)
}
