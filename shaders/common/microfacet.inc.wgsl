// Include-only. Analytic microfacet NDFs (Rust twin: facet_fit::microfacet::AnalyticNdf):
// D, Smith Λ and sampling of GGX (kind 0) and Beckmann (kind 1), αx, αy and a rotation.

struct AnalyticNdf {
    kind: u32,
    alpha_x: f32,
    alpha_y: f32,
    rotation: f32,
}

const MF_PI: f32 = 3.14159265358979;

fn ndf_to_local(n: AnalyticNdf, w: vec3<f32>) -> vec3<f32> {
    let c = cos(n.rotation);
    let s = sin(n.rotation);
    return vec3<f32>(c * w.x + s * w.y, -s * w.x + c * w.y, w.z);
}

// D(h), ∫ D cos θ dω = 1.
fn ndf_d(n: AnalyticNdf, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let l = ndf_to_local(n, h);
    let e = (l.x / n.alpha_x) * (l.x / n.alpha_x) + (l.y / n.alpha_y) * (l.y / n.alpha_y);
    if (n.kind == 0u) {
        // GGX: 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)
        let q = e + l.z * l.z;
        return 1.0 / (MF_PI * n.alpha_x * n.alpha_y * q * q);
    }
    // Beckmann: exp(−(hx²/αx² + hy²/αy²)/hz²) / (π αx αy hz⁴)
    let z2 = l.z * l.z;
    return exp(-e / z2) / (MF_PI * n.alpha_x * n.alpha_y * z2 * z2);
}

// erf by Abramowitz–Stegun 7.1.26 (|error| < 1.5e-7; the CPU uses libm's erf).
fn erf_approx(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.3275911 * abs(x));
    let y = 1.0 - (((((1.061405429 * t - 1.453152027) * t) + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * exp(-x * x);
    return select(-y, y, x >= 0.0);
}

// Smith Λ(w).
fn ndf_lambda(n: AnalyticNdf, w: vec3<f32>) -> f32 {
    let l = ndf_to_local(n, w);
    let a2t2 = ((l.x * n.alpha_x) * (l.x * n.alpha_x) + (l.y * n.alpha_y) * (l.y * n.alpha_y)) / (l.z * l.z);
    if (a2t2 <= 0.0) {
        return 0.0;
    }
    if (n.kind == 0u) {
        return 0.5 * (sqrt(1.0 + a2t2) - 1.0);
    }
    let a = 1.0 / sqrt(a2t2);
    if (a > 6.0) {
        return 0.0;
    }
    return 0.5 * (erf_approx(a) - 1.0) + exp(-a * a) / (2.0 * a * sqrt(MF_PI));
}

// A normal with density D(h) cos θh: a unit slope (GGX tan θ = sqrt(u/(1 − u)), Beckmann
// tan θ = sqrt(−ln(1 − u))) stretched by (αx, αy) and rotated.
fn ndf_sample(n: AnalyticNdf, u: vec2<f32>) -> vec3<f32> {
    var r = 0.0;
    if (n.kind == 0u) {
        r = sqrt(u.x / max(1.0 - u.x, 1e-30));
    } else {
        r = sqrt(-log(max(1.0 - u.x, 1e-30)));
    }
    let phi = 2.0 * MF_PI * u.y;
    let h = normalize(vec3<f32>(r * cos(phi) * n.alpha_x, r * sin(phi) * n.alpha_y, 1.0));
    let c = cos(n.rotation);
    let s = sin(n.rotation);
    return vec3<f32>(c * h.x - s * h.y, s * h.x + c * h.y, h.z);
}
