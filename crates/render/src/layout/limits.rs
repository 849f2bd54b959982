//! GPU resources whose size comes from input (the scene, a fit file, the environment map, the
//! render size), checked against the device's limits before they are created.
//!
//! wgpu reports a buffer over `max_buffer_size`, a binding over
//! `max_storage_buffer_binding_size` or a texture over `max_texture_dimension_*` as a validation
//! error, which outside an error scope is a panic. Every such resource is first described as a
//! [`Planned`] (what it is, its size, and what set that size, in words for the user) and
//! [`DeviceLimits::check`]ed; the error names the resource, the limit and the input to change.

use crate::error::RenderError;

/// The limits of one device that input-sized resources must respect.
#[derive(Clone, Debug)]
pub struct DeviceLimits {
    pub max_buffer_size: u64,
    pub max_storage_buffer_binding_size: u64,
    pub max_texture_dimension_2d: u32,
    pub max_texture_dimension_3d: u32,
}

/// A resource about to be created.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Planned {
    /// A storage buffer of `bytes`, bound whole.
    Storage {
        what: String,
        bytes: u64,
        set_by: String,
    },
    /// A buffer that is only copied to or mapped (not bound), of `bytes`.
    Buffer {
        what: String,
        bytes: u64,
        set_by: String,
    },
    /// A 2D texture (`size[2]` = 1) or a 3D one.
    Texture {
        what: String,
        size: [u32; 3],
        three_d: bool,
        set_by: String,
    },
}

impl DeviceLimits {
    pub fn of(device: &wgpu::Device) -> Self {
        Self::from_limits(&device.limits())
    }

    pub fn from_limits(l: &wgpu::Limits) -> Self {
        DeviceLimits {
            max_buffer_size: l.max_buffer_size,
            max_storage_buffer_binding_size: l.max_storage_buffer_binding_size,
            max_texture_dimension_2d: l.max_texture_dimension_2d,
            max_texture_dimension_3d: l.max_texture_dimension_3d,
        }
    }

    /// `Err` for the first planned resource over a limit.
    pub fn check(&self, planned: &[Planned]) -> Result<(), RenderError> {
        planned.iter().try_for_each(|p| self.check_one(p))
    }

    fn check_one(&self, p: &Planned) -> Result<(), RenderError> {
        let too_large = |what: &str, needed: u64, unit, limit_name, limit: u64, set_by: &str| {
            Err(RenderError::TooLarge {
                what: what.to_owned(),
                needed,
                unit,
                limit_name,
                limit,
                set_by: set_by.to_owned(),
            })
        };
        match p {
            Planned::Storage {
                what,
                bytes,
                set_by,
            } => {
                if *bytes > self.max_storage_buffer_binding_size {
                    return too_large(
                        what,
                        *bytes,
                        "bytes",
                        "max_storage_buffer_binding_size",
                        self.max_storage_buffer_binding_size,
                        set_by,
                    );
                }
                if *bytes > self.max_buffer_size {
                    return too_large(
                        what,
                        *bytes,
                        "bytes",
                        "max_buffer_size",
                        self.max_buffer_size,
                        set_by,
                    );
                }
                Ok(())
            }
            Planned::Buffer {
                what,
                bytes,
                set_by,
            } => {
                if *bytes > self.max_buffer_size {
                    return too_large(
                        what,
                        *bytes,
                        "bytes",
                        "max_buffer_size",
                        self.max_buffer_size,
                        set_by,
                    );
                }
                Ok(())
            }
            Planned::Texture {
                what,
                size,
                three_d,
                set_by,
            } => {
                let (limit_name, limit) = if *three_d {
                    ("max_texture_dimension_3d", self.max_texture_dimension_3d)
                } else {
                    ("max_texture_dimension_2d", self.max_texture_dimension_2d)
                };
                let side = size.iter().copied().max().unwrap_or(0);
                if side > limit {
                    return too_large(
                        what,
                        u64::from(side),
                        "texels on a side",
                        limit_name,
                        u64::from(limit),
                        set_by,
                    );
                }
                Ok(())
            }
        }
    }
}

impl Planned {
    pub fn storage(what: impl Into<String>, bytes: u64, set_by: impl Into<String>) -> Self {
        Planned::Storage {
            what: what.into(),
            bytes,
            set_by: set_by.into(),
        }
    }

    pub fn buffer(what: impl Into<String>, bytes: u64, set_by: impl Into<String>) -> Self {
        Planned::Buffer {
            what: what.into(),
            bytes,
            set_by: set_by.into(),
        }
    }

    pub fn texture_3d(what: impl Into<String>, size: [u32; 3], set_by: impl Into<String>) -> Self {
        Planned::Texture {
            what: what.into(),
            size,
            three_d: true,
            set_by: set_by.into(),
        }
    }

    // Only the tests plan a 2D texture so far; kept with the storage and buffer plans.
    #[allow(dead_code)]
    pub fn texture_2d(what: impl Into<String>, size: [u32; 2], set_by: impl Into<String>) -> Self {
        Planned::Texture {
            what: what.into(),
            size: [size[0], size[1], 1],
            three_d: false,
            set_by: set_by.into(),
        }
    }
}

/// `a × b × …` in u64, saturating (a size past u64 is over every limit anyway).
pub fn product(factors: &[u64]) -> u64 {
    factors.iter().fold(1u64, |acc, &f| acc.saturating_mul(f))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_limit_is_named_with_what_set_the_size() {
        let l = DeviceLimits {
            max_buffer_size: 1000,
            max_storage_buffer_binding_size: 500,
            max_texture_dimension_2d: 64,
            max_texture_dimension_3d: 32,
        };
        assert!(
            l.check(&[
                Planned::storage("a", 500, "x"),
                Planned::buffer("b", 1000, "y"),
                Planned::texture_3d("c", [32, 32, 32], "z"),
                Planned::texture_2d("d", [64, 1], "w"),
            ])
            .is_ok()
        );
        let e = l
            .check(&[Planned::storage(
                "the film",
                501,
                "--width × --height (1 × 1)",
            )])
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "the film: 501 bytes is more than this adapter's max_storage_buffer_binding_size (500); \
             the size comes from --width × --height (1 × 1)"
        );
        let e = l
            .check(&[Planned::buffer("film read-back", 1001, "the render size")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("max_buffer_size (1000)"), "{e}");
        let e = l
            .check(&[Planned::texture_3d(
                "a DPF level",
                [33, 8, 8],
                "the DPF resolution",
            )])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("33 texels on a side") && e.contains("max_texture_dimension_3d (32)"),
            "{e}"
        );
        assert_eq!(product(&[u64::MAX, 16]), u64::MAX);
        assert_eq!(product(&[3, 4, 5]), 60);
    }
}
