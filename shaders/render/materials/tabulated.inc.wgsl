// Include-only. The tabulated (and stretched) NDF of a fit on the GPU, the twin of
// facet_fit::tabulated::TabulatedNdf: D₀ on nu nodes u = sqrt(θ / (π/2)) × nphi azimuths,
// G1₀ on ng nodes evenly in θ, sampling cells (nu − 1) × nphi with their CDF and pdf (D cos θ),
// and the visible-normal slices of facet_fit::visible_tables (n_theta_v × n_phi_v slices of
// rows × columns cells, each with its CDF and pdf). Block in `tables` at the lobe's `table`:
// [nu, nphi, ng, n_theta_v, n_phi_v, rows, columns, -] then d, g1, cdf, cell_pdf, vis_cdf,
// vis_pdf. The includer declares `tables`.

#include "common/math.inc.wgsl"

struct TabNdf {
    base: u32,
    nu: u32,
    nphi: u32,
    ng: u32,
    n_theta_v: u32,
    n_phi_v: u32,
    rows: u32,
    columns: u32,
    alpha_x: f32,
    alpha_y: f32,
    rotation: f32,
}

fn tab_ndf_at(o: u32, alpha_x: f32, alpha_y: f32, rotation: f32) -> TabNdf {
    let n = array<u32, 7>(u32(tables[o]), u32(tables[o + 1u]), u32(tables[o + 2u]), u32(tables[o + 3u]),
        u32(tables[o + 4u]), u32(tables[o + 5u]), u32(tables[o + 6u]));
    return TabNdf(o + 8u, n[0], n[1], n[2], n[3], n[4], n[5], n[6], alpha_x, alpha_y, rotation);
}

fn tab_d_off(t: TabNdf) -> u32 { return t.base; }
fn tab_g1_off(t: TabNdf) -> u32 { return t.base + t.nu * t.nphi; }
fn tab_cdf_off(t: TabNdf) -> u32 { return tab_g1_off(t) + t.ng * t.nphi; }
fn tab_pdf_off(t: TabNdf) -> u32 { return tab_cdf_off(t) + (t.nu - 1u) * t.nphi; }
fn tab_vis_cdf_off(t: TabNdf) -> u32 { return tab_pdf_off(t) + (t.nu - 1u) * t.nphi; }
fn tab_vis_pdf_off(t: TabNdf) -> u32 { return tab_vis_cdf_off(t) + t.n_theta_v * t.n_phi_v * t.rows * t.columns; }

// θ of a unit vector, accurate near the pole where f32 acos(z) is not.
fn polar_angle(w: vec3<f32>) -> f32 {
    return atan2(length(w.xy), w.z);
}

fn azimuth_of(w: vec3<f32>) -> f32 {
    let p = atan2(w.y, w.x);
    return select(p, p + 2.0 * PI, p < 0.0);
}

// Bilinear on an (n × nphi) grid at row coordinate x, φ periodic.
fn tab_bilinear(off: u32, n: u32, nphi: u32, x: f32, phi: f32) -> f32 {
    let xc = clamp(x, 0.0, f32(n - 1u));
    let k = min(u32(xc), n - 2u);
    let t = xc - f32(k);
    if (nphi == 1u) {
        return mix(tables[off + k], tables[off + k + 1u], t);
    }
    let y = phi / (2.0 * PI) * f32(nphi);
    let l = min(u32(y), nphi - 1u);
    let l1 = (l + 1u) % nphi;
    let sy = y - f32(l);
    let r0 = mix(tables[off + k * nphi + l], tables[off + k * nphi + l1], sy);
    let r1 = mix(tables[off + (k + 1u) * nphi + l], tables[off + (k + 1u) * nphi + l1], sy);
    return mix(r0, r1, t);
}

// Where the base NDF is read for a normal h: h₀ ∝ (hx/αx, hy/αy, hz) in the rotated frame, its
// row coordinate x on the u = sqrt(θ / (π/2)) nodes, and r = cos θ₀ / cos θh.
struct TabBase {
    h0: vec3<f32>,
    x: f32,
    r: f32,
}

fn tab_base(t: TabNdf, h: vec3<f32>) -> TabBase {
    let l = unrotate_z(h, t.rotation);
    let h0 = normalize(vec3<f32>(l.x / t.alpha_x, l.y / t.alpha_y, l.z));
    let theta = polar_angle(h0);
    let x = min(sqrt(theta / (0.5 * PI)), 1.0) * f32(t.nu - 1u);
    return TabBase(h0, x, h0.z / l.z);
}

// D(h) = D₀(h₀) cos⁴θ₀ / (cos⁴θh αx αy), h₀ ∝ (hx/αx, hy/αy, hz).
fn tab_d(t: TabNdf, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let b = tab_base(t, h);
    let r = b.r;
    return tab_bilinear(tab_d_off(t), t.nu, t.nphi, b.x, azimuth_of(b.h0)) * r * r * r * r / (t.alpha_x * t.alpha_y);
}

// Λ(w) = 1/G1₀(w₀) − 1, w₀ ∝ (αx wx, αy wy, wz).
fn tab_lambda(t: TabNdf, w: vec3<f32>) -> f32 {
    if (w.z <= 0.0) {
        return 3.0e38;
    }
    let l = unrotate_z(w, t.rotation);
    let w0 = normalize(vec3<f32>(l.x * t.alpha_x, l.y * t.alpha_y, l.z));
    let theta = polar_angle(w0);
    let g1 = tab_bilinear(tab_g1_off(t), t.ng, t.nphi, theta / (0.5 * PI) * f32(t.ng - 1u), azimuth_of(w0));
    if (g1 <= 0.0) {
        return 3.0e38;
    }
    return max(1.0 / g1 - 1.0, 0.0);
}

// First of n cells at `co` whose cumulative mass exceeds x.
fn cdf_find(co: u32, n: u32, x: f32) -> u32 {
    var lo = 0u;
    var hi = n - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (tables[co + mid] <= x) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

fn u_node_theta(k: u32, nu: u32) -> f32 {
    let u = f32(k) / f32(nu - 1u);
    return u * u * 0.5 * PI;
}

// A normal with density tab_pdf: a base cell by its mass, uniform in solid angle inside it,
// then stretched.
fn tab_sample(t: TabNdf, u: vec2<f32>) -> vec3<f32> {
    let co = tab_cdf_off(t);
    let c = cdf_find(co, (t.nu - 1u) * t.nphi, u.x);
    let before = select(0.0, tables[co + c - 1u], c > 0u);
    let r = clamp((u.x - before) / max(tables[co + c] - before, 1e-30), 0.0, 1.0);
    let k = c / t.nphi;
    let l = c % t.nphi;
    let ca = cos(u_node_theta(k, t.nu));
    let cb = cos(u_node_theta(k + 1u, t.nu));
    let cos_t = clamp(ca + r * (cb - ca), -1.0, 1.0);
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let phi = (f32(l) + u.y) * 2.0 * PI / f32(t.nphi);
    let h0 = vec3<f32>(sin_t * cos(phi), sin_t * sin(phi), cos_t);
    let hl = normalize(vec3<f32>(h0.x * t.alpha_x, h0.y * t.alpha_y, h0.z));
    return rotate_z(hl, t.rotation);
}

// q₀(h₀) cos³θ₀ / (αx αy cos³θh).
fn tab_pdf(t: TabNdf, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let b = tab_base(t, h);
    let k = min(u32(b.x), t.nu - 2u);
    let lp = min(u32(azimuth_of(b.h0) / (2.0 * PI) * f32(t.nphi)), t.nphi - 1u);
    let r = b.r;
    return tables[tab_pdf_off(t) + k * t.nphi + lp] * r * r * r / (t.alpha_x * t.alpha_y);
}

// ---- Visible normals (facet_fit::visible_tables::VisibleTables) ---------------------------

// The view slices around the base view v: θv nodes (j, j + 1) with weight t for j + 1, φv
// nodes (p, p1) with weight s for p1 (isotropic: p = p1 = 0, s = 0), and the azimuth the
// slices' columns start from.
struct TabSlices {
    j: u32,
    t: f32,
    p: u32,
    p1: u32,
    s: f32,
    phi_ref: f32,
}

fn tab_slices(t: TabNdf, v: vec3<f32>) -> TabSlices {
    var q: TabSlices;
    let x = clamp(polar_angle(v) / (0.5 * PI), 0.0, 1.0) * f32(t.n_theta_v - 1u);
    q.j = min(u32(x), t.n_theta_v - 2u);
    q.t = x - f32(q.j);
    if (t.n_phi_v == 1u) {
        q.phi_ref = azimuth_of(v);
        return q;
    }
    let y = azimuth_of(v) / (2.0 * PI) * f32(t.n_phi_v);
    q.p = min(u32(y), t.n_phi_v - 1u);
    q.p1 = (q.p + 1u) % t.n_phi_v;
    q.s = y - f32(q.p);
    return q;
}

// The first choice (a) with probability 1 − w, else b; u rescaled to [0, 1].
fn tab_choose(a: u32, b: u32, w: f32, u: f32) -> vec2<f32> {
    if (u < 1.0 - w) {
        return vec2<f32>(f32(a), min(u / (1.0 - w), 1.0));
    }
    return vec2<f32>(f32(b), clamp((u - (1.0 - w)) / w, 0.0, 1.0));
}

fn tab_row_cos(r: u32, rows: u32) -> vec2<f32> {
    let a = f32(r) / f32(rows);
    let b = f32(r + 1u) / f32(rows);
    return vec2<f32>(cos(a * a * 0.5 * PI), cos(b * b * 0.5 * PI));
}

// Base-space view of ωo: w₀ ∝ (αx wx, αy wy, wz) in the rotated frame.
fn tab_base_view(t: TabNdf, wo: vec3<f32>) -> vec3<f32> {
    let l = unrotate_z(wo, t.rotation);
    return normalize(vec3<f32>(l.x * t.alpha_x, l.y * t.alpha_y, max(l.z, 0.0)));
}

// A normal visible from ωo with density tab_pdf_visible: a slice next to w₀ by its weight,
// a cell by its projected-area mass, uniform in solid angle inside it, then stretched.
fn tab_sample_visible(t: TabNdf, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let v = tab_base_view(t, wo);
    let q = tab_slices(t, v);
    let a = tab_choose(q.j, q.j + 1u, q.t, u.x);
    let b = tab_choose(q.p, q.p1, q.s, u.y);
    let slice = u32(a.x) * t.n_phi_v + u32(b.x);
    let cells = t.rows * t.columns;
    let co = tab_vis_cdf_off(t) + slice * cells;
    let c = cdf_find(co, cells, a.y);
    let before = select(0.0, tables[co + c - 1u], c > 0u);
    let rest = clamp((a.y - before) / max(tables[co + c] - before, 1e-30), 0.0, 1.0);
    let rc = tab_row_cos(c / t.columns, t.rows);
    let cos_t = clamp(rc.x + rest * (rc.y - rc.x), -1.0, 1.0);
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let phi = q.phi_ref + (f32(c % t.columns) + b.y) * 2.0 * PI / f32(t.columns);
    let h0 = vec3<f32>(sin_t * cos(phi), sin_t * sin(phi), cos_t);
    let hl = normalize(vec3<f32>(h0.x * t.alpha_x, h0.y * t.alpha_y, h0.z));
    return rotate_z(hl, t.rotation);
}

// q_w₀(h₀) cos³θ₀ / (αx αy cos³θh), q_w₀ the slices' mixture of cell densities.
fn tab_pdf_visible(t: TabNdf, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let v = tab_base_view(t, wo);
    let q = tab_slices(t, v);
    let base = tab_base(t, h);
    let h0 = base.h0;
    let u = sqrt(polar_angle(h0) / (0.5 * PI));
    let r = min(u32(u * f32(t.rows)), t.rows - 1u);
    var dphi = azimuth_of(h0) - q.phi_ref;
    dphi = dphi - 2.0 * PI * floor(dphi / (2.0 * PI));
    let col = min(u32(dphi / (2.0 * PI) * f32(t.columns)), t.columns - 1u);
    let cells = t.rows * t.columns;
    let at = tab_vis_pdf_off(t) + r * t.columns + col;
    let p0 = q.j * t.n_phi_v;
    let p1 = (q.j + 1u) * t.n_phi_v;
    let lo = (1.0 - q.s) * tables[at + (p0 + q.p) * cells] + q.s * tables[at + (p0 + q.p1) * cells];
    let hi = (1.0 - q.s) * tables[at + (p1 + q.p) * cells] + q.s * tables[at + (p1 + q.p1) * cells];
    let z = base.r;
    return mix(lo, hi, q.t) * z * z * z / (t.alpha_x * t.alpha_y);
}
