//! Fast f32 logarithms and exponentials for the error metric's passes: ln(1 + x) and its
//! inverse e^y − 1, branch-free and division-free so that the passes vectorise them.

/// e^y − 1 in f32 for y ≥ 0 (clamped to [0, 88]), to ~1.2e-7 relative: x recovered from the
/// grid's stored ln(1 + x) ([`ln_1p`]). Below y = 1/2 the series y + y²/2! + … + y⁸/8!
/// (remainder below y⁹/9! ≤ 5.4e-9 relative); above, 2ⁿ e^r − 1, n = ⌊y / ln 2 + ½⌋,
/// r = y − n ln 2 ∈ [−ln 2 / 2, ln 2 / 2] (ln 2 in two parts) and e^r to r⁷/7! (remainder
/// below 6e-9). No branch (both are computed and one selected), and no division: the series'
/// 1/k are constants (a division per term made this the cost of copying rows, 18 cycles a
/// value).
#[inline(always)]
pub fn exp_m1(y: f32) -> f32 {
    const LN2_HI: f32 = 0.693_145_75; // 0x3f317200: n · LN2_HI is exact for n < 2⁸
    const LN2_LO: f32 = 1.428_606_8e-6;
    /// 1/k for k = 0..8 (0 unused).
    const INV: [f32; 9] = [
        0.0,
        1.0,
        0.5,
        1.0 / 3.0,
        0.25,
        0.2,
        1.0 / 6.0,
        1.0 / 7.0,
        0.125,
    ];
    // max before min, not clamp: a NaN becomes 0, so n below is in range.
    #[allow(clippy::manual_clamp)]
    let y = y.max(0.0).min(88.0);
    // y (1 + y/2 (1 + y/3 (… (1 + y/8))))
    let mut small = 1.0 + y * INV[8];
    for k in (2..8).rev() {
        small = 1.0 + y * INV[k] * small;
    }
    small *= y;
    // SAFETY: y / ln 2 + ½ is finite and in [0.5, 127.5]: well inside i32.
    let n = unsafe { (y * std::f32::consts::LOG2_E + 0.5).to_int_unchecked::<i32>() };
    let r = (y - n as f32 * LN2_HI) - n as f32 * LN2_LO;
    // 1 + r (1 + r/2 (… (1 + r/7)))
    let mut e = 1.0 + r * INV[7];
    for k in (1..7).rev() {
        e = 1.0 + r * INV[k] * e;
    }
    let large = f32::from_bits(((n + 127) as u32) << 23) * e - 1.0;
    if y < 0.5 { small } else { large }
}

/// ln(1 + x) in f32 for x ≥ 0, to ~2e-7 relative: [`ln_1p_abs`] where 1 + x is exact enough;
/// below x = 1/16, where rounding 1 + x would cost relative accuracy, the series
/// x − x²/2 + x³/3 − x⁴/4 + x⁵/5 (error below x⁶/6 ≤ 1e-8, 1.6e-7 relative) is taken instead, so
/// that x is recovered from ln(1 + x) to f32 precision (the stored data). No branch (both are
/// computed and one selected).
#[inline(always)]
pub fn ln_1p(x: f32) -> f32 {
    let x = x.max(0.0);
    let small = x * (1.0 + x * (-0.5 + x * (1.0 / 3.0 + x * (-0.25 + x * 0.2))));
    if x < 0.0625 { small } else { ln_1p_abs(x) }
}

/// ln m = t·P(t), t = m − 1 ∈ [√½ − 1, √2 − 1): the coefficients of P, a degree-7 Chebyshev fit.
const LN_P: [f32; 8] = [
    0.999_999_94,
    -0.500_003_64,
    0.333_351_14,
    -0.249_700_68,
    0.198_985_44,
    -0.172_470_51,
    0.162_343_81,
    -0.101_341_79,
];

/// ln(1 + x) in f32 for x ≥ 0 to ~2e-7 absolute (relative above x = 1): exponent and mantissa
/// of y = 1 + x split, the mantissa brought into m ∈ [√½, √2) and ln m = t·P(t), t = m − 1, P a
/// degree-7 Chebyshev fit (max error 6e-8). For tiny x the rounding of 1 + x costs relative,
/// not absolute, accuracy: what the metric's model side needs, |ln(1 + x_model) − ln(1 + x)|
/// being a sum of absolute differences. No division and no branch: the metric spends most of
/// its time here and vectorises it, and libm's log1pf is several times slower.
#[inline(always)]
pub fn ln_1p_abs(x: f32) -> f32 {
    ln_positive(1.0 + x.max(0.0))
}

/// ln y in f32 for finite y > 0, to ~2e-7 absolute for y near 1 and 1.5e-7 relative
/// elsewhere: [`ln_1p_abs`]'s method.
#[inline(always)]
pub fn ln_positive(y: f32) -> f32 {
    const P: [f32; 8] = LN_P;
    let bits = y.to_bits();
    let m1 = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    // Branch-free: mantissas are random, a branch would mispredict half the time.
    let up = (m1 > std::f32::consts::SQRT_2) as u32;
    let m = f32::from_bits(m1.to_bits() - (up << 23));
    let e = ((bits >> 23) & 0xff) as i32 - 127 + up as i32;
    let t = m - 1.0;
    // Estrin's scheme: shorter dependency chains than Horner.
    let t2 = t * t;
    let t4 = t2 * t2;
    let p01 = P[0] + P[1] * t;
    let p23 = P[2] + P[3] * t;
    let p45 = P[4] + P[5] * t;
    let p67 = P[6] + P[7] * t;
    let p = (p01 + p23 * t2) + (p45 + p67 * t2) * t4;
    e as f32 * std::f32::consts::LN_2 + t * p
}

/// [`ln_1p_abs`] with fused multiply-adds (one rounding each: results differ from it in the
/// last bits). For the passes' kernels, compiled with FMA where the CPU has it; elsewhere
/// `mul_add` is exact but emulated, several times slower.
#[inline(always)]
pub fn ln_1p_fused(x: f32) -> f32 {
    ln_positive_fused(1.0 + x.max(0.0))
}

/// [`ln_positive`] with fused multiply-adds (see [`ln_1p_fused`]).
#[inline(always)]
pub fn ln_positive_fused(y: f32) -> f32 {
    let bits = y.to_bits();
    let m1 = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let up = (m1 > std::f32::consts::SQRT_2) as u32;
    let m = f32::from_bits(m1.to_bits() - (up << 23));
    let e = ((bits >> 23) & 0xff) as i32 - 127 + up as i32;
    let t = m - 1.0;
    let t2 = t * t;
    let t4 = t2 * t2;
    let p01 = LN_P[1].mul_add(t, LN_P[0]);
    let p23 = LN_P[3].mul_add(t, LN_P[2]);
    let p45 = LN_P[5].mul_add(t, LN_P[4]);
    let p67 = LN_P[7].mul_add(t, LN_P[6]);
    let p = p67.mul_add(t2, p45).mul_add(t4, p23.mul_add(t2, p01));
    (e as f32).mul_add(std::f32::consts::LN_2, t * p)
}

#[cfg(test)]
mod tests {
    #[test]
    fn fast_ln_1p_matches_libm() {
        let mut worst = 0.0f32;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if !x.is_finite() {
                break;
            }
            let (a, b) = (super::ln_1p(x), x.ln_1p());
            // Absolute below 1 (1 + x rounds in f32 for tiny x), relative above.
            worst = worst.max((a - b).abs() / b.max(1.0));
        }
        assert!(worst < 3e-7, "worst error {worst}");
    }

    /// x recovered from the stored ln(1 + x): e^y − 1 within 2e-7 of libm's relatively for
    /// y from 1e-9 to 88 (1.2e-7 measured), and x from [`ln_1p`] within 3e-6 relatively over
    /// the stored range (2.0e-6 measured: ln_1p's relative error in ln(1 + x) grows by
    /// ln(1 + x) (1 + x) / x, at most 28 below 1e12).
    #[test]
    fn exp_m1_inverts_ln_1p() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let y = 1e-9f32 * 1.0002f32.powi(k);
            if y > 88.0 {
                break;
            }
            let (a, b) = (super::exp_m1(y) as f64, (y as f64).exp_m1());
            worst = worst.max((a - b).abs() / b);
        }
        println!("e^y − 1 worst {worst:e}");
        assert!(worst < 2e-7, "e^y − 1: worst error {worst}");
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if x > crate::model::merl_grid::MAX_X {
                break;
            }
            let back = super::exp_m1(super::ln_1p(x)) as f64;
            worst = worst.max((back - x as f64).abs() / x as f64);
        }
        println!("x worst {worst:e}");
        assert!(worst < 3e-6, "x: worst error {worst}");
        assert_eq!(super::exp_m1(0.0), 0.0);
    }

    /// The model side's logarithm: within 2e-7 of libm's absolutely below x = 1, relatively
    /// above (1 + x rounds to f32: 2⁻²⁴ ≈ 6e-8, plus the polynomial's 6e-8).
    #[test]
    fn absolute_ln_1p_matches_libm() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if !x.is_finite() {
                break;
            }
            let (a, b) = (super::ln_1p_abs(x) as f64, (x as f64).ln_1p());
            worst = worst.max((a - b).abs() / b.max(1.0));
        }
        assert!(worst < 2e-7, "worst error {worst}");
    }

    /// The fused variants to the same bound as [`absolute_ln_1p_matches_libm`], and ln y for
    /// y from 2⁻⁶⁴ to 2⁶⁴ to 1.5e-7 of max(|ln y|, 1): the polynomial's 6e-8, the f32 rounding
    /// of e ln 2 + t P(t) (6e-8 relative), and one rounding of the exponent's product.
    #[test]
    fn fused_logs_match_libm() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if !x.is_finite() {
                break;
            }
            let (a, b) = (super::ln_1p_fused(x) as f64, (x as f64).ln_1p());
            worst = worst.max((a - b).abs() / b.max(1.0));
        }
        assert!(worst < 2e-7, "ln(1 + x): worst error {worst}");
        let mut worst = 0.0f64;
        for k in -64_000..64_000 {
            let y = 2f64.powf(k as f64 * 1e-3) as f32;
            let (a, b) = (super::ln_positive_fused(y) as f64, (y as f64).ln());
            worst = worst.max((a - b).abs() / b.abs().max(1.0));
        }
        assert!(worst < 1.5e-7, "ln y: worst error {worst}");
    }
}
