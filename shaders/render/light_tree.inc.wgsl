// Include-only. The light BVH (Rust: facet_render::resources::light_bvh, which documents the
// method and is this file's CPU reference): choosing a light for a shading point (p, n) by
// walking down the tree, and the probability of a light from its leaf up. The includer
// declares `light_tree: array<LightNode>` (scene.inc.wgsl does).

#include "render/none.inc.wgsl"

// Rust: facet_render::resources::light_bvh::GpuLightNode: the box as its bounding sphere, the
// cone of emission, the power bound.
struct LightNode {
    // xyz the centre of the box, w φ
    centre_phi: vec4<f32>,
    // xyz the axis of the cone of emission axes, w cos θo (their spread)
    axis_cos_o: vec4<f32>,
    // half the box's diagonal
    radius: f32,
    // cos θe: emission reaches θe beyond an axis
    cos_e: f32,
    sin_o: f32,
    // a leaf: its light; inside: the second child (the first is the next node)
    child: u32,
    // NONE at the root
    parent: u32,
    leaf: u32,
    pad0: u32,
    pad1: u32,
}

// cos(max(0, a − b)) and sin(max(0, a − b)) for a, b in [0, π].
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    return select(cos_a * cos_b + sin_a * sin_b, 1.0, cos_a > cos_b);
}

fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    return select(sin_a * cos_b - cos_a * sin_b, 0.0, cos_a > cos_b);
}

fn safe_sqrt(x: f32) -> f32 {
    return sqrt(max(x, 0.0));
}

// A bound on what node `i`'s lights deliver to p with geometric normal n:
// φ cos θ'p / d² · cos θ'i (LightBounds::importance).
fn light_node_importance(i: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let node = light_tree[i];
    let phi = node.centre_phi.w;
    if (phi <= 0.0) {
        return 0.0;
    }
    let dc = p - node.centre_phi.xyz;
    let dc2 = dot(dc, dc);
    // pbrt's clamp: d² at least the radius.
    let d2 = max(dc2, node.radius);
    var wi = vec3<f32>(0.0);
    if (dc2 > 0.0) {
        wi = dc / sqrt(dc2);
    }
    let cos_o = node.axis_cos_o.w;
    let cos_w = dot(node.axis_cos_o.xyz, wi);
    let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
    let r2 = node.radius * node.radius;
    let cos_b = select(safe_sqrt(1.0 - r2 / dc2), -1.0, dc2 < r2);
    let sin_b = safe_sqrt(1.0 - cos_b * cos_b);
    let cos_x = cos_sub_clamped(sin_w, cos_w, node.sin_o, cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, node.sin_o, cos_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    if (cos_p <= node.cos_e) {
        return 0.0;
    }
    var importance = phi * cos_p / d2;
    if (any(n != vec3<f32>(0.0))) {
        let cos_i = dot(-wi, n);
        let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
        importance *= max(cos_sub_clamped(sin_i, cos_i, sin_b, cos_b), 0.0);
    }
    return max(importance, 0.0);
}

// The probability of interior node i's first child: its share of the children's importance,
// ½ where both are 0.
fn light_first_child_share(i: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let i0 = light_node_importance(i + 1u, p, n);
    let i1 = light_node_importance(light_tree[i].child, p, n);
    return select(0.5, i0 / (i0 + i1), i0 + i1 > 0.0);
}

struct LightPick {
    light: u32,
    pmf: f32,
}

// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 0.99999994;

// A light for (p, n) from u in [0, 1), and its probability (LightBvh::sample).
fn light_tree_sample(p: vec3<f32>, n: vec3<f32>, u_in: f32) -> LightPick {
    var i = 0u;
    var u = u_in;
    var pmf = 1.0;
    loop {
        let node = light_tree[i];
        if (node.leaf == 1u) {
            return LightPick(node.child, pmf);
        }
        let p0 = light_first_child_share(i, p, n);
        if (u < p0) {
            i += 1u;
            pmf *= p0;
            u = min(u / p0, ONE_MINUS_EPSILON);
        } else {
            i = node.child;
            pmf *= 1.0 - p0;
            u = min((u - p0) / (1.0 - p0), ONE_MINUS_EPSILON);
        }
    }
    return LightPick(NONE, 0.0);
}

// The probability that light_tree_sample at (p, n) picks the light of leaf `leaf` (LightBvh::pmf).
fn light_tree_pmf(leaf: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    if (leaf == NONE) {
        return 0.0;
    }
    var pmf = 1.0;
    var i = leaf;
    loop {
        let parent = light_tree[i].parent;
        if (parent == NONE) {
            break;
        }
        let p0 = light_first_child_share(parent, p, n);
        pmf *= select(1.0 - p0, p0, i == parent + 1u);
        i = parent;
    }
    return pmf;
}
