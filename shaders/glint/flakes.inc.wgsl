// Include-only. The flake field (Rust twin: facet_glint::flakes): the quadtree's keyed binomial
// splits, leaf flakes from TEA. Counting lit flakes is glint/lit.inc.wgsl's.
// Needs `field: Field` and `split_table: array<u32>` (facet_glint::flakes::SplitTable) declared
// by the includer, and glint/tea.inc.wgsl.

#include "common/math.inc.wgsl"

// Set from Rust (facet_glint::flakes), written once there.
override LEAF_FLAKES: u32;
override MAX_DEPTH: u32;
override BINOMIAL_EXACT_MAX: u32;
override SPLIT_SALT: u32;
override POSITION_SALT: u32;

// Rust: facet_glint::gpu::GlintField.
struct Field {
    density: f32,
    seed: u32,
    root_count: u32,
    filtered: u32,
    threshold: f32,
    // Whether counts blend the four direction cells around the half vector.
    blend: u32,
    // The deepest level whose nodes' flake counts `split_table` holds.
    table_levels: u32,
    pad: u32,
}

// Rust: facet_glint::gpu::GlintQuery. Two queries sharing one footprint (a shading point's
// light sample and BSDF sample): their P (0: no query) and their half vectors' direction
// coordinates (facet_glint::flakes::direction_coords).
struct Query {
    center: vec2<f32>,
    a: vec2<f32>,
    b: vec2<f32>,
    p: vec2<f32>,
    coords0: vec2<f32>,
    coords1: vec2<f32>,
}


// Acklam's normal quantile (Rust twin: facet_glint::flakes::normal_quantile).
fn normal_quantile(u: f32) -> f32 {
    let p = clamp(u, 1e-7, 1.0 - 1e-7);
    if (p < 0.02425 || p > 1.0 - 0.02425) {
        let q = sqrt(-2.0 * log(min(p, 1.0 - p)));
        let x = (((((-7.784894002430293e-3 * q - 3.223964580411365e-1) * q - 2.400758277161838) * q - 2.549732539343734) * q + 4.374664141464968) * q + 2.938163982698783)
            / ((((7.784695709041462e-3 * q + 3.224671290700398e-1) * q + 2.445134137142996) * q + 3.754408661907416) * q + 1.0);
        return select(-x, x, p < 0.5);
    }
    let q = p - 0.5;
    let r = q * q;
    return (((((-3.969683028665376e1 * r + 2.209460984245205e2) * r - 2.759285104469687e2) * r + 1.383577518672690e2) * r - 3.066479806614716e1) * r + 2.506628277459239) * q
        / (((((-5.447609879822406e1 * r + 1.615858368580409e2) * r - 1.556989798598866e2) * r + 6.680131188771972e1) * r - 1.328068155288572e1) * r + 1.0);
}

// Inverse CDF of Binomial(n, ½) at u.
fn binomial(n: u32, u: f32) -> u32 {
    if (n == 0u) {
        return 0u;
    }
    if (n > BINOMIAL_EXACT_MAX) {
        let x = f32(n) / 2.0 + sqrt(f32(n)) / 2.0 * normal_quantile(u) + 0.5;
        return min(u32(max(x, 0.0)), n);
    }
    var k = 0u;
    var p = exp2(-f32(n));
    var cdf = p;
    // A literal trip count (≥ BINOMIAL_EXACT_MAX) so the loop unrolls: llvmpipe caps a loop's
    // iterations per invocation at 65 535, and a walk calls this three times per node.
    for (var i = 0u; i < 24u; i++) {
        if (cdf >= u || k >= n) {
            break;
        }
        p *= f32(n - k) / f32(k + 1u);
        k += 1u;
        cdf += p;
    }
    return k;
}

// The flake counts of the four children of node (level, ix, iy) holding n flakes
// (facet_glint::FlakeField::split): read from the table down to its deepest level, drawn below.
fn split_counts(level: u32, ix: u32, iy: u32, n: u32, h: vec2<u32>) -> vec4<u32> {
    if (level < field.table_levels) {
        // Level d starts at (4^d − 1) / 3, row-major.
        let d = level + 1u;
        let w = 1u << d;
        let i = ((1u << (2u * d)) - 1u) / 3u + 2u * iy * w + 2u * ix;
        return vec4<u32>(split_table[i], split_table[i + 1u], split_table[i + w], split_table[i + w + 1u]);
    }
    let u = pcg3d(vec3<u32>(h.x, h.y, SPLIT_SALT));
    let left = binomial(n, unit24(u.x));
    let l0 = binomial(left, unit24(u.y));
    let r0 = binomial(n - left, unit24(u.z));
    return vec4<u32>(l0, r0, left - l0, n - left - r0);
}

fn node_hash(level: u32, ix: u32, iy: u32) -> vec2<u32> {
    return pcg3d(vec3<u32>(ix | (level << 21u), iy, field.seed * 0x9e3779b9u)).xy;
}

// Footprint area π |det [a b]|.
fn footprint_area(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return PI * abs(a.x * b.y - a.y * b.x);
}

// Flake k of a leaf whose hash is h: its id (facet_glint::flakes::FlakeField::leaf_flake).
fn leaf_flake_id(h: vec2<u32>, k: u32) -> vec2<u32> {
    return pcg3d(vec3<u32>(h.x ^ (k * 0x85ebca6bu), h.y, k)).xy;
}

// The position of flake id in the leaf cell from lo with side size
// (facet_glint::flakes::FlakeField::flake_at).
fn flake_uv(id: vec2<u32>, lo: vec2<f32>, size: f32) -> vec2<f32> {
    let u = pcg3d(vec3<u32>(id.x, id.y, POSITION_SALT));
    return lo + size * vec2<f32>(unit24(u.x), unit24(u.y));
}
