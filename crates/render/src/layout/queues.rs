//! The integrator's work queues: slot lists filled by one stage with atomic counters and
//! consumed by the next through indirect dispatch (`shaders/render/queue_args.wgsl`).

use super::tags::MaterialKind;

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
    /// Hits on the materials of a class (not glints, which have a queue per material).
    Shade(MaterialKind),
    /// Hits on glint material k.
    Glint(u32),
}

/// The first shading queue's index.
const FIRST_SHADE: u32 = 3;

impl Queue {
    pub const fn index(self) -> u32 {
        match self {
            Queue::Generate => 0,
            Queue::Extend => 1,
            Queue::Shadow => 2,
            Queue::Shade(k) => FIRST_SHADE + k as u32,
            Queue::Glint(k) => FIRST_SHADE + MaterialKind::Glint as u32 + k,
        }
    }

    /// The material class a shading queue serves.
    pub const fn class(self) -> Option<MaterialKind> {
        match self {
            Queue::Shade(k) => Some(k),
            Queue::Glint(_) => Some(MaterialKind::Glint),
            _ => None,
        }
    }

    /// The first shading queue.
    pub const fn first_shade() -> u32 {
        FIRST_SHADE
    }

    /// Number of queues for a scene with `glints` glint materials.
    pub const fn count(glints: u32) -> u32 {
        FIRST_SHADE + MaterialKind::Glint as u32 + glints
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
