//! Prints f cos θo and the sampling pdf of a `.bsdf` at scattered direction pairs, one line
//! per pair: `wi.x wi.y wi.z wo.x wo.y wo.z r g b pdf`. `mitsuba_check.py` beside it reads the
//! lines and evaluates the same file with Mitsuba 3's `measured` plugin (`pip install mitsuba`).
//!
//! `cargo run --release -p facet-fit --example bsdf_eval -- FILE.bsdf [PAIRS] | python3 crates/fit/examples/mitsuba_check.py FILE.bsdf`

use facet_fit::Brdf;
use facet_fit::model::geometry::spherical;
use facet_fit::sources::rgl::RglBsdf;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let file = RglBsdf::open(Path::new(&args[1])).unwrap();
    let pairs: usize = args.get(2).map_or(2000, |s| s.parse().unwrap());
    for k in 0..pairs {
        let r = |a: f64| (k as f64 * a + 0.1).fract();
        let wi = spherical(1.5 * r(0.618_034), std::f64::consts::TAU * r(0.754_878));
        let wo = spherical(1.5 * r(0.569_840), std::f64::consts::TAU * r(0.913_099));
        let f = file.eval(wi, wo).unwrap();
        println!(
            "{} {} {} {} {} {} {} {} {} {}",
            wi.x,
            wi.y,
            wi.z,
            wo.x,
            wo.y,
            wo.z,
            f[0] * wo.z,
            f[1] * wo.z,
            f[2] * wo.z,
            file.pdf(wi, wo)
        );
    }
}
