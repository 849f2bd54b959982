// Include-only. An RGL `.bsdf` (Dupuy & Jakob 2018, "An Adaptive Parameterization for Efficient
// Material Acquisition and Rendering") on the GPU, the twin of facet_fit::sources::rgl::RglBsdf
// (eval, pdf, sample), which reads as Mitsuba 3's `measured` plugin; its warps are the twins of
// facet_fit::sources::rgl::warp2d::Warp2D (eval, invert, sample). Everything in the local
// shading frame (z the normal); `wi` is the parameter direction (Mitsuba's si.wi, the camera
// side). Block at `offset` in `tables` as facet_render::materials::rgl::rgl_block lays it
// out: 8 header words and 7 warp records of 8 words, all u32 bit patterns, then the arrays;
// offsets in the block are relative to its start. The includer declares `tables`.

#include "common/math.inc.wgsl"

// The warp records, in facet_render::materials::rgl::RGL_WARPS order.
const RGL_NDF: u32 = 0u;
const RGL_SIGMA: u32 = 1u;
const RGL_VNDF: u32 = 2u;
const RGL_LUMINANCE: u32 = 3u;
const RGL_RED: u32 = 4u;
// Sample bounds of the reference code: f32's largest value below one.
const RGL_ONE_MINUS_EPSILON: f32 = 0.99999994;

// The header: where the block is, its flags and its parameter nodes (absolute offsets).
struct RglTable {
    base: u32,
    isotropic: bool,
    jacobian: bool,
    reduction: u32,
    nphi: u32,
    ntheta: u32,
    phi_nodes: u32,
    theta_nodes: u32,
}

// One warp: its columns and rows, its arrays (absolute offsets) and its slice strides.
struct RglWarp {
    nx: u32,
    ny: u32,
    data: u32,
    marginal: u32,
    conditional: u32,
    stride_phi: u32,
    stride_theta: u32,
}

fn rgl_word(o: u32) -> u32 {
    return bitcast<u32>(tables[o]);
}

fn rgl_at(offset: u32) -> RglTable {
    let flags = rgl_word(offset);
    return RglTable(offset, (flags & 1u) != 0u, (flags & 2u) != 0u, rgl_word(offset + 1u),
        rgl_word(offset + 2u), rgl_word(offset + 3u), offset + rgl_word(offset + 4u),
        offset + rgl_word(offset + 5u));
}

fn rgl_warp(t: RglTable, k: u32) -> RglWarp {
    let o = t.base + 8u + 8u * k;
    return RglWarp(rgl_word(o), rgl_word(o + 1u), t.base + rgl_word(o + 2u),
        t.base + rgl_word(o + 3u), t.base + rgl_word(o + 4u), rgl_word(o + 5u), rgl_word(o + 6u));
}

// ---- The format's coordinates.

// u = √(θ / (π/2)).
fn rgl_theta2u(theta: f32) -> f32 {
    return sqrt(max(theta / (0.5 * PI), 0.0));
}

// u = (φ + π) / 2π.
fn rgl_phi2u(phi: f32) -> f32 {
    return (phi + PI) / (2.0 * PI);
}

// θ of a unit vector by atan2, accurate at the pole and at grazing (the CPU's 2 asin(|d − z|/2)).
fn rgl_elevation(d: vec3<f32>) -> f32 {
    return atan2(length(d.xy), d.z);
}

// φ = atan2(y, x), 0 on the axis where atan2 is undefined in SPIR-V (the CPU's atan2 gives 0).
fn rgl_azimuth(d: vec3<f32>) -> f32 {
    return select(atan2(d.y, d.x), 0.0, d.x == 0.0 && d.y == 0.0);
}

// d with x and y negated as the fold of wi negates them: drjit's mulsign_neg(a, b), −a unless
// b < 0, with b = wi.y for both (reduction 2) or wi.x and wi.y (reduction 4). An involution.
fn rgl_fold_like(t: RglTable, d: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if (t.reduction < 2u) {
        return d;
    }
    let sy = wi.y;
    let sx = select(sy, wi.x, t.reduction == 4u);
    return vec3<f32>(select(-d.x, d.x, sx < 0.0), select(-d.y, d.y, sy < 0.0), d.z);
}

// ---- Parameters: where (φi, θi) falls between the nodes, and a warp's slices there.

struct RglParams {
    i_phi: u32,
    w_phi: f32,
    i_theta: u32,
    w_theta: f32,
}

// Warp2D's find_interval over `n` nodes at `off`: the i in [0, n − 2] with nodes[i] <= x,
// nodes[i + 1] > x (0 below every node, n − 2 above).
fn rgl_find_node(off: u32, n: u32, x: f32) -> u32 {
    var first = 1u;
    var len = max(n, 2u) - 2u;
    while (len > 0u) {
        let half = len / 2u;
        let middle = first + half;
        if (tables[off + middle] <= x) {
            first = middle + 1u;
            len -= half + 1u;
        } else {
            len = half;
        }
    }
    return min(first - 1u, max(n, 2u) - 2u);
}

// The lower node and the upper's weight, clamped to [0, 1], along n nodes at `off`.
fn rgl_param(off: u32, n: u32, x: f32) -> vec2<f32> {
    if (n < 2u) {
        return vec2<f32>(0.0);
    }
    let i = rgl_find_node(off, n, x);
    let w = clamp((x - tables[off + i]) / (tables[off + i + 1u] - tables[off + i]), 0.0, 1.0);
    return vec2<f32>(f32(i), w);
}

fn rgl_params(t: RglTable, phi_i: f32, theta_i: f32) -> RglParams {
    let p = rgl_param(t.phi_nodes, t.nphi, phi_i);
    let q = rgl_param(t.theta_nodes, t.ntheta, theta_i);
    return RglParams(u32(p.x), p.y, u32(q.x), q.y);
}

// The four parameter slices of a warp and their weights (Warp2D::corners); a warp without
// parameters has strides 0, so all four are slice 0, and weight 1 on the first.
struct RglCorners {
    slice: vec4<u32>,
    weight: vec4<f32>,
}

fn rgl_corners(w: RglWarp, p: RglParams) -> RglCorners {
    let s = p.i_phi * w.stride_phi + p.i_theta * w.stride_theta;
    let sp = w.stride_phi;
    let st = w.stride_theta;
    let wp = select(0.0, p.w_phi, sp > 0u);
    let wt = select(0.0, p.w_theta, st > 0u);
    return RglCorners(vec4<u32>(s, s + st, s + sp, s + sp + st),
        vec4<f32>((1.0 - wp) * (1.0 - wt), (1.0 - wp) * wt, wp * (1.0 - wt), wp * wt));
}

// Σ over the corners of weight × array[off + slice · unit + i] (Warp2D::lookup).
fn rgl_lookup(off: u32, c: RglCorners, unit: u32, i: u32) -> f32 {
    let at = vec4<u32>(off + i) + c.slice * unit;
    return dot(c.weight, vec4<f32>(tables[at.x], tables[at.y], tables[at.z], tables[at.w]));
}

// ---- Warp2D: bilinear data on the unit square, sampled and inverted by its CDFs.

// (nx − 1)(ny − 1): densities in index units to the unit square.
fn rgl_cells(w: RglWarp) -> f32 {
    return f32((w.nx - 1u) * (w.ny - 1u));
}

// The patch of a position (lower node, as the index px + py nx) and the fraction inside it.
struct RglPatch {
    p: vec2<u32>,
    f: vec2<f32>,
}

fn rgl_patch(w: RglWarp, pos: vec2<f32>) -> RglPatch {
    let s = clamp(pos, vec2<f32>(0.0), vec2<f32>(1.0)) * vec2<f32>(f32(w.nx - 1u), f32(w.ny - 1u));
    let p = min(vec2<u32>(s), vec2<u32>(w.nx - 2u, w.ny - 2u));
    return RglPatch(p, s - vec2<f32>(p));
}

// The bilinear value at `pos` (Warp2D::eval without the cells factor of a distribution).
fn rgl_warp_value(w: RglWarp, c: RglCorners, pos: vec2<f32>) -> f32 {
    let q = rgl_patch(w, pos);
    let unit = w.nx * w.ny;
    let i = q.p.x + q.p.y * w.nx;
    let v00 = rgl_lookup(w.data, c, unit, i);
    let v10 = rgl_lookup(w.data, c, unit, i + 1u);
    let v01 = rgl_lookup(w.data, c, unit, i + w.nx);
    let v11 = rgl_lookup(w.data, c, unit, i + w.nx + 1u);
    let fx = q.f.x;
    let fy = q.f.y;
    return (1.0 - fy) * ((1.0 - fx) * v00 + fx * v10) + fy * ((1.0 - fx) * v01 + fx * v11);
}

// A position on the unit square and the warp's density there.
struct RglWarped {
    pos: vec2<f32>,
    pdf: f32,
}

// Warp2D::invert: the uniform sample that the warp takes to `pos`, and the density at `pos`.
fn rgl_warp_invert(w: RglWarp, c: RglCorners, pos: vec2<f32>) -> RglWarped {
    let q = rgl_patch(w, pos);
    var sx = q.f.x;
    var sy = q.f.y;
    let unit = w.nx * w.ny;
    let i = q.p.x + q.p.y * w.nx;
    let c0 = (1.0 - sy) * rgl_lookup(w.data, c, unit, i) + sy * rgl_lookup(w.data, c, unit, i + w.nx);
    let c1 = (1.0 - sy) * rgl_lookup(w.data, c, unit, i + 1u)
        + sy * rgl_lookup(w.data, c, unit, i + w.nx + 1u);
    let pdf = (1.0 - sx) * c0 + sx * c1;
    // ∫₀ˣ of the linear c0 → c1, plus the row's CDF before the cell, over the row's total.
    sx *= c0 + 0.5 * sx * (c1 - c0);
    sx += (1.0 - sy) * rgl_lookup(w.conditional, c, unit, i)
        + sy * rgl_lookup(w.conditional, c, unit, i + w.nx);
    let row = q.p.y * w.nx;
    let r0 = rgl_lookup(w.conditional, c, unit, row + w.nx - 1u);
    let r1 = rgl_lookup(w.conditional, c, unit, row + 2u * w.nx - 1u);
    let total = (1.0 - sy) * r0 + sy * r1;
    sx = select(0.0, sx / total, total > 0.0);
    sy *= r0 + 0.5 * sy * (r1 - r0);
    sy += rgl_lookup(w.marginal, c, w.ny, q.p.y);
    return RglWarped(vec2<f32>(sx, sy), pdf * rgl_cells(w));
}

// The t ∈ [0, 1] with ∫₀ᵗ of the linear density a → b equal to s: the root of
// (b − a) t²/2 + a t = s. Departure from the reference's (a − √(a² − 2s(a − b))) / (a − b):
// the same root written 2s / (a + √(a² + 2s(b − a))), which f32 computes without cancelling
// when a ≈ b (the reference's branch for |a − b| < 1e-4 (a + b) is kept).
fn rgl_solve_linear_cdf(a: f32, b: f32, s: f32) -> f32 {
    if (abs(a - b) < 1e-4 * (a + b)) {
        return select(0.5, 2.0 * s / (a + b), a + b > 0.0);
    }
    let d = a + sqrt(max(a * a + 2.0 * s * (b - a), 0.0));
    return select(0.0, 2.0 * s / d, d > 0.0);
}

// find_interval over the rows: the last row whose interpolated marginal CDF is below s.
fn rgl_find_row(w: RglWarp, c: RglCorners, s: f32) -> u32 {
    var first = 1u;
    var len = w.ny - 2u;
    while (len > 0u) {
        let half = len / 2u;
        let middle = first + half;
        if (rgl_lookup(w.marginal, c, w.ny, middle) < s) {
            first = middle + 1u;
            len -= half + 1u;
        } else {
            len = half;
        }
    }
    return min(first - 1u, w.ny - 2u);
}

// find_interval over the columns of rows `offset` and `offset + nx` mixed at sy.
fn rgl_find_column(w: RglWarp, c: RglCorners, offset: u32, sy: f32, s: f32) -> u32 {
    let unit = w.nx * w.ny;
    var first = 1u;
    var len = w.nx - 2u;
    while (len > 0u) {
        let half = len / 2u;
        let middle = first + half;
        let cdf = (1.0 - sy) * rgl_lookup(w.conditional, c, unit, offset + middle)
            + sy * rgl_lookup(w.conditional, c, unit, offset + w.nx + middle);
        if (cdf < s) {
            first = middle + 1u;
            len -= half + 1u;
        } else {
            len = half;
        }
    }
    return min(first - 1u, w.nx - 2u);
}

// Warp2D::sample: the uniform u warped to the distribution (the row by the marginal CDF, the
// column by the conditional CDF at that height), and the density there.
fn rgl_warp_sample(w: RglWarp, c: RglCorners, u: vec2<f32>) -> RglWarped {
    let unit = w.nx * w.ny;
    let lo = 1.0 - RGL_ONE_MINUS_EPSILON;
    var sx = clamp(u.x, lo, RGL_ONE_MINUS_EPSILON);
    var sy = clamp(u.y, lo, RGL_ONE_MINUS_EPSILON);
    let row = rgl_find_row(w, c, sy);
    sy -= rgl_lookup(w.marginal, c, w.ny, row);
    let offset = row * w.nx;
    let r0 = rgl_lookup(w.conditional, c, unit, offset + w.nx - 1u);
    let r1 = rgl_lookup(w.conditional, c, unit, offset + 2u * w.nx - 1u);
    sy = rgl_solve_linear_cdf(r0, r1, sy);
    sx *= (1.0 - sy) * r0 + sy * r1;
    let col = rgl_find_column(w, c, offset, sy, sx);
    sx -= (1.0 - sy) * rgl_lookup(w.conditional, c, unit, offset + col)
        + sy * rgl_lookup(w.conditional, c, unit, offset + w.nx + col);
    let i = offset + col;
    let c0 = (1.0 - sy) * rgl_lookup(w.data, c, unit, i) + sy * rgl_lookup(w.data, c, unit, i + w.nx);
    let c1 = (1.0 - sy) * rgl_lookup(w.data, c, unit, i + 1u)
        + sy * rgl_lookup(w.data, c, unit, i + w.nx + 1u);
    sx = rgl_solve_linear_cdf(c0, c1, sx);
    let pos = vec2<f32>((f32(col) + sx) / f32(w.nx - 1u), (f32(row) + sy) / f32(w.ny - 1u));
    return RglWarped(pos, ((1.0 - sx) * c0 + sx * c1) * rgl_cells(w));
}

// ---- The BSDF.

// The folded directions and the coordinates every lookup of (ωi, ωo) takes (RglBsdf::query).
struct RglQuery {
    wi: vec3<f32>,
    m: vec3<f32>,
    u_wi: vec2<f32>,
    u_m: vec2<f32>,
    params: RglParams,
}

fn rgl_query(t: RglTable, wi: vec3<f32>, wo: vec3<f32>) -> RglQuery {
    let fi = rgl_fold_like(t, wi, wi);
    let fo = rgl_fold_like(t, wo, wi);
    let m = normalize(fi + fo);
    let theta_i = rgl_elevation(fi);
    let phi_i = rgl_azimuth(fi);
    let phi_m = rgl_azimuth(m);
    // φm relative to φi when isotropic, wrapped into [0, 1).
    var u_phi = rgl_phi2u(select(phi_m, phi_m - phi_i, t.isotropic));
    u_phi -= floor(u_phi);
    let u_m = vec2<f32>(rgl_theta2u(rgl_elevation(m)), u_phi);
    return RglQuery(fi, m, vec2<f32>(rgl_theta2u(theta_i), rgl_phi2u(phi_i)), u_m,
        rgl_params(t, phi_i, theta_i));
}

// f(ωi, ωo) (not times cos θo), RglBsdf::eval: the data at vndf⁻¹(u(m)), times D / 4σ with
// the Jacobian, over cos θo, clipped at zero; 0 below the horizon or where σ is not positive.
fn rgl_eval(t: RglTable, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let q = rgl_query(t, wi, wo);
    let vndf = rgl_warp(t, RGL_VNDF);
    let s = rgl_warp_invert(vndf, rgl_corners(vndf, q.params), q.u_m).pos;
    var scale = 1.0;
    if (t.jacobian) {
        let none = RglParams(0u, 0.0, 0u, 0.0);
        let sw = rgl_warp(t, RGL_SIGMA);
        let sigma = rgl_warp_value(sw, rgl_corners(sw, none), q.u_wi);
        if (!(sigma > 0.0)) {
            return vec3<f32>(0.0);
        }
        let nw = rgl_warp(t, RGL_NDF);
        scale = rgl_warp_value(nw, rgl_corners(nw, none), q.u_m) / (4.0 * sigma);
    }
    scale /= wo.z;
    // The three planes share one layout, hence one set of corners.
    let red = rgl_warp(t, RGL_RED);
    let c = rgl_corners(red, q.params);
    var f = vec3<f32>(0.0);
    for (var k = 0u; k < 3u; k++) {
        f[k] = rgl_warp_value(rgl_warp(t, RGL_RED + k), c, s);
    }
    return max(f * scale, vec3<f32>(0.0));
}

// The density of rgl_sample over solid angle, RglBsdf::pdf: luminance(s) · vndf(u(m)) /
// (2π² u sin θm · 4 ⟨ωi, m⟩); 0 below the horizon.
fn rgl_pdf(t: RglTable, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    let q = rgl_query(t, wi, wo);
    let vndf = rgl_warp(t, RGL_VNDF);
    let inv = rgl_warp_invert(vndf, rgl_corners(vndf, q.params), q.u_m);
    let lw = rgl_warp(t, RGL_LUMINANCE);
    let lum = rgl_warp_value(lw, rgl_corners(lw, q.params), inv.pos) * rgl_cells(lw);
    let jacobian = max(2.0 * PI * PI * q.u_m.x * length(q.m.xy), 1e-6) * 4.0 * dot(q.wi, q.m);
    return inv.pdf * lum / jacobian;
}

// ωo sampled for ωi from u, RglBsdf::sample (measured.cpp's sample()): s = luminance.sample
// ((u.y, u.x)), u(m) = vndf.sample(s), m from θm = u² π/2 and φm (+ φi when isotropic),
// ωo = 2 ⟨ωi, m⟩ m − ωi, unfolded with ωi's signs. z <= 0 when there is none.
fn rgl_sample(t: RglTable, wi: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    if (wi.z <= 0.0) {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let wf = rgl_fold_like(t, wi, wi);
    let phi_i = rgl_azimuth(wf);
    let params = rgl_params(t, phi_i, rgl_elevation(wf));
    let lw = rgl_warp(t, RGL_LUMINANCE);
    let s = rgl_warp_sample(lw, rgl_corners(lw, params), u.yx).pos;
    let vndf = rgl_warp(t, RGL_VNDF);
    let u_m = rgl_warp_sample(vndf, rgl_corners(vndf, params), s).pos;
    let theta_m = u_m.x * u_m.x * 0.5 * PI;
    let phi_m = (2.0 * u_m.y - 1.0) * PI + select(0.0, phi_i, t.isotropic);
    let m = vec3<f32>(cos(phi_m) * sin(theta_m), sin(phi_m) * sin(theta_m), cos(theta_m));
    return rgl_fold_like(t, 2.0 * dot(wf, m) * m - wf, wi);
}
