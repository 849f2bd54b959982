// Include-only. Analytic microfacet NDFs (Rust twin: facet_fit::microfacet::AnalyticNdf):
// D, Smith Λ and sampling of GGX (NDF_KIND_GGX) and Beckmann (NDF_KIND_BECKMANN), αx, αy and a
// rotation: of D cos θh, and of the normals visible from ωo (facet_fit::visible_normals).

#include "common/math.inc.wgsl"
#include "common/ndf_kind.inc.wgsl"

struct AnalyticNdf {
    kind: u32,
    alpha_x: f32,
    alpha_y: f32,
    rotation: f32,
}

// D(h), ∫ D cos θ dω = 1.
fn ndf_d(n: AnalyticNdf, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let l = unrotate_z(h, n.rotation);
    let e = (l.x / n.alpha_x) * (l.x / n.alpha_x) + (l.y / n.alpha_y) * (l.y / n.alpha_y);
    if (n.kind == NDF_KIND_GGX) {
        // GGX: 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)
        let q = e + l.z * l.z;
        return 1.0 / (PI * n.alpha_x * n.alpha_y * q * q);
    }
    // Beckmann: exp(−(hx²/αx² + hy²/αy²)/hz²) / (π αx αy hz⁴)
    let z2 = l.z * l.z;
    return exp(-e / z2) / (PI * n.alpha_x * n.alpha_y * z2 * z2);
}

// erf by Abramowitz–Stegun 7.1.26 (|error| < 1.5e-7; the CPU uses libm's erf).
fn erf_approx(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.3275911 * abs(x));
    let y = 1.0 - (((((1.061405429 * t - 1.453152027) * t) + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * exp(-x * x);
    return select(-y, y, x >= 0.0);
}

// Smith Λ(w).
fn ndf_lambda(n: AnalyticNdf, w: vec3<f32>) -> f32 {
    let l = unrotate_z(w, n.rotation);
    let a2t2 = ((l.x * n.alpha_x) * (l.x * n.alpha_x) + (l.y * n.alpha_y) * (l.y * n.alpha_y)) / (l.z * l.z);
    if (a2t2 <= 0.0) {
        return 0.0;
    }
    if (n.kind == NDF_KIND_GGX) {
        return 0.5 * (sqrt(1.0 + a2t2) - 1.0);
    }
    let a = 1.0 / sqrt(a2t2);
    if (a > 6.0) {
        return 0.0;
    }
    return 0.5 * (erf_approx(a) - 1.0) + exp(-a * a) / (2.0 * a * sqrt(PI));
}

// A normal with density D(h) cos θh: a unit slope (GGX tan θ = sqrt(u/(1 − u)), Beckmann
// tan θ = sqrt(−ln(1 − u))) stretched by (αx, αy) and rotated.
fn ndf_sample(n: AnalyticNdf, u: vec2<f32>) -> vec3<f32> {
    var r = 0.0;
    if (n.kind == NDF_KIND_GGX) {
        r = sqrt(u.x / max(1.0 - u.x, 1e-30));
    } else {
        r = sqrt(-log(max(1.0 - u.x, 1e-30)));
    }
    let phi = 2.0 * PI * u.y;
    let h = normalize(vec3<f32>(r * cos(phi) * n.alpha_x, r * sin(phi) * n.alpha_y, 1.0));
    return rotate_z(h, n.rotation);
}

// Inverse error function: Giles (2010), single precision (facet_fit::visible_normals::erfinv_giles).
fn erfinv_f32(y: f32) -> f32 {
    var w = -log(max((1.0 - y) * (1.0 + y), 1e-30));
    var p: f32;
    if (w < 5.0) {
        w = w - 2.5;
        p = 2.81022636e-08;
        p = 3.43273939e-07 + p * w;
        p = -3.5233877e-06 + p * w;
        p = -4.39150654e-06 + p * w;
        p = 0.00021858087 + p * w;
        p = -0.00125372503 + p * w;
        p = -0.00417768164 + p * w;
        p = 0.246640727 + p * w;
        p = 1.50140941 + p * w;
    } else {
        w = sqrt(w) - 3.0;
        p = -0.000200214257;
        p = 0.000100950558 + p * w;
        p = 0.00134934322 + p * w;
        p = -0.00367342844 + p * w;
        p = 0.00573950773 + p * w;
        p = -0.0076224613 + p * w;
        p = 0.00943887047 + p * w;
        p = 1.00167406 + p * w;
        p = 2.83297682 + p * w;
    }
    return p * y;
}

// Visible slopes of the unit Beckmann NDF seen from cos θ in the x–z plane: Newton's method on
// the CDF in the erf domain, x = erf(x̃) ∈ (−1, erf(cot θ)), CDF ∝ 1 + x + tan θ exp(−x̃²)/√π.
fn beckmann_visible_slopes_11(cos_theta: f32, u_in: vec2<f32>) -> vec2<f32> {
    let tan_theta = max(sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / cos_theta, 1e-6);
    let cot_theta = 1.0 / tan_theta;
    let max_x = erf_approx(cot_theta);
    let u = clamp(u_in, vec2<f32>(1e-6), vec2<f32>(1.0 - 1e-6));
    var x = max_x - (max_x + 1.0) * erf_approx(sqrt(-log(u.x)));
    let target_cdf = u.x * (1.0 + max_x + tan_theta * exp(-cot_theta * cot_theta) / sqrt(PI));
    for (var i = 0u; i < 6u; i++) {
        let slope = erfinv_f32(x);
        let value = 1.0 + x + tan_theta * exp(-slope * slope) / sqrt(PI) - target_cdf;
        let derivative = 1.0 - slope * tan_theta;
        x = clamp(x - value / derivative, -1.0 + 1e-6, min(max_x, 1.0 - 1e-6));
    }
    return vec2<f32>(erfinv_f32(x), erfinv_f32(2.0 * u.y - 1.0));
}

// A normal from the distribution of normals visible from wo (wo.z > 0), density
// ndf_pdf_visible: GGX by spherical caps (Dupuy & Benyoub 2023), Beckmann by visible slopes.
fn ndf_sample_visible(n: AnalyticNdf, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let o = unrotate_z(wo, n.rotation);
    let v = normalize(vec3<f32>(n.alpha_x * o.x, n.alpha_y * o.y, max(o.z, 1e-7)));
    var h: vec3<f32>;
    if (n.kind == NDF_KIND_GGX) {
        let phi = 2.0 * PI * u.x;
        let z = (1.0 - u.y) * (1.0 + v.z) - v.z;
        let r = sqrt(max(1.0 - z * z, 0.0));
        let hs = vec3<f32>(r * cos(phi), r * sin(phi), z) + v;
        h = vec3<f32>(n.alpha_x * hs.x, n.alpha_y * hs.y, max(hs.z, 0.0));
    } else {
        let s = beckmann_visible_slopes_11(v.z, u);
        let l = length(v.xy);
        var sin_phi = 0.0;
        var cos_phi = 1.0;
        if (l > 1e-7) {
            sin_phi = v.y / l;
            cos_phi = v.x / l;
        }
        let slope = vec2<f32>((cos_phi * s.x - sin_phi * s.y) * n.alpha_x, (sin_phi * s.x + cos_phi * s.y) * n.alpha_y);
        h = vec3<f32>(-slope.x, -slope.y, 1.0);
    }
    return rotate_z(normalize(h), n.rotation);
}

// D_wo(h) = G1(wo) max(0, wo·h) D(h) / wo.z, G1 = 1 / (1 + Λ(wo)).
fn ndf_pdf_visible(n: AnalyticNdf, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    if (wo.z <= 0.0 || h.z <= 0.0) {
        return 0.0;
    }
    return max(dot(wo, h), 0.0) * ndf_d(n, h) / ((1.0 + ndf_lambda(n, wo)) * wo.z);
}
