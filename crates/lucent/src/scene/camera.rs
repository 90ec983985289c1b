//! A perspective camera (pbrt-v4 §5.2, without motion): a pinhole, or a
//! thin lens of some aperture radius focused at a distance
//! (`docs/scene-format.md`, "`[camera]`").

use crate::geometry::{Ray, Vec3};
use crate::sampling::concentric_disk;

/// A thin lens: rays leave a disk of `radius` about the eye and pass
/// through the point the pinhole ray meets on the plane `focus_distance`
/// ahead (perpendicular to the view direction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Aperture radius, scene units (> 0).
    pub radius: f32,
    /// Distance from the eye to the plane in focus, scene units (> 0).
    pub focus_distance: f32,
}

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
    /// Unit view direction, right and up vectors of the film.
    forward: Vec3,
    right: Vec3,
    upv: Vec3,
    lens: Option<ThinLens>,
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
            forward,
            right,
            upv,
            lens: None,
        }
    }

    /// This camera with a thin lens (None: a pinhole).
    pub fn with_lens(mut self, lens: Option<ThinLens>) -> Self {
        self.lens = lens;
        self
    }

    pub fn lens(&self) -> Option<ThinLens> {
        self.lens
    }

    /// The ray through film position (x, y) and the lens point that
    /// `u` ∈ [0, 1)² picks (uniform over the aperture's disk); the pinhole
    /// ray without a lens.
    pub fn ray_through_lens(&self, x: f32, y: f32, u: [f32; 2]) -> Ray {
        let pinhole = self.ray(x, y);
        let Some(lens) = self.lens else {
            return pinhole;
        };
        let focus = pinhole.d * (lens.focus_distance / pinhole.d.dot(self.forward));
        let [lx, ly] = concentric_disk(u);
        let offset = self.right * (lens.radius * lx) + self.upv * (lens.radius * ly);
        Ray::new(self.origin + offset, (focus - offset).normalize())
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

    fn lens_camera(radius: f32, focus_distance: f32) -> Camera {
        Camera::new(
            Vec3::new(1.0, 2.0, 5.0),
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::Y,
            50.0,
            64,
            48,
        )
        .with_lens(Some(ThinLens {
            radius,
            focus_distance,
        }))
    }

    /// Where `r` meets the plane `depth` ahead of the eye along `forward`.
    fn at_depth(c: &Camera, r: &Ray, depth: f32) -> Vec3 {
        let t = (depth - (r.o - c.origin).dot(c.forward)) / r.d.dot(c.forward);
        r.at(t)
    }

    /// Every lens sample's ray through a film position meets the focal
    /// plane at the pinhole ray's point (a point there stays sharp), and
    /// leaves from within the aperture. Catches a focus point taken along
    /// the ray (a sphere of focus) rather than on the plane.
    #[test]
    fn a_point_in_the_focal_plane_stays_sharp() {
        let c = lens_camera(0.3, 4.0);
        for (x, y) in [(32.0, 24.0), (3.5, 40.2), (60.0, 1.0)] {
            let p = at_depth(&c, &c.ray(x, y), 4.0);
            for u in [[0.1, 0.9], [0.99, 0.5], [0.5, 0.0], [0.73, 0.21]] {
                let r = c.ray_through_lens(x, y, u);
                assert!((r.o - c.origin).length() <= 0.3 * 1.0001);
                assert!((at_depth(&c, &r, 4.0) - p).length() < 1e-4);
            }
        }
    }

    /// The rays of one film position spread over a disk of radius
    /// A·|z − f|/f on the plane at depth z (aperture radius A, focus f):
    /// the circle of confusion; the lens' edge reaches it.
    #[test]
    fn the_circle_of_confusion_matches_the_thin_lens_formula() {
        let (a, f) = (0.25, 3.0);
        let c = lens_camera(a, f);
        for z in [1.5, 6.0, 20.0] {
            let centre = at_depth(&c, &c.ray(32.0, 24.0), z);
            let mut widest = 0.0f32;
            for k in 0..64 {
                // u = (1, v) is the disk's edge for the concentric map.
                let u = [0.999_999, k as f32 / 64.0];
                let r = c.ray_through_lens(32.0, 24.0, u);
                widest = widest.max((at_depth(&c, &r, z) - centre).length());
            }
            let expect = a * (z - f).abs() / f;
            assert!(
                (widest / expect - 1.0).abs() < 1e-3,
                "z = {z}: {widest} vs {expect}"
            );
        }
    }

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
