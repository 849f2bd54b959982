//! The NDF extraction by power iterations: its stopping rule and its eigenvalue.

mod common;

use common::merl_from_spec;
use facet_fit::extract::{ExtractConfig, Stopping, extract_isotropic};

#[test]
fn fixed_iteration_count_is_honoured() {
    let src = merl_from_spec("ggx?alpha=0.3&f0=0.04");
    let cfg = ExtractConfig {
        stopping: Stopping::Fixed(4),
        ..ExtractConfig::isotropic()
    };
    let ex = extract_isotropic(&src, &cfg).unwrap();
    assert_eq!(ex.iterations, 4);
    let conv = extract_isotropic(&src, &ExtractConfig::isotropic()).unwrap();
    assert!(conv.residual < 1e-9 && conv.residual < ex.residual);
    // λ is F(0) of the data.
    assert!(
        (conv.eigenvalue - 0.04).abs() < 1e-3,
        "λ = {}",
        conv.eigenvalue
    );
}
