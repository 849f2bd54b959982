// Include-only. A measured table on the MERL grid (Matusik et al. 2003), the twin of
// facet_fit::merl_grid::MerlTable::lookup_interpolated: f_r itself (the channel scales applied),
// RGB interleaved per sample at `tables[o + 3 s + c]`, sample s = φd + P (θd + D θh), negative
// where missing. Sample (i, j, k) sits at θh = (i / H)² π/2, θd = j / D · π/2, φd = k / P · π.
// The grid's sizes come from facet_fit::merl_grid as pipeline constants. The includer declares
// `tables`.

#include "common/math.inc.wgsl"

override MERL_THETA_H: u32;
override MERL_THETA_D: u32;
override MERL_PHI_D: u32;

// Continuous bin coordinates (samples at integers) of the Rusinkiewicz pair of (wi, wo):
// (√(θh / (π/2)) H, θd / (π/2) D, (φd mod π) / π P). The rotations take their sines and cosines
// from h itself, so that f32 keeps its accuracy near the pole.
fn merl_coords(wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let h = normalize(wi + wo);
    let s = length(h.xy);
    var cp = 1.0;
    var sp = 0.0;
    if (s > 1e-7) {
        cp = h.x / s;
        sp = h.y / s;
    }
    // d = R_y(−θh) R_z(−φh) wi.
    let a = vec3<f32>(cp * wi.x + sp * wi.y, -sp * wi.x + cp * wi.y, wi.z);
    let d = vec3<f32>(h.z * a.x - s * a.z, a.y, s * a.x + h.z * a.z);
    let theta_h = atan2(s, h.z);
    let theta_d = atan2(length(d.xy), d.z);
    var phi_d = atan2(d.y, d.x);
    // Reciprocity: φd and φd + π are one bin.
    phi_d = phi_d - PI * floor(phi_d / PI);
    return vec3<f32>(
        sqrt(max(theta_h, 0.0) / (0.5 * PI)) * f32(MERL_THETA_H),
        max(theta_d, 0.0) / (0.5 * PI) * f32(MERL_THETA_D),
        phi_d / PI * f32(MERL_PHI_D),
    );
}

// The lower corner and weight along one clamped axis of n samples.
fn merl_axis(v: f32, n: u32) -> vec2<f32> {
    let c = clamp(v, 0.0, f32(n - 1u));
    let i0 = min(u32(c), n - 2u);
    return vec2<f32>(f32(i0), c - f32(i0));
}

// f_r(wi, wo): trilinear between the 8 samples around the pair, φd wrapping with period π,
// missing corners left out and the others' weights renormalised; 0 where all 8 are missing.
fn merl_eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let x = merl_coords(wi, wo);
    let ah = merl_axis(x.x, MERL_THETA_H);
    let ad = merl_axis(x.y, MERL_THETA_D);
    let p0 = min(u32(x.z), MERL_PHI_D - 1u);
    let tp = x.z - f32(p0);
    let ih = array<u32, 2>(u32(ah.x), u32(ah.x) + 1u);
    let wh = array<f32, 2>(1.0 - ah.y, ah.y);
    let id = array<u32, 2>(u32(ad.x), u32(ad.x) + 1u);
    let wd = array<f32, 2>(1.0 - ad.y, ad.y);
    let ip = array<u32, 2>(p0, (p0 + 1u) % MERL_PHI_D);
    let wp = array<f32, 2>(1.0 - tp, tp);
    var sum = vec3<f32>(0.0);
    var wsum = 0.0;
    for (var c = 0u; c < 8u; c++) {
        let a = c >> 2u;
        let b = (c >> 1u) & 1u;
        let e = c & 1u;
        let w = wh[a] * wd[b] * wp[e];
        if (w <= 0.0) {
            continue;
        }
        let s = ip[e] + MERL_PHI_D * (id[b] + MERL_THETA_D * ih[a]);
        let at = o + 3u * s;
        let v = vec3<f32>(tables[at], tables[at + 1u], tables[at + 2u]);
        if (all(v >= vec3<f32>(0.0))) {
            sum += w * v;
            wsum += w;
        }
    }
    if (wsum <= 0.0) {
        return vec3<f32>(0.0);
    }
    return sum / wsum;
}
