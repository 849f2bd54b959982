//! The pinhole camera as the generate stage takes it, with the ray cone's pixel spread angle
//! (Akenine-Möller et al. 2019: α = atan(2 tan(yfov/2) / height)).

use crate::error::RenderError;
use crate::gpu_types::GpuFrame;
use crate::integrator::RenderConfig;
use crate::scene::Camera;
use glam::Vec3;

/// An orthonormal camera frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFrame {
    pub position: Vec3,
    pub forward: Vec3,
    pub up: Vec3,
    pub right: Vec3,
    pub yfov: f32,
}

impl CameraFrame {
    /// Checks the camera and completes its frame; a degenerate one is an error.
    pub fn new(camera: &Camera) -> Result<Self, RenderError> {
        let forward = camera.forward.normalize_or_zero();
        let right = forward.cross(camera.up).normalize_or_zero();
        let ok = camera.position.is_finite()
            && forward != Vec3::ZERO
            && right != Vec3::ZERO
            && camera.yfov.is_finite()
            && camera.yfov > 1e-4
            && camera.yfov < std::f32::consts::PI - 1e-3;
        if !ok {
            return Err(RenderError::Scene(format!(
                "the camera {camera:?} is degenerate (position, direction, up or field of view)"
            )));
        }
        Ok(CameraFrame {
            position: camera.position,
            forward,
            up: right.cross(forward),
            right,
            yfov: camera.yfov,
        })
    }

    /// The camera fields of the frame uniform for an image of `config`'s size.
    pub fn gpu_frame(&self, config: &RenderConfig) -> GpuFrame {
        let tan_half = (0.5 * self.yfov).tan();
        let aspect = config.width as f32 / config.height as f32;
        let spread = (2.0 * tan_half / config.height as f32).atan();
        GpuFrame {
            width: config.width,
            height: config.height,
            max_depth: config.max_depth,
            seed: config.seed,
            rr_depth: config.rr_depth,
            ray_epsilon: 1e-5,
            cam_pos: self.position.extend(tan_half).to_array(),
            cam_forward: self.forward.extend(aspect).to_array(),
            cam_up: self.up.extend(spread).to_array(),
            cam_right: self.right.extend(0.0).to_array(),
            ..Default::default()
        }
    }
}
