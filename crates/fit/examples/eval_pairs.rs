//! The reference values of the Python package's `Brdf.eval` test: `Brdf::eval` of an input
//! (anything `facet fit` takes) on direction pairs read from a file, one pair after another on
//! one thread, written to a file.
//!
//! `cargo run --release -p facet-fit --example eval_pairs -- INPUT PAIRS OUT`: PAIRS holds
//! N × 6 little-endian f64 (wi.xyz, wo.xyz), OUT receives N × 3 (r, g, b; NaN where `eval`
//! returns `None`). `crates/python/tests/test_eval.py` runs it through `$FACET_EVAL_PAIRS`.

use facet_fit::sources::{InputSpec, Residence};
use glam::DVec3;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, pairs, out] = &args[..] else {
        return Err("usage: eval_pairs INPUT PAIRS OUT".into());
    };
    let src = InputSpec::parse(input).open(None, &mut None, Residence::Read)?;
    let bytes = std::fs::read(Path::new(pairs))?;
    let v: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let mut f = Vec::with_capacity(v.len() / 2 * 8);
    for p in v.chunks_exact(6) {
        let (wi, wo) = (DVec3::new(p[0], p[1], p[2]), DVec3::new(p[3], p[4], p[5]));
        for c in src.eval(wi, wo).unwrap_or([f64::NAN; 3]) {
            f.extend(c.to_le_bytes());
        }
    }
    std::fs::write(out, f)?;
    Ok(())
}
