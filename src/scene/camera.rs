//! A pinhole perspective camera (pbrt-v4 §5.2 without lens or motion).

use crate::geometry::{Ray, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub look_from: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y: f32,
    pub width: u32,
    pub height: u32,
    // derived
    origin: Vec3,
    forward: Vec3,
    right: Vec3,
    upv: Vec3,
    tan_half: f32,
}

impl Camera {
    /// Builds a camera; the caller has checked that `look_from != look_at`,
    /// `up` is not parallel to the view direction, 0 < fov_y < 180 and the
    /// resolution is non-zero.
    pub fn new(
        look_from: Vec3,
        look_at: Vec3,
        up: Vec3,
        fov_y: f32,
        width: u32,
        height: u32,
    ) -> Self {
        let forward = (look_at - look_from).normalize();
        let right = forward.cross(up).normalize();
        let upv = right.cross(forward);
        Camera {
            look_from,
            look_at,
            up,
            fov_y,
            width,
            height,
            origin: look_from,
            forward,
            right,
            upv,
            tan_half: (fov_y.to_radians() * 0.5).tan(),
        }
    }

    /// The ray through film position (x, y) in pixels, y down; (0, 0) is
    /// the top-left corner of the image.
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let aspect = self.width as f32 / self.height as f32;
        let sx = (2.0 * x / self.width as f32 - 1.0) * self.tan_half * aspect;
        let sy = (1.0 - 2.0 * y / self.height as f32) * self.tan_half;
        let d = (self.forward + self.right * sx + self.upv * sy).normalize();
        Ray::new(self.origin, d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_fov_is_vertical() {
        let c = Camera::new(
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::ZERO,
            Vec3::Y,
            90.0,
            200,
            100,
        );
        let r = c.ray(100.0, 50.0);
        assert!((r.d - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        let top = c.ray(100.0, 0.0);
        assert!((top.d.y / -top.d.z - 1.0).abs() < 1e-5); // tan 45° = 1
        let right = c.ray(200.0, 50.0);
        assert!((right.d.x / -right.d.z - 2.0).abs() < 1e-5); // aspect 2
    }
}
