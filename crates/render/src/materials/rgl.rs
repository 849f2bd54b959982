//! The measured RGL class: an RGL `.bsdf` evaluated and sampled from its own warps as Mitsuba 3's
//! `measured` plugin does, shaded by `shaders/render/shade_rgl.wgsl`
//! (`shaders/render/materials/rgl.inc.wgsl`). Its class block is [`RglBlock`].
//!
//! The file ([`RglBsdf`]) is one block of f32 words in the scene's `tables` buffer, the
//! layout `materials/rgl.inc.wgsl` reads: every warp of the file (Dupuy & Jakob 2018's
//! `Marginal2D`, [`Warp2D`]) with its sizes, its data and, for the two distributions, its
//! marginal and conditional CDFs, as the CPU reader holds them (normalised, in f64) rounded
//! to f32.
//!
//! Layout, offsets in words from the block's start; header words are u32 bit patterns
//! (`f32::from_bits`, read back with `bitcast<u32>`), so offsets are exact past 2²⁴:
//!
//! | words | content |
//! |---|---|
//! | 0..8 | flags (bit 0 isotropic, bit 1 jacobian), reduction, nφ, nθ, φi nodes, θi nodes, block length, 0 |
//! | 8..64 | 7 warp records of 8 words, in [`RGL_WARPS`] order: nx, ny, data, marginal, conditional, φi stride, θi stride, 0 |
//! | 64.. | φi nodes, θi nodes, then each warp's data, marginal and conditional arrays |
//!
//! Worked example: an isotropic file with θi on 10 nodes puts φi (1 node) at 64, θi at 65 and the
//! `ndf` data at 75; the φi stride of its parametric warps is 0 (one node), the θi stride 1
//! (slices are consecutive). An interpolant's marginal and conditional offsets are 0, and a
//! warp without parameters (`ndf`, `sigma`) has both strides 0.

use super::lobe::UNKNOWN_CONE_ALPHA;
use super::record::GpuMaterial;
use super::{MaterialPlan, MaterialSlot, ShadeStage};
use crate::class_block;
use crate::layout::gpu_types::MaterialKind;
use crate::layout::queues::Queue;
use facet_brdf::Brdf;
use facet_brdf::sources::rgl::RglBsdf;
use facet_brdf::sources::rgl::warp2d::Warp2D;

class_block!(
    /// An RGL `.bsdf` file.
    RglBlock => "RglBlock" {
        /// its block in the scene tables
        table: u32,
        /// the GGX α the ray cone widens by (the file states none)
        cone_alpha: f32,
    }
);

/// The plan of an RGL file; its table's offset is set when it is placed
/// ([`MaterialPlan::place_tables`]).
pub fn plan<'a>(mut gpu: GpuMaterial) -> MaterialPlan<'a> {
    let block = RglBlock {
        table: 0,
        cone_alpha: UNKNOWN_CONE_ALPHA,
    };
    gpu.put(0, &block);
    let kind = MaterialKind::Rgl;
    MaterialPlan::new(MaterialSlot::new(gpu, kind, None, Queue::Shade(kind)))
}

/// Points an RGL record at its table.
pub fn set_table(gpu: &mut GpuMaterial, table: u32) {
    let mut block: RglBlock = gpu.get(0);
    block.table = table;
    gpu.put(0, &block);
}

/// Its stage.
pub fn stage() -> ShadeStage {
    ShadeStage::new("render/shade_rgl.wgsl", "shade_rgl", Vec::new())
}

/// Words of the block's header.
pub const RGL_HEADER_WORDS: usize = 8;
/// Words of one warp record.
pub const RGL_WARP_WORDS: usize = 8;
/// The warps of the block, in record order (the WGSL's `RGL_NDF` … `RGL_BLUE`).
pub const RGL_WARPS: [&str; 7] = ["ndf", "sigma", "vndf", "luminance", "red", "green", "blue"];

/// A count or offset as the bit pattern of one f32 word.
fn word(n: usize) -> f32 {
    f32::from_bits(u32::try_from(n).expect("an RGL block past 2³² words"))
}

/// The block of `bsdf` for the `tables` buffer (layout in the module's documentation).
pub fn rgl_block(bsdf: &RglBsdf) -> Vec<f32> {
    let [r, g, b] = bsdf.rgb();
    let warps: [&Warp2D; 7] = [
        bsdf.ndf(),
        bsdf.sigma(),
        bsdf.vndf(),
        bsdf.luminance(),
        r,
        g,
        b,
    ];
    // Every parametric warp of a file shares the (φi, θi) nodes of `vndf`.
    let nodes = bsdf.vndf().params();
    let (nphi, ntheta) = (nodes[0].len(), nodes[1].len());
    let records = RGL_HEADER_WORDS + warps.len() * RGL_WARP_WORDS;
    let mut block = vec![0.0f32; records];
    let push = |block: &mut Vec<f32>, values: &[f64]| -> usize {
        let at = block.len();
        block.extend(values.iter().map(|&v| v as f32));
        at
    };
    let phi_at = push(&mut block, &nodes[0]);
    let theta_at = push(&mut block, &nodes[1]);
    for (k, w) in warps.iter().enumerate() {
        debug_assert!(w.params().is_empty() || w.params() == nodes);
        let [nx, ny] = w.size();
        let data = push(&mut block, w.data());
        let (marginal, conditional) = if w.is_distribution() {
            let m = push(&mut block, w.marginal());
            (m, push(&mut block, w.conditional()))
        } else {
            (0, 0)
        };
        // Slice strides as Warp2D::layout sets them: θi fastest, a single node none.
        let (stride_phi, stride_theta) = if w.params().is_empty() {
            (0, 0)
        } else {
            (if nphi > 1 { ntheta } else { 0 }, usize::from(ntheta > 1))
        };
        let record = [
            nx,
            ny,
            data,
            marginal,
            conditional,
            stride_phi,
            stride_theta,
            0,
        ];
        let at = RGL_HEADER_WORDS + k * RGL_WARP_WORDS;
        for (o, v) in block[at..at + RGL_WARP_WORDS].iter_mut().zip(record) {
            *o = word(v);
        }
    }
    let flags = usize::from(bsdf.is_isotropic()) | usize::from(bsdf.has_jacobian()) << 1;
    let header = [
        flags,
        bsdf.reduction() as usize,
        nphi,
        ntheta,
        phi_at,
        theta_at,
        block.len(),
        0,
    ];
    for (o, v) in block.iter_mut().zip(header) {
        *o = word(v);
    }
    block
}
