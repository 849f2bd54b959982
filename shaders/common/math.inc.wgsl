// Include-only. What several shader families share: π, the rotation of a frame about the
// normal (an NDF's `rotation`) and the correlated Smith G2.

const PI: f32 = 3.14159265358979;

// v rotated by `angle` about z: from an NDF's own frame to the shading frame.
fn rotate_z(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let c = cos(angle);
    let s = sin(angle);
    return vec3<f32>(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
}

// v rotated by −angle about z, the inverse of rotate_z: from the shading frame to an NDF's own.
fn unrotate_z(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let c = cos(angle);
    let s = sin(angle);
    return vec3<f32>(c * v.x + s * v.y, -s * v.x + c * v.y, v.z);
}

// Correlated Smith G2 (design.md; facet_fit::microfacet::g2):
// 1 / (1 + max(Λi, Λo) + λ(φ) min(Λi, Λo)), λ = 4.41φ/(4.41φ + 1).
fn g2_correlated(lam_i: f32, lam_o: f32, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let li = length(wi.xy);
    let lo = length(wo.xy);
    var phi = 0.0;
    if (li > 1e-6 && lo > 1e-6) {
        phi = acos(clamp(dot(wi.xy, wo.xy) / (li * lo), -1.0, 1.0));
    }
    let corr = 4.41 * phi / (4.41 * phi + 1.0);
    return 1.0 / (1.0 + max(lam_i, lam_o) + corr * min(lam_i, lam_o));
}
