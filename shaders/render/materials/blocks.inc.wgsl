// Include-only. Generated from facet_render::materials (crates/render/src/materials/):
// do not edit; `FACET_REGENERATE=1 cargo test -p facet-render --test tags` rewrites it.
// Each class block's fields and its decoder from material m's block at word `at`
// (render/scene.inc.wgsl declares `materials`).

// A glTF metallic-roughness material and its clear coat.
struct GltfBlock {
    // the base colour factor (rgb)
    base_color: vec3<f32>,
    // the metallic factor
    metallic: f32,
    // the roughness factor (GGX α = roughness²)
    roughness: f32,
    // KHR_materials_specular's weight of the dielectric's specular lobe
    specular: f32,
    // the base colour texture (NONE: none)
    tex_base: u32,
    // the metallic-roughness texture (NONE: none)
    tex_mr: u32,
    // KHR_materials_clearcoat's factor (0: no coat)
    clearcoat: f32,
    // the clear coat's roughness factor
    clearcoat_roughness: f32,
    // the clear coat's factor texture (NONE: none)
    tex_clearcoat: u32,
    // the clear coat's roughness texture (NONE: none)
    tex_clearcoat_roughness: u32,
    // the clear coat's normal map (NONE: none)
    tex_clearcoat_normal: u32,
    // the clear coat's normal map's xy scale
    clearcoat_normal_scale: f32,
}

const GLTF_BLOCK_WORDS: u32 = 14u;

fn gltf_block(m: u32, at: u32) -> GltfBlock {
    return GltfBlock(
        vec3<f32>(bitcast<f32>(materials[m].block[at + 0u]), bitcast<f32>(materials[m].block[at + 1u]), bitcast<f32>(materials[m].block[at + 2u])),
        bitcast<f32>(materials[m].block[at + 3u]),
        bitcast<f32>(materials[m].block[at + 4u]),
        bitcast<f32>(materials[m].block[at + 5u]),
        materials[m].block[at + 6u],
        materials[m].block[at + 7u],
        bitcast<f32>(materials[m].block[at + 8u]),
        bitcast<f32>(materials[m].block[at + 9u]),
        materials[m].block[at + 10u],
        materials[m].block[at + 11u],
        materials[m].block[at + 12u],
        bitcast<f32>(materials[m].block[at + 13u]),
    );
}

// A fit's microfacet lobe: Fresnel table, diffuse term, NDF.
struct LobeBlock {
    // ρd, the Lambertian albedo (rgb)
    diffuse: vec3<f32>,
    // F(θd)'s table in the scene tables: FRESNEL_NODES rgb nodes
    fresnel: u32,
    // the Fresnel table's nodes
    fresnel_nodes: u32,
    // the NDF: NDF_KIND_GGX, NDF_KIND_BECKMANN or NDF_KIND_TABULATED
    ndf_kind: u32,
    // the NDF's stretch along the tangent (an analytic NDF's αx)
    alpha_x: f32,
    // the NDF's stretch along the bitangent (αy)
    alpha_y: f32,
    // the stretch's rotation from the tangent (radians)
    rotation: f32,
    // a tabulated NDF's block in the scene tables (materials/tabulated.inc.wgsl), NONE else
    table: u32,
    // the GGX α the ray cone widens by
    cone_alpha: f32,
}

const LOBE_BLOCK_WORDS: u32 = 11u;

fn lobe_block(m: u32, at: u32) -> LobeBlock {
    return LobeBlock(
        vec3<f32>(bitcast<f32>(materials[m].block[at + 0u]), bitcast<f32>(materials[m].block[at + 1u]), bitcast<f32>(materials[m].block[at + 2u])),
        materials[m].block[at + 3u],
        materials[m].block[at + 4u],
        materials[m].block[at + 5u],
        bitcast<f32>(materials[m].block[at + 6u]),
        bitcast<f32>(materials[m].block[at + 7u]),
        bitcast<f32>(materials[m].block[at + 8u]),
        materials[m].block[at + 9u],
        bitcast<f32>(materials[m].block[at + 10u]),
    );
}

// A MERL-grid measurement, after its sampling model's lobe.
struct MerlBlock {
    // its table in the scene tables (materials/merl.inc.wgsl)
    table: u32,
}

const MERL_BLOCK_WORDS: u32 = 1u;

fn merl_block(m: u32, at: u32) -> MerlBlock {
    return MerlBlock(
        materials[m].block[at + 0u],
    );
}

// An RGL `.bsdf` file.
struct RglBlock {
    // its block in the scene tables
    table: u32,
    // the GGX α the ray cone widens by (the file states none)
    cone_alpha: f32,
}

const RGL_BLOCK_WORDS: u32 = 2u;

fn rgl_block(m: u32, at: u32) -> RglBlock {
    return RglBlock(
        materials[m].block[at + 0u],
        bitcast<f32>(materials[m].block[at + 1u]),
    );
}
