// Chooses direction cells (select_cell in glint/lit.inc.wgsl), for the test that compares WGSL
// with Rust. The field and split table lit.inc.wgsl's walk reads are declared, not used.

#include "glint/tea.inc.wgsl"

var<private> field: Field;
var<private> split_table: array<u32, 1>;

#include "glint/flakes.inc.wgsl"
#include "glint/chains8.inc.wgsl"
#include "glint/lit.inc.wgsl"

// Per query: direction coordinates (x, y) and the uniform (z).
@group(0) @binding(0) var<storage, read> queries: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> chosen: array<vec2<f32>>;

@compute @workgroup_size(64)
fn select_check(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i < arrayLength(&queries)) {
        let q = queries[i];
        chosen[i] = select_cell(q.xy, q.z);
    }
}
