// Include-only. The index that means "none" (Rust: facet_render::layout::gpu_types::NONE): no texture,
// no light, no parent.

const NONE: u32 = 0xffffffffu;
