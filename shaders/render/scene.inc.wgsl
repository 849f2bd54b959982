// Include-only. Group 1 of the integrator stages: the scene (Rust: facet_render::resources).
// Geometry, BVH, materials, textures, lights and one f32 `tables` buffer holding the light CDF,
// the environment map and its CDFs, the Fresnel tables and the tabulated NDFs at offsets.

#include "render/tags.inc.wgsl"
#include "common/math.inc.wgsl"
#include "common/microfacet.inc.wgsl"
#include "render/light_tree.inc.wgsl"
#include "render/none.inc.wgsl"

// Rust: facet_render::materials::GpuMaterial. The header every class reads, then the class
// block, whose fields its class defines (render/materials/blocks.inc.wgsl decodes them).
struct Material {
    // emitted radiance (rgb) and its texture (NONE: none)
    emissive: vec3<f32>,
    tex_emissive: u32,
    // the tangent-space normal map (NONE: none) and its xy scale
    tex_normal: u32,
    normal_scale: f32,
    // the shading queue its hits go to
    queue: u32,
    // a fit's coat layer: its block in `tables` (NONE: no coat), render/materials/coat.inc.wgsl
    coat: u32,
    block: array<u32, 16>,
}

// Rust: facet_render::layout::gpu_types::GpuLight.
struct Light {
    kind: u32,
    // the triangle of a LIGHT_TRIANGLE
    prim: u32,
    cos_inner: f32,
    cos_outer: f32,
    position: vec4<f32>,
    // unit direction the light travels (spot, directional)
    direction: vec4<f32>,
    // point/spot intensity, directional irradiance
    intensity: vec4<f32>,
    // its leaf in the light BVH, NONE outside it
    leaf: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(1) @binding(0) var<storage, read> bvh_nodes: array<CwNode>;
@group(1) @binding(1) var<storage, read> bvh_primitives: array<u32>;
@group(1) @binding(2) var<storage, read> bvh_triangles: array<vec4<f32>>;
// Regions of n_vertices each: position, normal, tangent (w the bitangent sign), uv (xy).
@group(1) @binding(3) var<storage, read> vertices: array<vec4<f32>>;
// i0, i1, i2, material.
@group(1) @binding(4) var<storage, read> triangles: array<vec4<u32>>;
@group(1) @binding(5) var<storage, read> materials: array<Material>;
// Headers (offset, width, height, srgb) per texture, then RGBA8 texels.
@group(1) @binding(6) var<storage, read> textures: array<u32>;
@group(1) @binding(7) var<storage, read> lights: array<Light>;
@group(1) @binding(8) var<storage, read> tables: array<f32>;
// Light index of each triangle, NONE when it does not emit (one entry when nothing emits).
@group(1) @binding(9) var<storage, read> triangle_light: array<u32>;
// The light BVH (one unused node without one: frame.scene.light_tree_nodes == 0).
@group(1) @binding(10) var<storage, read> light_tree: array<LightNode>;

#include "render/materials/blocks.inc.wgsl"

fn vertex(region: u32, i: u32) -> vec4<f32> {
    return vertices[region * frame.scene.n_vertices + i];
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// ---- textures: bilinear, repeat, sRGB decoded --------------------------------------------

fn srgb_to_linear(c: f32) -> f32 {
    return select(pow((c + 0.055) / 1.055, 2.4), c / 12.92, c <= 0.04045);
}

fn texel(t: u32, x: i32, y: i32) -> vec4<f32> {
    let off = textures[4u * t];
    let w = i32(textures[4u * t + 1u]);
    let h = i32(textures[4u * t + 2u]);
    let xx = ((x % w) + w) % w;
    let yy = ((y % h) + h) % h;
    let c = unpack4x8unorm(textures[off + u32(yy * w + xx)]);
    if (textures[4u * t + 3u] != 0u) {
        return vec4<f32>(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z), c.w);
    }
    return c;
}

fn texture_sample(t: u32, uv: vec2<f32>) -> vec4<f32> {
    let w = f32(textures[4u * t + 1u]);
    let h = f32(textures[4u * t + 2u]);
    let x = uv.x * w - 0.5;
    let y = uv.y * h - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let a = mix(texel(t, i32(x0), i32(y0)), texel(t, i32(x0) + 1, i32(y0)), fx);
    let b = mix(texel(t, i32(x0), i32(y0) + 1), texel(t, i32(x0) + 1, i32(y0) + 1), fx);
    return mix(a, b, fy);
}

// ---- surfaces -------------------------------------------------------------------------------

struct Surface {
    p: vec3<f32>,
    // geometric normal, facing the incoming ray's origin
    ng: vec3<f32>,
    // shading frame (normal-mapped), n on the side of ng
    n: vec3<f32>,
    // the interpolated vertex normal (before the normal map) and tangent (w: the bitangent's sign)
    n_vertex: vec3<f32>,
    tangent: vec4<f32>,
    t: vec3<f32>,
    b: vec3<f32>,
    uv: vec2<f32>,
    material: u32,
    // world-space dP/du and dP/dv of the triangle's UV mapping
    dpdu: vec3<f32>,
    dpdv: vec3<f32>,
    // |Δn| / |Δp| over the triangle's edges: the curvature the ray cone sees
    curvature: f32,
    area: f32,
    front: bool,
}

fn surface_at(prim: u32, bu: f32, bv: f32, wo: vec3<f32>) -> Surface {
    let tri = triangles[prim];
    let p0 = vertex(0u, tri.x).xyz;
    let p1 = vertex(0u, tri.y).xyz;
    let p2 = vertex(0u, tri.z).xyz;
    let bw = 1.0 - bu - bv;
    var s: Surface;
    s.p = bw * p0 + bu * p1 + bv * p2;
    let c = cross(p1 - p0, p2 - p0);
    s.area = 0.5 * length(c);
    var ng = normalize(c);
    let n0 = vertex(1u, tri.x).xyz;
    let n1 = vertex(1u, tri.y).xyz;
    let n2 = vertex(1u, tri.z).xyz;
    var n = normalize(bw * n0 + bu * n1 + bv * n2);
    let tg = bw * vertex(2u, tri.x) + bu * vertex(2u, tri.y) + bv * vertex(2u, tri.z);
    let uv0 = vertex(3u, tri.x).xy;
    let uv1 = vertex(3u, tri.y).xy;
    let uv2 = vertex(3u, tri.z).xy;
    s.uv = bw * uv0 + bu * uv1 + bv * uv2;
    s.material = tri.w;
    // Two-sided: the geometric normal faces wo, the shading normal follows it.
    s.front = dot(ng, wo) >= 0.0;
    if (!s.front) {
        ng = -ng;
    }
    if (dot(n, ng) < 0.0) {
        n = -n;
    }
    // [dp1 dp2] = [dP/du dP/dv] [duv1 duv2]
    let dp1 = p1 - p0;
    let dp2 = p2 - p0;
    let duv1 = uv1 - uv0;
    let duv2 = uv2 - uv0;
    let det = duv1.x * duv2.y - duv1.y * duv2.x;
    if (abs(det) > 1e-12) {
        s.dpdu = (dp1 * duv2.y - dp2 * duv1.y) / det;
        s.dpdv = (dp2 * duv1.x - dp1 * duv2.x) / det;
    } else {
        s.dpdu = vec3<f32>(0.0);
        s.dpdv = vec3<f32>(0.0);
    }
    s.curvature = max(max(length(n1 - n0) / max(length(dp1), 1e-20), length(n2 - n0) / max(length(dp2), 1e-20)),
                      length(n2 - n1) / max(length(p2 - p1), 1e-20));
    let m = materials[s.material];
    s.n_vertex = n;
    s.tangent = tg;
    if (m.tex_normal != NONE) {
        n = normal_mapped(n, tg, m.tex_normal, m.normal_scale, s.uv);
    }
    s.ng = ng;
    s.n = n;
    // Tangent frame: x along the interpolated tangent (the NDF's rotation is relative to it).
    var t = tg.xyz - n * dot(n, tg.xyz);
    if (dot(t, t) < 1e-12) {
        t = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
        t = t - n * dot(n, t);
    }
    s.t = normalize(t);
    s.b = cross(n, s.t);
    return s;
}

// Tangent-space normal map (glTF) about the vertex normal n: n' = normalize(t x + b y + n z),
// xy scaled; n where the map gives no direction.
fn normal_mapped(n: vec3<f32>, tg: vec4<f32>, tex: u32, scale: f32, uv: vec2<f32>) -> vec3<f32> {
    let tn = texture_sample(tex, uv).xyz * 2.0 - 1.0;
    let t0 = normalize(tg.xyz - n * dot(n, tg.xyz));
    let b0 = cross(n, t0) * select(-1.0, 1.0, tg.w >= 0.0);
    let mapped = normalize(t0 * tn.x * scale + b0 * tn.y * scale + n * max(tn.z, 1e-3));
    return select(n, mapped, all(mapped == mapped));
}

fn to_local(s: Surface, w: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(w, s.t), dot(w, s.b), dot(w, s.n));
}

fn to_world(s: Surface, w: vec3<f32>) -> vec3<f32> {
    return w.x * s.t + w.y * s.b + w.z * s.n;
}

// A ray origin off the surface on the side of w (self-intersection).
fn offset_origin(s: Surface, w: vec3<f32>) -> vec3<f32> {
    let e = frame.ray_epsilon * (1.0 + max(max(abs(s.p.x), abs(s.p.y)), abs(s.p.z)));
    return s.p + select(-s.ng, s.ng, dot(w, s.ng) >= 0.0) * e;
}

fn emitted(s: Surface) -> vec3<f32> {
    let m = materials[s.material];
    var le = m.emissive;
    if (m.tex_emissive != NONE) {
        le *= texture_sample(m.tex_emissive, s.uv).xyz;
    }
    return select(vec3<f32>(0.0), le, s.front);
}

// ---- environment ---------------------------------------------------------------------------
// Equirectangular, Y up (facet_render::scene::environment): φ = atan2(z, x) in [0, 2π),
// u = φ / 2π, θ = acos(y), v = θ / π, row 0 straight up.

fn env_uv(d: vec3<f32>) -> vec2<f32> {
    var phi = atan2(d.z, d.x);
    if (phi < 0.0) {
        phi += 2.0 * PI;
    }
    return vec2<f32>(phi / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
}

fn env_pixel(d: vec3<f32>) -> vec2<u32> {
    let uv = env_uv(d);
    return vec2<u32>(min(u32(uv.x * f32(frame.scene.env_width)), frame.scene.env_width - 1u),
                     min(u32(uv.y * f32(frame.scene.env_height)), frame.scene.env_height - 1u));
}

fn env_radiance(d: vec3<f32>) -> vec3<f32> {
    if (frame.scene.env_kind == ENV_CONSTANT) {
        return frame.scene.env_color.xyz;
    }
    if (frame.scene.env_kind == ENV_MAP) {
        let px = env_pixel(d);
        let o = frame.scene.env_texels + 3u * (px.y * frame.scene.env_width + px.x);
        return vec3<f32>(tables[o], tables[o + 1u], tables[o + 2u]);
    }
    return vec3<f32>(0.0);
}

// Discrete probability of a pixel: cdf differences of its row and column.
fn env_pixel_prob(px: vec2<u32>) -> f32 {
    let w1 = frame.scene.env_width + 1u;
    let row = tables[frame.scene.env_marginal + px.y + 1u] - tables[frame.scene.env_marginal + px.y];
    let c = frame.scene.env_conditional + px.y * w1 + px.x;
    return row * (tables[c + 1u] - tables[c]);
}

// Solid-angle density of env_sample: p · w · h / (2π² sin θ).
fn env_pdf(d: vec3<f32>) -> f32 {
    if (frame.scene.env_kind == ENV_CONSTANT) {
        return 1.0 / (4.0 * PI);
    }
    if (frame.scene.env_kind != ENV_MAP) {
        return 0.0;
    }
    let sin_t = sqrt(max(1.0 - d.y * d.y, 0.0));
    if (sin_t <= 0.0) {
        return 0.0;
    }
    let px = env_pixel(d);
    return env_pixel_prob(px) * f32(frame.scene.env_width * frame.scene.env_height) / (2.0 * PI * PI * sin_t);
}

// Largest i in [0, n) with cdf[base + i] <= u.
fn cdf_search(base: u32, n: u32, u: f32) -> u32 {
    var lo = 0u;
    var hi = n;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (tables[base + mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

fn env_sample(u: vec2<f32>) -> vec3<f32> {
    if (frame.scene.env_kind != ENV_MAP) {
        // Uniform sphere.
        let y = 1.0 - 2.0 * u.x;
        let r = sqrt(max(1.0 - y * y, 0.0));
        let phi = 2.0 * PI * u.y;
        return vec3<f32>(r * cos(phi), y, r * sin(phi));
    }
    let h = frame.scene.env_height;
    let w = frame.scene.env_width;
    let row = cdf_search(frame.scene.env_marginal, h + 1u, u.y);
    let r0 = tables[frame.scene.env_marginal + row];
    let r1 = tables[frame.scene.env_marginal + row + 1u];
    let fy = clamp((u.y - r0) / max(r1 - r0, 1e-30), 0.0, 1.0);
    let base = frame.scene.env_conditional + row * (w + 1u);
    let col = cdf_search(base, w + 1u, u.x);
    let c0 = tables[base + col];
    let c1 = tables[base + col + 1u];
    let fx = clamp((u.x - c0) / max(c1 - c0, 1e-30), 0.0, 1.0);
    let uu = (f32(col) + fx) / f32(w);
    let vv = (f32(row) + fy) / f32(h);
    let phi = 2.0 * PI * uu;
    let theta = PI * vv;
    return vec3<f32>(sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi));
}

// ---- lights ----------------------------------------------------------------------------------

// The CDF's probability of light i (in the tree's absence).
fn light_pmf(i: u32) -> f32 {
    return tables[frame.scene.light_cdf + i + 1u] - tables[frame.scene.light_cdf + i];
}

// The probability that next-event estimation at p, geometric normal n, picks light i: by the
// light BVH for a light in it (asked with probability light_tree_share), else by the CDF.
fn light_select_pmf(i: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let share = frame.scene.light_tree_share;
    let leaf = lights[i].leaf;
    if (leaf != NONE) {
        return share * light_tree_pmf(leaf, p, n);
    }
    return (1.0 - share) * light_pmf(i);
}

struct LightSample {
    wi: vec3<f32>,
    dist: f32,
    // Le · (geometry) / pdf, everything but the BSDF and cos θi
    weight: vec3<f32>,
    // solid-angle pdf including the light choice; 0 for delta lights (no MIS)
    pdf: f32,
}

// The solid-angle pdf of light sampling at the shading point p (geometric normal n; `sel` the
// point the selection is asked at) toward point q of emissive triangle prim (normal nq, area).
fn triangle_light_pdf(prim: u32, p: vec3<f32>, sel: vec3<f32>, n: vec3<f32>, q: vec3<f32>, nq: vec3<f32>, area: f32) -> f32 {
    let l = triangle_light[prim];
    if (l == NONE) {
        return 0.0;
    }
    return triangle_solid_angle_pdf(light_select_pmf(l, sel, n), p, q, nq, area);
}

// The solid-angle pdf at p of a uniform point q on a triangle (normal nq, area) picked with
// probability pmf: pmf d² / (cos θq A).
fn triangle_solid_angle_pdf(pmf: f32, p: vec3<f32>, q: vec3<f32>, nq: vec3<f32>, area: f32) -> f32 {
    let d = q - p;
    let d2 = dot(d, d);
    let cos_l = abs(dot(nq, normalize(d)));
    if (cos_l <= 0.0 || area <= 0.0) {
        return 0.0;
    }
    return pmf * d2 / (cos_l * area);
}

// Next-event estimation's light for the shading point p: the light BVH asked at `sel` (p lifted
// off the surface, where the continuation ray starts, so that the emission a BSDF sample finds
// asks it at the same point) with geometric normal n, or the CDF.
fn sample_light(p: vec3<f32>, sel: vec3<f32>, n: vec3<f32>, u0_in: f32, u: vec2<f32>) -> LightSample {
    var ls: LightSample;
    ls.pdf = 0.0;
    ls.weight = vec3<f32>(0.0);
    ls.dist = 0.0;
    ls.wi = vec3<f32>(0.0, 0.0, 1.0);
    if (frame.scene.n_lights == 0u) {
        return ls;
    }
    let share = frame.scene.light_tree_share;
    var i = 0u;
    var pmf = 0.0;
    if (u0_in < share) {
        let pick = light_tree_sample(sel, n, min(u0_in / share, ONE_MINUS_EPSILON));
        i = pick.light;
        pmf = share * pick.pmf;
    } else {
        let u0 = select(u0_in, (u0_in - share) / (1.0 - share), share > 0.0);
        i = min(cdf_search(frame.scene.light_cdf, frame.scene.n_lights + 1u, u0), frame.scene.n_lights - 1u);
        pmf = (1.0 - share) * light_pmf(i);
    }
    if (pmf <= 0.0 || i >= frame.scene.n_lights) {
        return ls;
    }
    let l = lights[i];
    if (l.kind == LIGHT_POINT || l.kind == LIGHT_SPOT) {
        let d = l.position.xyz - p;
        let d2 = dot(d, d);
        ls.dist = sqrt(d2);
        ls.wi = d / ls.dist;
        var falloff = 1.0;
        if (l.kind == LIGHT_SPOT) {
            // glTF: smooth attenuation between the outer and inner cone.
            let c = dot(-ls.wi, l.direction.xyz);
            let t = clamp((c - l.cos_outer) / max(l.cos_inner - l.cos_outer, 1e-4), 0.0, 1.0);
            falloff = t * t;
        }
        ls.weight = l.intensity.xyz * falloff / (d2 * pmf);
        ls.pdf = 0.0;
    } else if (l.kind == LIGHT_DIRECTIONAL) {
        ls.wi = -l.direction.xyz;
        ls.dist = 4.0 * frame.scene.scene_radius;
        ls.weight = l.intensity.xyz / pmf;
        ls.pdf = 0.0;
    } else if (l.kind == LIGHT_TRIANGLE) {
        let tri = triangles[l.prim];
        let p0 = vertex(0u, tri.x).xyz;
        let p1 = vertex(0u, tri.y).xyz;
        let p2 = vertex(0u, tri.z).xyz;
        // Uniform point on the triangle: b0 = 1 − √u0', b1 = u1 √u0'.
        let su = sqrt(u.x);
        let q = (1.0 - su) * p0 + su * (1.0 - u.y) * p1 + su * u.y * p2;
        let c = cross(p1 - p0, p2 - p0);
        let area = 0.5 * length(c);
        let nq = normalize(c);
        let d = q - p;
        ls.dist = length(d);
        ls.wi = d / ls.dist;
        // The pmf it was picked with (the tree's from the top, equal within rounding to
        // light_select_pmf's from its leaf, which MIS uses when a BSDF sample hits it).
        ls.pdf = triangle_solid_angle_pdf(pmf, p, q, nq, area);
        let m = materials[tri.w];
        // One-sided emitters: only the front (counter-clockwise) side emits.
        var le = m.emissive;
        if (m.tex_emissive != NONE) {
            let uv = (1.0 - su) * vertex(3u, tri.x).xy + su * (1.0 - u.y) * vertex(3u, tri.y).xy + su * u.y * vertex(3u, tri.z).xy;
            le *= texture_sample(m.tex_emissive, uv).xyz;
        }
        if (dot(nq, -ls.wi) > 0.0 && ls.pdf > 0.0) {
            ls.weight = le / ls.pdf;
        } else {
            ls.pdf = 0.0;
        }
    } else {
        ls.wi = env_sample(u);
        ls.dist = 4.0 * frame.scene.scene_radius;
        ls.pdf = pmf * env_pdf(ls.wi);
        if (ls.pdf > 0.0) {
            ls.weight = env_radiance(ls.wi) / ls.pdf;
        }
    }
    return ls;
}

// The light index of the environment, if it is one of the lights.
fn env_light_pmf() -> f32 {
    for (var i = 0u; i < frame.scene.n_lights; i++) {
        if (lights[i].kind == LIGHT_ENVIRONMENT) {
            return (1.0 - frame.scene.light_tree_share) * light_pmf(i);
        }
    }
    return 0.0;
}

// A normal for reflecting wo off an analytic lobe, by frame.ndf_sampling, and its pdf.
fn lobe_sample_h(n: AnalyticNdf, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    if (frame.ndf_sampling == NDF_SAMPLING_D_COS) {
        return ndf_sample(n, u);
    }
    return ndf_sample_visible(n, wo, u);
}

fn lobe_pdf_h(n: AnalyticNdf, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    if (frame.ndf_sampling == NDF_SAMPLING_D_COS) {
        return ndf_d(n, h) * max(h.z, 0.0);
    }
    return ndf_pdf_visible(n, wo, h);
}

// Power heuristic, β = 2.
fn mis_weight(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    return select(1.0, a2 / (a2 + b2), a2 + b2 > 0.0);
}

// Weight of a light sample of solid-angle pdf `pdf_light` (0: a delta light, which only light
// sampling reaches), against BSDF sampling's pdf of the same direction; frame.strategy decides.
// Under STRATEGY_BSDF the shading stage does not take such samples at all.
fn light_sample_weight(pdf_light: f32, pdf_bsdf: f32) -> f32 {
    if (pdf_light <= 0.0 || frame.strategy == STRATEGY_LIGHT) {
        return 1.0;
    }
    return mis_weight(pdf_light, pdf_bsdf);
}

// Weight of emission a ray finds: `pdf_bsdf` that of the BSDF sample that made the ray (0: a
// camera ray or a delta lobe, which only this technique reaches), `pdf_light` light sampling's
// for the same direction (0: an emitter light sampling never picks).
fn emission_weight(pdf_bsdf: f32, pdf_light: f32) -> f32 {
    if (pdf_bsdf <= 0.0 || pdf_light <= 0.0 || frame.strategy == STRATEGY_BSDF) {
        return 1.0;
    }
    if (frame.strategy == STRATEGY_LIGHT) {
        return 0.0;
    }
    return mis_weight(pdf_bsdf, pdf_light);
}
