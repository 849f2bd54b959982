//! The pinhole camera as the generate stage takes it (its part of the frame uniform, which
//! `integrator.rs` assembles).

use crate::error::RenderError;
use crate::scene::Camera;
use glam::Vec3;

/// An orthonormal camera frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFrame {
    /// Eye position, world space.
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up, orthogonal to `forward`.
    pub up: Vec3,
    /// Unit right, `forward × up`.
    pub right: Vec3,
    /// Vertical field of view, radians.
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
}
