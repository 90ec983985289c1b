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
    // derived: the (unnormalized) direction through film position (0, 0)
    // and its change per pixel in x and y, so a ray costs two multiply-adds
    // and a normalization instead of the divisions of the film mapping
    origin: Vec3,
    d00: Vec3,
    dx: Vec3,
    dy: Vec3,
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
        // Film position (x, y) maps to forward + right·sx + upv·sy with
        // sx = (2x/w − 1)·tan(fov/2)·aspect and sy = (1 − 2y/h)·tan(fov/2).
        let tan_half = (fov_y.to_radians() * 0.5).tan();
        let half_w = tan_half * width as f32 / height as f32;
        Camera {
            look_from,
            look_at,
            up,
            fov_y,
            width,
            height,
            origin: look_from,
            d00: forward - right * half_w + upv * tan_half,
            dx: right * (2.0 * half_w / width as f32),
            dy: upv * (-2.0 * tan_half / height as f32),
        }
    }

    /// The ray through film position (x, y) in pixels, y down; (0, 0) is
    /// the top-left corner of the image.
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let d = (self.d00 + self.dx * x + self.dy * y).normalize();
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
