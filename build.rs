//! Records the commit the `facet` binary was built from (FACET_COMMIT, "unknown" outside a git
//! checkout) for `facet bench`'s report.

fn main() {
    let commit = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into());
    let dirty = std::process::Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .output()
        .ok()
        .is_some_and(|o| o.status.success() && !o.stdout.is_empty());
    println!(
        "cargo:rustc-env=FACET_COMMIT={commit}{}",
        if dirty { "-dirty" } else { "" }
    );
    for f in [".git/HEAD", ".git/index"] {
        println!("cargo:rerun-if-changed={f}");
    }
}
