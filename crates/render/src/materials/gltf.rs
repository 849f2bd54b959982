//! The glTF metallic-roughness class (glTF 2.0, Appendix B, with KHR_materials_specular's weight
//! and KHR_materials_clearcoat), shaded by `shaders/render/shade_diffuse.wgsl`.

use super::record::GpuMaterial;
use super::{MaterialPlan, MaterialSlot, ShadeStage};
use crate::class_block;
use crate::layout::gpu_types::{MaterialKind, NONE};
use crate::layout::queues::Queue;
use crate::scene::Material;

class_block!(
    /// A glTF metallic-roughness material and its clear coat.
    GltfBlock => "GltfBlock" {
        /// the base colour factor (rgb)
        base_color: [f32; 3],
        /// the metallic factor
        metallic: f32,
        /// the roughness factor (GGX α = roughness²)
        roughness: f32,
        /// KHR_materials_specular's weight of the dielectric's specular lobe
        specular: f32,
        /// the base colour texture (NONE: none)
        tex_base: u32,
        /// the metallic-roughness texture (NONE: none)
        tex_mr: u32,
        /// KHR_materials_clearcoat's factor (0: no coat)
        clearcoat: f32,
        /// the clear coat's roughness factor
        clearcoat_roughness: f32,
        /// the clear coat's factor texture (NONE: none)
        tex_clearcoat: u32,
        /// the clear coat's roughness texture (NONE: none)
        tex_clearcoat_roughness: u32,
        /// the clear coat's normal map (NONE: none)
        tex_clearcoat_normal: u32,
        /// the clear coat's normal map's xy scale
        clearcoat_normal_scale: f32,
    }
);

fn texture(t: Option<u32>) -> u32 {
    t.unwrap_or(NONE)
}

/// The block of glTF material `m`.
pub fn block(m: &Material) -> GltfBlock {
    let c = m.base_color;
    let mut b = GltfBlock {
        base_color: [c.x, c.y, c.z],
        metallic: m.metallic,
        roughness: m.roughness,
        specular: m.specular,
        tex_base: texture(m.base_color_texture),
        tex_mr: texture(m.metallic_roughness_texture),
        tex_clearcoat: NONE,
        tex_clearcoat_roughness: NONE,
        tex_clearcoat_normal: NONE,
        ..Default::default()
    };
    if let Some(cc) = &m.clearcoat {
        b.clearcoat = cc.factor;
        b.clearcoat_roughness = cc.roughness;
        b.tex_clearcoat = texture(cc.texture);
        b.tex_clearcoat_roughness = texture(cc.roughness_texture);
        b.tex_clearcoat_normal = texture(cc.normal_texture);
        b.clearcoat_normal_scale = cc.normal_scale;
    }
    b
}

/// The plan of glTF material `m` over its header `gpu`.
pub fn plan(mut gpu: GpuMaterial, m: &Material) -> MaterialPlan<'_> {
    gpu.put(0, &block(m));
    MaterialPlan::new(MaterialSlot::new(
        gpu,
        MaterialKind::Gltf,
        None,
        Queue::Shade(MaterialKind::Gltf),
    ))
}

/// Its stage.
pub fn stage() -> ShadeStage {
    ShadeStage::new("render/shade_diffuse.wgsl", "shade_diffuse", Vec::new())
}
