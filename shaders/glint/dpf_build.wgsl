// Builds one level of the DPF table: one thread per cell (θo, θi, Δφ) at its centre,
//   P = ∫_{ω ∈ cone(ωo, γ)} D(h) cos θh / (4 ωi·h) dω,  h = normalize(ωi + ω),
// either Gauss–Legendre in the cone's polar angle ψ × midpoint in its azimuth χ, on the rings
// of the cone rule as Rust built them (facet_glint::cone_rule; CPU twin
// facet_glint::dpf::dpf_on_rings), or, on wide cones, polar coordinates (ρ, φ) about the mirror
// direction clipped to the cone (facet_glint::lobe_rule; CPU twin facet_glint::dpf::dpf_on_lobe).

#include "common/math.inc.wgsl"
#include "common/ndf_kind.inc.wgsl"
#include "common/microfacet.inc.wgsl"

const WG: u32 = 64u;
// Rust: facet_glint::lobe_rule::LOBE_EPS, TOUCH_MERGE and TAIL_START.
override LOBE_EPS: f32;
override TOUCH_MERGE: f32;
override TAIL_START: f32;
// 0: the rings; 1: the rule about the lobe. A constant per pipeline, so a build compiles only the
// rule its levels take (facet_glint::gpu builds a pipeline per rule used).
override RULE: u32;

// Rust: facet_glint::gpu::DpfParams.
struct Params {
    n_theta: u32,
    n_dphi: u32,
    n_rings: u32,
    // NDF_KIND_*: GGX, Beckmann, or the table over (u = sqrt(θ/(π/2)), φ).
    ndf_kind: u32,
    alpha_x: f32,
    alpha_y: f32,
    rotation: f32,
    table_nu: u32,
    table_nphi: u32,
    // The rule about the lobe: Gauss–Legendre nodes per radial interval and per ring (core,
    // tail), the cone's half-angle γ and the lobe width w its intervals are scaled to.
    n_radial: u32,
    n_angular: u32,
    n_tail_angular: u32,
    gamma: f32,
    lobe_width: f32,
    pad0: u32,
    pad1: u32,
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
// The NDF table when ndf_kind is NDF_KIND_TABULATED (index k · nphi + l).
@group(0) @binding(2) var<storage, read> ndf_table: array<f32>;
@group(0) @binding(3) var<storage, read_write> out: array<f32>;
// The rule about the lobe's Gauss–Legendre nodes on [0, 1], (x, weight): n_radial, n_angular,
// then n_tail_angular.
@group(0) @binding(4) var<storage, read> lobe_nodes: array<vec2<f32>>;

fn ndf(h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    if (params.ndf_kind == NDF_KIND_TABULATED) {
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
    if (RULE == 1u) {
        out[cell] = lobe_sum(wi, wo);
    } else {
        out[cell] = rings_sum(wi, wo);
    }
}

// A unit vector perpendicular to n (the CPU's choice of helper axis).
fn perpendicular(n: vec3<f32>) -> vec3<f32> {
    var a = vec3<f32>(1.0, 0.0, 0.0);
    if (abs(n.x) >= 0.9) {
        a = vec3<f32>(0.0, 1.0, 0.0);
    }
    return normalize(cross(a, n));
}

fn rings_sum(wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let t = perpendicular(wo);
    let b = cross(wo, t);
    var sum = 0.0;
    for (var k = 0u; k < params.n_rings; k++) {
        let r = rings[k];
        // χ = (m + ½) Δ by rotation: (cos, sin) of χ + Δ from those of χ.
        let step = 2.0 * PI / f32(r.n_chi);
        let rot = vec2<f32>(cos(step), sin(step));
        var cs = vec2<f32>(cos(0.5 * step), sin(0.5 * step));
        var ring = 0.0;
        for (var m = 0u; m < r.n_chi; m++) {
            ring += density(wi, r.cos_psi * wo + r.sin_psi * (cs.x * t + cs.y * b));
            cs = vec2<f32>(cs.x * rot.x - cs.y * rot.y, cs.y * rot.x + cs.x * rot.y);
        }
        sum += r.weight * ring; // Σ_rings weight · Σ_χ p(h)/(4 ωi·h)
    }
    return sum;
}

// The half-width of the arc of the ring at ρ about r inside the cone (cos φ ≥ c(ρ) on it): π for
// a whole ring, 0 for none (Rust: facet_glint::lobe_rule::arc_half_width).
fn arc_half_width(cr: f32, sr: f32, cb: f32, sb: f32, cos_gamma: f32) -> f32 {
    let denom = sr * sb;
    let cos_mid = cr * cb;
    if (denom < LOBE_EPS * LOBE_EPS) {
        return select(0.0, PI, cos_mid >= cos_gamma);
    }
    let c = (cos_gamma - cos_mid) / denom; // c(ρ) = (cos γ − cos ρ cos β) / (sin ρ sin β)
    if (c <= -1.0) {
        return PI;
    }
    if (c >= 1.0) {
        return 0.0;
    }
    return atan2(sqrt((1.0 - c) * (1.0 + c)), c); // acos c
}

// Whether a ring touches the cone at ρ = x: the range's ends (not ρ = 0 or π) and γ − β.
fn touches(x: f32, lo: f32, hi: f32, whole_below: f32) -> bool {
    return (x == lo && lo > 0.0) || (x == hi && hi < PI) || x == whole_below;
}

// Where the interval from a ends: the first lobe scale point from `scale` on, or the next point
// where a ring touches the cone; a scale point within TOUCH_MERGE of itself of a touching point
// is skipped (Rust: facet_glint::lobe_rule::interval_end).
fn interval_end(a: f32, a_touches: bool, scale: f32, next_tangent: f32) -> f32 {
    var s = scale;
    while (s < next_tangent - TOUCH_MERGE * s) {
        if (!(a_touches && s - a < TOUCH_MERGE * s)) {
            return s;
        }
        s *= 2.0;
    }
    return next_tangent;
}

// g(s) and g′(s) of an interval's RadialMap (Rust: facet_glint::lobe_rule::RadialMap).
fn radial_map(code: u32, s: f32) -> vec2<f32> {
    switch code {
        case 1u: {
            return vec2<f32>(s * s, 2.0 * s);
        }
        case 2u: {
            let t = 1.0 - s;
            return vec2<f32>(1.0 - t * t, 2.0 * t);
        }
        case 3u: {
            return vec2<f32>(0.5 * (1.0 - cos(PI * s)), 0.5 * PI * sin(PI * s));
        }
        default: {
            return vec2<f32>(s, 1.0);
        }
    }
}

// P = ∫ sin ρ dρ ∫_{arc(ρ)} q dφ about r = mirror(ωi): the intervals of ρ cut at the lobe scales
// w·2^k and at |γ − β|, as facet_glint::lobe_rule::LobeRule::for_each_node walks them.
fn lobe_sum(wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let r = vec3<f32>(-wi.x, -wi.y, wi.z);
    let cb = clamp(dot(r, wo), -1.0, 1.0);
    let perp = wo - cb * r;
    let sb = length(perp);
    var u = perpendicular(r);
    if (sb > LOBE_EPS) {
        u = perp / sb;
    }
    let v = cross(r, u);
    let beta = atan2(sb, cb); // not acos(cb): lavapipe's acos is good to ~1e-4 only
    let gamma = params.gamma;
    let lo = max(0.0, beta - gamma);
    let hi = min(PI, beta + gamma);
    let whole_below = gamma - beta;
    let cos_gamma = cos(gamma);
    let n_r = params.n_radial;
    var sum = 0.0;
    var a = lo;
    var scale = params.lobe_width;
    loop {
        if (a >= hi - LOBE_EPS) {
            break;
        }
        loop {
            if (scale > a + LOBE_EPS) {
                break;
            }
            scale *= 2.0;
        }
        var next_tangent = hi;
        if (whole_below > a + LOBE_EPS && whole_below < hi) {
            next_tangent = whole_below;
        }
        let start = touches(a, lo, hi, whole_below);
        let b = interval_end(a, start, scale, next_tangent);
        let end = touches(b, lo, hi, whole_below);
        let code = select(0u, 1u, start) + select(0u, 2u, end);
        let len = b - a;
        // The core's or the tail's angular nodes.
        var first = n_r;
        var n_a = params.n_angular;
        if (a >= TAIL_START * params.lobe_width) {
            first = n_r + params.n_angular;
            n_a = params.n_tail_angular;
        }
        for (var j = 0u; j < n_r; j++) {
            let node = lobe_nodes[j];
            let g = radial_map(code, node.x);
            let rho = a + len * g.x;
            let sr = sin(rho);
            let cr = cos(rho);
            let half = arc_half_width(cr, sr, cb, sb, cos_gamma);
            if (half < LOBE_EPS) {
                continue;
            }
            // The arc's nodes φ = half (2t − 1) come in pairs ±φ (the rule is symmetric).
            var ring = 0.0;
            for (var m = 0u; 2u * m < n_a; m++) {
                let ang = lobe_nodes[first + m];
                let phi = half * (2.0 * ang.x - 1.0);
                let sp = sin(phi);
                let cp = cos(phi);
                let base = cr * r + sr * cp * u;
                if (2u * m + 1u == n_a) {
                    ring += ang.y * density(wi, base);
                } else {
                    ring += ang.y * (density(wi, base + sr * sp * v) + density(wi, base - sr * sp * v));
                }
            }
            sum += node.y * len * g.y * sr * 2.0 * half * ring; // dρ sin ρ dφ
        }
        a = b;
    }
    return sum;
}
