// Include-only. The tabulated (and stretched) NDF of a fit on the GPU, the twin of
// facet_fit::tabulated::TabulatedNdf: D₀ on nu nodes u = sqrt(θ / (π/2)) × nphi azimuths,
// G1₀ on ng nodes evenly in θ, sampling cells (nu − 1) × nphi with their CDF and pdf.
// Block in `tables` at `tab_offset`: [nu, nphi, ng, -] then d, g1, cdf, cell_pdf.

struct TabNdf {
    base: u32,
    nu: u32,
    nphi: u32,
    ng: u32,
    alpha_x: f32,
    alpha_y: f32,
    rotation: f32,
}

fn tab_ndf(m: Material) -> TabNdf {
    let o = m.tab_offset;
    return TabNdf(o + 4u, u32(tables[o]), u32(tables[o + 1u]), u32(tables[o + 2u]), m.alpha_x, m.alpha_y, m.rotation);
}

fn tab_d_off(t: TabNdf) -> u32 { return t.base; }
fn tab_g1_off(t: TabNdf) -> u32 { return t.base + t.nu * t.nphi; }
fn tab_cdf_off(t: TabNdf) -> u32 { return tab_g1_off(t) + t.ng * t.nphi; }
fn tab_pdf_off(t: TabNdf) -> u32 { return tab_cdf_off(t) + (t.nu - 1u) * t.nphi; }

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

fn tab_local(t: TabNdf, w: vec3<f32>) -> vec3<f32> {
    let c = cos(t.rotation);
    let s = sin(t.rotation);
    return vec3<f32>(c * w.x + s * w.y, -s * w.x + c * w.y, w.z);
}

// D(h) = D₀(h₀) cos⁴θ₀ / (cos⁴θh αx αy), h₀ ∝ (hx/αx, hy/αy, hz).
fn tab_d(t: TabNdf, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let l = tab_local(t, h);
    let h0 = normalize(vec3<f32>(l.x / t.alpha_x, l.y / t.alpha_y, l.z));
    let theta = acos(clamp(h0.z, -1.0, 1.0));
    let x = min(sqrt(theta / (0.5 * PI)), 1.0) * f32(t.nu - 1u);
    let r = h0.z / l.z;
    return tab_bilinear(tab_d_off(t), t.nu, t.nphi, x, azimuth_of(h0)) * r * r * r * r / (t.alpha_x * t.alpha_y);
}

// Λ(w) = 1/G1₀(w₀) − 1, w₀ ∝ (αx wx, αy wy, wz).
fn tab_lambda(t: TabNdf, w: vec3<f32>) -> f32 {
    if (w.z <= 0.0) {
        return 3.0e38;
    }
    let l = tab_local(t, w);
    let w0 = normalize(vec3<f32>(l.x * t.alpha_x, l.y * t.alpha_y, l.z));
    let theta = acos(clamp(w0.z, -1.0, 1.0));
    let g1 = tab_bilinear(tab_g1_off(t), t.ng, t.nphi, theta / (0.5 * PI) * f32(t.ng - 1u), azimuth_of(w0));
    if (g1 <= 0.0) {
        return 3.0e38;
    }
    return max(1.0 / g1 - 1.0, 0.0);
}

fn u_node_theta(k: u32, nu: u32) -> f32 {
    let u = f32(k) / f32(nu - 1u);
    return u * u * 0.5 * PI;
}

// A normal with density tab_pdf: a base cell by its mass, uniform in solid angle inside it,
// then stretched.
fn tab_sample(t: TabNdf, u: vec2<f32>) -> vec3<f32> {
    let n = (t.nu - 1u) * t.nphi;
    let co = tab_cdf_off(t);
    // First cell with cdf > u.x.
    var lo = 0u;
    var hi = n - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (tables[co + mid] <= u.x) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let c = lo;
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
    let cr = cos(t.rotation);
    let sr = sin(t.rotation);
    return vec3<f32>(cr * hl.x - sr * hl.y, sr * hl.x + cr * hl.y, hl.z);
}

// q₀(h₀) cos³θ₀ / (αx αy cos³θh).
fn tab_pdf(t: TabNdf, h: vec3<f32>) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let l = tab_local(t, h);
    let h0 = normalize(vec3<f32>(l.x / t.alpha_x, l.y / t.alpha_y, l.z));
    let theta = acos(clamp(h0.z, -1.0, 1.0));
    let x = min(sqrt(theta / (0.5 * PI)), 1.0) * f32(t.nu - 1u);
    let k = min(u32(x), t.nu - 2u);
    let lp = min(u32(azimuth_of(h0) / (2.0 * PI) * f32(t.nphi)), t.nphi - 1u);
    let r = h0.z / l.z;
    return tables[tab_pdf_off(t) + k * t.nphi + lp] * r * r * r / (t.alpha_x * t.alpha_y);
}
