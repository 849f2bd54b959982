// Builds one level of the DPF table: one thread per cell (θo, θi, Δφ) at its centre,
//   P = ∫_{ω ∈ cone(ωo, γ)} D(h) cos θh / (4 ωi·h) dω,  h = normalize(ωi + ω),
// Gauss–Legendre in the cone's polar angle ψ × midpoint in its azimuth χ: the rings of the cone
// rule as Rust built them (facet_glint::cone_rule), the same the CPU reference sums
// (facet_glint::dpf::dpf_on_rings).

#include "common/microfacet.inc.wgsl"

const WG: u32 = 64u;
const PI: f32 = 3.14159265358979;

// Rust: facet_glint::gpu::DpfParams.
struct Params {
    n_theta: u32,
    n_dphi: u32,
    n_rings: u32,
    // 0: GGX, 1: Beckmann, 2: table over (u = sqrt(θ/(π/2)), φ).
    ndf_kind: u32,
    alpha_x: f32,
    alpha_y: f32,
    rotation: f32,
    table_nu: u32,
    table_nphi: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// Rust: facet_glint::cone_rule::Ring. Nodes cos ψ ωo + sin ψ (cos χ t + sin χ b),
// χ = (k + ½) 2π / n_chi, each weighted w_gl γ sin ψ 2π / n_chi.
struct Ring {
    cos_psi: f32,
    sin_psi: f32,
    weight: f32,
    n_chi: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
// The rings of the cone rule.
@group(0) @binding(1) var<storage, read> rings: array<Ring>;
// The NDF table when ndf_kind = 2 (index k · nphi + l).
@group(0) @binding(2) var<storage, read> ndf_table: array<f32>;
@group(0) @binding(3) var<storage, read_write> out: array<f32>;

fn ndf(h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    if (params.ndf_kind == 2u) {
        let theta = acos(clamp(h.z, -1.0, 1.0));
        let x = sqrt(theta / (0.5 * PI)) * f32(params.table_nu - 1u);
        let k = min(u32(x), params.table_nu - 2u);
        let t = x - f32(k);
        var phi = atan2(h.y, h.x);
        if (phi < 0.0) {
            phi += 2.0 * PI;
        }
        let np = params.table_nphi;
        let yy = phi / (2.0 * PI) * f32(np);
        let l = min(u32(yy), np - 1u);
        let l1 = (l + 1u) % np;
        let s = select(yy - f32(l), 0.0, np == 1u);
        let row0 = mix(ndf_table[k * np + l], ndf_table[k * np + l1], s);
        let row1 = mix(ndf_table[(k + 1u) * np + l], ndf_table[(k + 1u) * np + l1], s);
        return mix(row0, row1, t);
    }
    return ndf_d(AnalyticNdf(params.ndf_kind, params.alpha_x, params.alpha_y, params.rotation), h);
}

fn density(wi: vec3<f32>, w: vec3<f32>) -> f32 {
    let s = wi + w;
    let len = length(s);
    if (len < 1e-6) {
        return 0.0;
    }
    let h = s / len;
    let cih = dot(wi, h);
    if (h.z <= 0.0 || cih <= 0.0) {
        return 0.0;
    }
    return ndf(h) * h.z / (4.0 * cih);
}

@compute @workgroup_size(WG)
fn dpf_build(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let cell = gid.x + gid.y * nwg.x * WG;
    let nt = params.n_theta;
    let np = params.n_dphi;
    if (cell >= nt * nt * np) {
        return;
    }
    let o = cell / (nt * np);
    let i = (cell / np) % nt;
    let p = cell % np;
    let st = 0.5 * PI / f32(nt);
    let theta_o = (f32(o) + 0.5) * st;
    let theta_i = (f32(i) + 0.5) * st;
    let dphi = (f32(p) + 0.5) * PI / f32(np);
    let wi = vec3<f32>(sin(theta_i), 0.0, cos(theta_i));
    let wo = vec3<f32>(sin(theta_o) * cos(dphi), sin(theta_o) * sin(dphi), cos(theta_o));
    // Frame around ωo (the CPU's choice of helper axis).
    var a = vec3<f32>(1.0, 0.0, 0.0);
    if (abs(wo.x) >= 0.9) {
        a = vec3<f32>(0.0, 1.0, 0.0);
    }
    let t = normalize(cross(a, wo));
    let b = cross(wo, t);
    var sum = 0.0;
    for (var k = 0u; k < params.n_rings; k++) {
        let r = rings[k];
        var ring = 0.0;
        for (var m = 0u; m < r.n_chi; m++) {
            let chi = (f32(m) + 0.5) / f32(r.n_chi) * 2.0 * PI;
            ring += density(wi, r.cos_psi * wo + r.sin_psi * (cos(chi) * t + sin(chi) * b));
        }
        sum += r.weight * ring; // Σ_rings weight · Σ_χ p(h)/(4 ωi·h)
    }
    out[cell] = sum;
}
