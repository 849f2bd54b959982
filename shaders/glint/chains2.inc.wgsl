// Include-only. The lit-count walk's width (glint/lit.inc.wgsl) where each query reads one
// direction cell (select_cell): 2 queries. Half the stack entry of chains8.inc.wgsl's walk, the
// same counts; on lavapipe the demo's glint stage takes 0.74× the time (docs/log/glints.md).

const CHAINS: u32 = 2u;

// Whether any chain has lit flakes.
fn any_lit(l: array<u32, CHAINS>) -> bool {
    return (l[0] | l[1]) != 0u;
}

fn add_lit(a: array<u32, CHAINS>, b: array<u32, CHAINS>) -> array<u32, CHAINS> {
    return array<u32, CHAINS>(a[0] + b[0], a[1] + b[1]);
}
