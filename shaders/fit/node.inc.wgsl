// Include-only. A quadrature node or query direction of the power iteration
// (Rust: facet_fit::gpu::GpuNode, and GpuState below; layouts checked against naga in
// tests/shaders.rs).
struct Node {
    x: f32,
    y: f32,
    z: f32,
    // 4 f(o,o) cos θo for iteration rows; 1 for table queries.
    row_scale: f32,
    // Quadrature weight of the column: w sin θ (isotropic) or w sin θ Δφ (anisotropic).
    col_weight: f32,
    // Normalisation weight c with Σ c D = ∫ D cos θ dω.
    norm_weight: f32,
    pad0: f32,
    pad1: f32,
}

// Iteration state, written by the reduction pass.
struct State {
    iteration: u32,
    lambda: f32,
    pad0: u32,
    pad1: u32,
}
