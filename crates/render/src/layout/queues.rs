//! The integrator's work queues: slot lists filled by one stage with atomic counters and
//! consumed by the next through indirect dispatch (`shaders/render/queue_args.wgsl`).

/// The most glint materials one scene may have (one queue and one shading dispatch each).
pub const MAX_GLINT_MATERIALS: u32 = 8;

/// A queue; its index is the WGSL queue number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Queue {
    /// Slots whose next path starts (logic → generate).
    Generate,
    /// Rays to trace (logic, generate → extend).
    Extend,
    /// Shadow rays (shading → connect).
    Shadow,
    /// Hits on glTF metallic-roughness materials.
    Diffuse,
    /// Hits on fitted materials with a GGX / Beckmann NDF.
    Analytic,
    /// Hits on fitted materials with their tabulated NDF.
    Tabulated,
    /// Hits on measured MERL-grid tables.
    Merl,
    /// Hits on measured RGL `.bsdf` files.
    Rgl,
    /// Hits on glint material k.
    Glint(u32),
}

impl Queue {
    pub const fn index(self) -> u32 {
        match self {
            Queue::Generate => 0,
            Queue::Extend => 1,
            Queue::Shadow => 2,
            Queue::Diffuse => 3,
            Queue::Analytic => 4,
            Queue::Tabulated => 5,
            Queue::Merl => 6,
            Queue::Rgl => 7,
            Queue::Glint(k) => 8 + k,
        }
    }

    /// The material class a shading queue serves.
    pub const fn class_name(self) -> &'static str {
        match self {
            Queue::Diffuse => "diffuse",
            Queue::Analytic => "analytic",
            Queue::Tabulated => "tabulated",
            Queue::Merl => "measured MERL",
            Queue::Rgl => "measured RGL",
            Queue::Glint(_) => "glint",
            _ => "none",
        }
    }

    /// Number of queues for a scene with `glints` glint materials.
    pub const fn count(glints: u32) -> u32 {
        8 + glints
    }

    /// Override constants naming the fixed queues in WGSL.
    pub fn constants() -> [(&'static str, f64); 3] {
        [
            ("Q_GEN", Queue::Generate.index() as f64),
            ("Q_EXTEND", Queue::Extend.index() as f64),
            ("Q_SHADOW", Queue::Shadow.index() as f64),
        ]
    }
}
