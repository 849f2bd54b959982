// Include-only. Traversal of an obvhs compressed wide BVH8 (Ylitie, Karras, Laine, "Efficient
// Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG 2017), ported from obvhs
// 0.4 (`cwbvh/traverse_macro.rs`, `cwbvh/node.rs` intersect_ray_basic, `triangle.rs`
// intersect) operation for operation, so that hits match obvhs's CPU traversal.
//
// The includer declares, with any group and binding:
//   var<storage, read> bvh_nodes: array<CwNode>;            // obvhs CwBvhNode, 80 bytes, as is
//   var<storage, read> bvh_primitives: array<u32>;          // slot -> original triangle index
//   var<storage, read> bvh_triangles: array<vec4<f32>>;     // slot -> 3 vertices (xyz, w unused)
// (facet_render::bvh::GpuBvh holds the three buffers.) An empty scene is one zeroed node: it has
// no children, so every ray misses.

// obvhs's CwBvhNode, byte for byte (little endian). Worked example of the byte packing: child 5's
// meta is byte 1 of child_meta[1], i.e. (child_meta[5 >> 2] >> (8 * (5 & 3))) & 0xff.
struct CwNode {
    // Origin of the child grid (min corner of the node).
    p: vec3<f32>,
    // Bytes e[0], e[1], e[2] (grid scale exponents, scale = bitcast<f32>(e << 23)), then imask
    // (bit i set: child slot i is an internal node).
    e_imask: u32,
    // Index of the first child node in bvh_nodes; children are contiguous.
    child_base_idx: u32,
    // Index of the first primitive slot of the leaves below.
    primitive_base_idx: u32,
    // 8 bytes each. Meta: 001sssss for an internal child (s = 24 + slot), ccc ooooo for a leaf
    // (ccc the primitive count in unary, o the offset from primitive_base_idx), 0 empty.
    child_meta: vec2<u32>,
    // Quantised child bounds on the node's 8-bit grid (deviation from the paper, kept from
    // obvhs: min and max are interleaved per axis).
    child_min_x: vec2<u32>,
    child_max_x: vec2<u32>,
    child_min_y: vec2<u32>,
    child_max_y: vec2<u32>,
    child_min_z: vec2<u32>,
    child_max_z: vec2<u32>,
}

// prim is the ORIGINAL triangle index (0xffffffff on a miss, t then the ray's tmax);
// p = (1 - u - v) v0 + u v1 + v v2 with the triangle's vertices in its index order. obvhs's
// Möller–Trumbore (e1 = v0 - v1, e2 = v2 - v0, u = (r.e2)/(n.d), v = (r.e1)/(n.d)) gives exactly
// these weights (Cramer's rule), so no conversion is needed.
struct Hit {
    t: f32,
    prim: u32,
    u: f32,
    v: f32,
}

const BVH_MISS: u32 = 0xffffffffu;
// obvhs cwbvh::node::EPSILON: nodes are clipped to t >= 1e-4 (it is not the triangles' tmin).
const BVH_NODE_TMIN: f32 = 0.0001;
// obvhs TRAVERSAL_STACK_SIZE; CwBvh::validate asserts the depth stays below it.
const BVH_STACK_SIZE: u32 = 32u;

// obvhs ray::safe_inverse: |x| <= f32::EPSILON (2^-23) -> signum(x) / EPSILON, where signum
// reads the sign bit (signum(-0.0) = -1, unlike WGSL sign()).
fn bvh_safe_inverse(x: f32) -> f32 {
    if (abs(x) <= 1.1920929e-7) {
        return select(8388608.0, -8388608.0, (bitcast<u32>(x) & 0x80000000u) != 0u);
    }
    return 1.0 / x;
}

fn bvh_byte(words: vec2<u32>, i: u32) -> u32 {
    return (words[i >> 2u] >> ((i & 3u) * 8u)) & 0xffu;
}

// Bit i of each byte: 1 when the ray goes towards +axis (x: 4, y: 2, z: 1), replicated in the
// four bytes: the inverse octant, XORed into child slots so that children come near to far.
fn bvh_octant_inv4(dir: vec3<f32>) -> u32 {
    return select(0x04040404u, 0u, dir.x < 0.0)
         | select(0x02020202u, 0u, dir.y < 0.0)
         | select(0x01010101u, 0u, dir.z < 0.0);
}

// Hit mask of a node's children (obvhs intersect_ray_basic): bits 24..31 the internal children
// hit, at bit 24 + (slot ^ octant) for traversal order; bits 0..23 the primitive slots of the
// leaves hit, relative to primitive_base_idx.
fn bvh_intersect_node(node: CwNode, origin: vec3<f32>, dir: vec3<f32>, inv_dir: vec3<f32>,
                      tmax: f32, oct_inv4: u32) -> u32 {
    let e = vec3<u32>(node.e_imask & 0xffu, (node.e_imask >> 8u) & 0xffu, (node.e_imask >> 16u) & 0xffu);
    let extent = bitcast<vec3<f32>>(e << vec3<u32>(23u));
    // The ray moves into the node's grid instead of the boxes out of it: t = q * (scale / d) + (p - o) / d.
    let adj_dir_inv = extent * inv_dir;
    let adj_origin = (node.p - origin) * inv_dir;
    let neg = dir < vec3<f32>(0.0);

    // Per byte, as obvhs get_child_and_index_bits on the two halves of its u64: internal children
    // (meta 001sssss: bits 3 and 4 both set) get their slot XOR the octant as bit index, leaves
    // their primitive offset; child_bits is 1 for internal children, the unary count for leaves.
    var child_bits: vec2<u32>;
    var bit_index: vec2<u32>;
    for (var h = 0u; h < 2u; h++) {
        let cmeta = node.child_meta[h];
        let is_inner = (cmeta & (cmeta << 1u)) & 0x10101010u;
        let inner_mask = (is_inner >> 4u) * 0xffu;
        bit_index[h] = (cmeta ^ (oct_inv4 & inner_mask)) & 0x1f1f1f1fu;
        child_bits[h] = (cmeta >> 5u) & 0x07070707u;
    }

    var hit_mask = 0u;
    for (var c = 0u; c < 8u; c++) {
        let lo = vec3<f32>(vec3<u32>(bvh_byte(node.child_min_x, c), bvh_byte(node.child_min_y, c), bvh_byte(node.child_min_z, c)));
        let hi = vec3<f32>(vec3<u32>(bvh_byte(node.child_max_x, c), bvh_byte(node.child_max_y, c), bvh_byte(node.child_max_z, c)));
        let t_lo = select(lo, hi, neg) * adj_dir_inv + adj_origin;
        let t_hi = select(hi, lo, neg) * adj_dir_inv + adj_origin;
        let tmin = max(max(max(t_lo.x, t_lo.y), t_lo.z), BVH_NODE_TMIN);
        let tmax_c = min(min(min(t_hi.x, t_hi.y), t_hi.z), tmax);
        if (tmin <= tmax_c) {
            hit_mask |= bvh_byte(child_bits, c) << bvh_byte(bit_index, c);
        }
    }
    return hit_mask;
}

// obvhs Triangle::intersect (Möller–Trumbore as in madmann91's BVH introduction), for the triangle
// in primitive slot `slot`: vec3(t, u, v), t = +inf (bitcast) when missed. The u | v | w sign-bit
// test rejects -0.0 as obvhs does; triangles count at 0 <= t <= tmax (tmin 0).
fn bvh_intersect_triangle(slot: u32, origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> vec3<f32> {
    let v0 = bvh_triangles[3u * slot].xyz;
    let v1 = bvh_triangles[3u * slot + 1u].xyz;
    let v2 = bvh_triangles[3u * slot + 2u].xyz;
    let e1 = v0 - v1;
    let e2 = v2 - v0;
    let n = cross(e1, e2);
    let c = v0 - origin;
    let r = cross(dir, c);
    let inv_det = 1.0 / dot(n, dir);
    let u = dot(r, e2) * inv_det;
    let v = dot(r, e1) * inv_det;
    let w = 1.0 - u - v;
    let signs = bitcast<u32>(u) | bitcast<u32>(v) | bitcast<u32>(w);
    if (inv_det != 0.0 && (signs & 0x80000000u) == 0u) {
        let t = dot(n, c) * inv_det;
        if (t >= 0.0 && t <= tmax) {
            return vec3<f32>(t, u, v);
        }
    }
    return vec3<f32>(bitcast<f32>(0x7f800000u), 0.0, 0.0);
}

// The traversal of obvhs's traverse! macro. A group is (base index, bit mask): the node group's
// mask holds the internal children still to visit in bits 24..31 (and the node's imask in bits
// 0..7, for the relative index), the primitive group's the leaf primitive slots still to test.
// any_hit: stop at the first primitive with t < tmax (ray_traverse_miss); otherwise shrink tmax
// to each closer hit (ray_traverse). Returns the hit with the primitive SLOT in prim.
fn bvh_traverse(origin: vec3<f32>, dir_in: vec3<f32>, tmax_in: f32, any_hit: bool) -> Hit {
    // Deviation from obvhs (as facet_render::bvh::Bvh::ray): -0.0 becomes +0.0, or safe_inverse
    // (sign bit: -1/eps) and the slab order (d < 0: false) disagree and the ray misses every box
    // it starts in. A select, not dir + 0.0, which a compiler may fold away.
    let dir = select(dir_in, vec3<f32>(0.0), dir_in == vec3<f32>(0.0));
    var hit = Hit(tmax_in, BVH_MISS, 0.0, 0.0);
    var tmax = tmax_in;
    let inv_dir = vec3<f32>(bvh_safe_inverse(dir.x), bvh_safe_inverse(dir.y), bvh_safe_inverse(dir.z));
    let oct_inv4 = bvh_octant_inv4(dir);

    var stack: array<vec2<u32>, BVH_STACK_SIZE>;
    var sp = 0u;
    // Start with the root alone: bit 31 maps to slot 7 ^ octant with no imask bits below it, so
    // the relative index is 0.
    var current_group = vec2<u32>(0u, 0x80000000u);
    var primitive_group = vec2<u32>(0u, 0u);

    loop {
        while (primitive_group.y != 0u) {
            let local = firstLeadingBit(primitive_group.y);
            primitive_group.y &= ~(1u << local);
            let slot = primitive_group.x + local;
            let tuv = bvh_intersect_triangle(slot, origin, dir, tmax);
            if (tuv.x < tmax) {
                hit = Hit(tuv.x, slot, tuv.y, tuv.z);
                if (any_hit) {
                    return hit;
                }
                tmax = tuv.x;
            }
        }
        primitive_group = vec2<u32>(0u, 0u);

        if ((current_group.y & 0xff000000u) != 0u) {
            let hits_imask = current_group.y;
            let child_bit = firstLeadingBit(hits_imask);
            current_group.y &= ~(1u << child_bit);
            if ((current_group.y & 0xff000000u) != 0u) {
                // A full stack drops the group (obvhs asserts the depth stays below 32).
                if (sp < BVH_STACK_SIZE) {
                    stack[sp] = current_group;
                    sp += 1u;
                }
            }
            // Undo the octant swizzle; the child's index is the number of internal siblings
            // in lower slots: child_base_idx + popcount(imask & ((1 << slot) - 1)).
            let slot_index = (child_bit - 24u) ^ (oct_inv4 & 0xffu);
            let relative_index = countOneBits(hits_imask & ~(0xffffffffu << slot_index));
            let node = bvh_nodes[current_group.x + relative_index];
            let hitmask = bvh_intersect_node(node, origin, dir, inv_dir, tmax, oct_inv4);
            current_group = vec2<u32>(node.child_base_idx, (hitmask & 0xff000000u) | (node.e_imask >> 24u));
            primitive_group = vec2<u32>(node.primitive_base_idx, hitmask & 0x00ffffffu);
        } else {
            current_group = vec2<u32>(0u, 0u);
        }

        if (primitive_group.y == 0u && (current_group.y & 0xff000000u) == 0u) {
            if (sp == 0u) {
                break;
            }
            sp -= 1u;
            current_group = stack[sp];
        }
    }
    return hit;
}

// The nearest triangle at t < tmax; prim = BVH_MISS (and t = tmax) when there is none.
fn trace_closest(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> Hit {
    var hit = bvh_traverse(origin, dir, tmax, false);
    if (hit.prim != BVH_MISS) {
        hit.prim = bvh_primitives[hit.prim];
    }
    return hit;
}

// Whether any triangle lies at t < tmax (shadow and occlusion rays).
fn trace_any(origin: vec3<f32>, dir: vec3<f32>, tmax: f32) -> bool {
    return bvh_traverse(origin, dir, tmax, true).prim != BVH_MISS;
}
