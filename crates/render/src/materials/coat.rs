//! The coat as a layer: a fit's clear coat (a dielectric GGX lobe of weight w over the base,
//! facet_brdf::model::coat) over any fitted class, `shaders/render/materials/coat.inc.wgsl`.
//! A record's header names the coat's block in the scene tables (NONE: no coat).

use facet_brdf::model::coat::CoatLayer;

/// A coat's block as `materials/coat.inc.wgsl` reads it: [n, w, α, η, E_c at the n nodes].
pub fn coat_block(layer: &CoatLayer) -> Vec<f32> {
    let nodes = layer.albedo_nodes();
    let c = &layer.coat;
    [
        nodes.len() as f32,
        c.weight as f32,
        c.alpha as f32,
        c.eta as f32,
    ]
    .into_iter()
    .chain(nodes.iter().map(|&e| e as f32))
    .collect()
}
