// Include-only. The lit-count walk's width (glint/lit.inc.wgsl) where each query blends its four
// direction cells: 2 queries × 4 cells. Written out, not loops: llvmpipe caps the iterations of
// each shader invocation's loops at 65 535, and the walk calls these once per node.

const CHAINS: u32 = 8u;

// Whether any chain has lit flakes (chains past the live ones hold 0).
fn any_lit(l: array<u32, CHAINS>) -> bool {
    return (l[0] | l[1] | l[2] | l[3] | l[4] | l[5] | l[6] | l[7]) != 0u;
}

fn add_lit(a: array<u32, CHAINS>, b: array<u32, CHAINS>) -> array<u32, CHAINS> {
    return array<u32, CHAINS>(a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4], a[5] + b[5], a[6] + b[6], a[7] + b[7]);
}
