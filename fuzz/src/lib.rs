//! What the fuzz targets assert about a loader's answer. (The seeds in `corpus/<target>/seed-*`
//! are written by the root package's `tests/loader_mutation/`, see the README.)
//!
//! Every target: no panic; an error's message names the path given to the loader; an accepted
//! input gives a value the renderer and the fitter can use (finite values, indices in range,
//! BRDFs finite and non-negative where evaluated). A broken assertion panics, which libFuzzer
//! reports as a crash. The checks are `facet_oracles`', which the mutation test uses too; here
//! each becomes an assertion.

use facet_fit::Brdf;
use facet_fit::model::material::FittedMaterial;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_render::scene::{EnvironmentMap, Scene};
use std::cell::RefCell;
use std::path::Path;

thread_local! {
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Runs one input. The loaders catch panics of their decoders and turn them into errors, which
/// is what a caller sees, so libFuzzer's hook (abort on any panic) is replaced the first time by
/// one that only records the panic; a panic that leaves `f` is then printed and aborts (a
/// crash). `FACET_FUZZ_CAUGHT_PANICS=1` keeps libFuzzer's hook: caught panics crash too.
pub fn run(f: impl FnOnce()) {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        if std::env::var_os("FACET_FUZZ_CAUGHT_PANICS").is_none() {
            std::panic::set_hook(Box::new(|info| {
                LAST_PANIC.with_borrow_mut(|s| *s = info.to_string());
            }));
        }
    });
    if std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_err() {
        eprintln!(
            "panic out of the loader or its checks: {}",
            LAST_PANIC.take()
        );
        std::process::abort();
    }
}

/// Panics with the oracle's message when it found something wrong.
fn assert_ok<T>(verdict: Result<T, String>) -> T {
    verdict.unwrap_or_else(|problem| panic!("{problem}"))
}

/// Panics unless the error's message names `path`.
pub fn assert_names(path: &Path, e: impl std::fmt::Display) {
    assert_ok(facet_oracles::names_path(path, e));
}

/// Panics unless every value the BRDF gives at `facet_oracles::direction_pairs` is finite and
/// non-negative.
pub fn assert_brdf_sane(what: &str, brdf: &dyn Brdf) {
    assert_ok(facet_oracles::brdf_sane(what, brdf));
}

/// Panics unless every model of the fit passes [`assert_brdf_sane`].
pub fn assert_fit_sane(fit: &FittedMaterial) {
    assert_ok(facet_oracles::fit_sane(fit));
}

/// Panics unless every network of the library (read from `path`) builds and is sane, or is
/// refused with an error naming `path`.
pub fn assert_nbrdf_sane(path: &Path, library: &NbrdfLibrary) {
    assert_ok(facet_oracles::nbrdf_sane(path, library));
}

/// Panics unless a table accepted from `bytes` is sane: the standard layout, the values
/// `written` into the file read back, every sample finite and non-negative, a sane BRDF.
pub fn assert_merl_sane(bytes: &[u8], table: MerlTable, written: &[(usize, f64)]) {
    assert_ok(facet_oracles::merl_sane(bytes, table, written));
}

/// Panics unless the scene is one the renderer can use.
pub fn assert_scene_sane(scene: &Scene) {
    assert_ok(facet_oracles::scene_sane(scene));
}

/// Panics unless the map and its sampling distribution are usable.
pub fn assert_env_sane(map: &EnvironmentMap) {
    assert_ok(facet_oracles::env_sane(map));
}
