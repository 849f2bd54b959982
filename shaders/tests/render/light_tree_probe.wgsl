// The light BVH's choices on the GPU for given shading points, read back by
// crates/render/tests/light_bvh.rs and compared with the CPU's (LightBvh::pmf, LightBvh::sample).

#include "render/light_tree.inc.wgsl"

struct Probe {
    // xyz the point, w the random number of the pick
    p: vec4<f32>,
    // xyz the geometric normal, w (bits) the leaf whose pmf is asked
    n: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> light_tree: array<LightNode>;
@group(0) @binding(1) var<storage, read> probes: array<Probe>;
// x the pmf of the asked leaf's light, y (bits) the light picked, z its pmf
@group(0) @binding(2) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= arrayLength(&probes)) {
        return;
    }
    let q = probes[i];
    let pick = light_tree_sample(q.p.xyz, q.n.xyz, q.p.w);
    let pmf = light_tree_pmf(bitcast<u32>(q.n.w), q.p.xyz, q.n.xyz);
    results[i] = vec4<f32>(pmf, bitcast<f32>(pick.light), pick.pmf, 0.0);
}
