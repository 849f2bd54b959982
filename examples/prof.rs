use facet_fit::analytic::parse_analytic;
use facet_fit::grid::*;
use facet_fit::merl::*;
use std::time::Instant;
fn main() {
    let model = parse_analytic("ggx?alpha=0.15&conductor=gold").unwrap();
    let t = Instant::now();
    let table = MerlTable::sample(&model);
    println!("sample {:?}", t.elapsed());
    let src = MerlBrdf::from_table("x", table).unwrap();
    for _ in 0..3 {
        let t = Instant::now();
        let set = GridSamples::new(&src);
        println!("grid {:?} n={}", t.elapsed(), set.len());
        let t = Instant::now();
        let e = microfacet_error(&model, &set);
        println!("error {:?} {e}", t.elapsed());
        let t = Instant::now();
        let f = fresnel_average(&model, &set);
        println!("fresnel {:?} {:?}", t.elapsed(), f[0]);
        let t = Instant::now();
        let tabs = IsoTables::new(&model).unwrap();
        println!("tables {:?}", t.elapsed());
        let sub = set.subsample(32);
        let t = Instant::now();
        let e = tables_error(&tabs, &sub);
        println!("sub error {:?} {e}", t.elapsed());
    }
}
