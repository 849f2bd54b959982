// Glint counting on the GPU, the twin of facet_glint::glint_brdf::glint_count: one thread per
// pair of queries sharing a footprint; when the filter is on and N a P exceeds the threshold the
// mean replaces the count.

#include "glint/tea.inc.wgsl"

const WG: u32 = 64u;

@group(0) @binding(0) var<uniform> field: Field;
@group(0) @binding(1) var<storage, read> queries: array<Query>;
@group(0) @binding(2) var<storage, read_write> counts: array<vec2<f32>>;
@group(0) @binding(3) var<storage, read> split_table: array<u32>;

#include "glint/flakes.inc.wgsl"
#include "glint/chains8.inc.wgsl"
#include "glint/lit.inc.wgsl"

@compute @workgroup_size(WG)
fn glint_count(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&queries)) {
        return;
    }
    counts[i] = count_pair(queries[i]);
}
