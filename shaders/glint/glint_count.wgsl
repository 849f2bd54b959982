// Glint counting on the GPU, the twin of facet_glint::glint_brdf::glint_count: one thread per
// query; when the filter is on and N a P exceeds the threshold the mean replaces the count.

#include "glint/tea.inc.wgsl"

const WG: u32 = 64u;

@group(0) @binding(0) var<uniform> field: Field;
@group(0) @binding(1) var<storage, read> queries: array<Query>;
@group(0) @binding(2) var<storage, read_write> counts: array<f32>;

#include "glint/flakes.inc.wgsl"

@compute @workgroup_size(WG)
fn glint_count(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&queries)) {
        return;
    }
    let q = queries[i];
    let expected = field.density * footprint_area(q) * q.p;
    if (field.filtered != 0u && expected > field.threshold) {
        counts[i] = expected;
        return;
    }
    counts[i] = f32(count_footprint(q, tea(q.cell_x, q.cell_y)));
}
