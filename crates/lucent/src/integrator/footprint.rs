//! The footprint of a path sample ([`Cone`]): the width of the surface
//! one sample stands for, carried along the path as a ray cone
//! (Amanatides 1984; Akenine-Möller et al. 2019), w(t) = w₀ + γ·t, from
//! the camera's pixel angle ([`CameraSpread`]). Subsurface level of detail
//! (`crate::materials::lod`) compares it with the profile's reach. The
//! rules for camera rays and specular and non-specular bounces, and why
//! they are conservative: `docs/bssrdf.md` §11, "The footprint". Cost: two
//! f32 per path, one multiply-add per hit.

use crate::geometry::Vec3;

/// The spread angle (radians) a non-specular bounce gives the footprint
/// cone at least: a tenth of a cosine lobe's ~1 rad (`docs/bssrdf.md` §11, "The footprint").
pub const ROUGH_SPREAD: f32 = 0.1;

/// A ray cone: the footprint one path sample stands for (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Width at the ray's origin (scene units).
    pub width: f32,
    /// Spread angle (radians): the width grows by this per unit distance.
    pub spread: f32,
}

impl Cone {
    /// The cone of a camera ray with unit direction `d`: from a point,
    /// spreading by the pixel's angle along `d`.
    pub fn camera(cam: &CameraSpread, d: Vec3) -> Cone {
        let c = d.dot(cam.forward).max(0.0);
        Cone {
            width: 0.0,
            spread: cam.pixel_angle * c * c,
        }
    }

    /// The footprint width at distance `t` along the ray (unit direction).
    #[inline]
    pub(crate) fn width_at(&self, t: f32) -> f32 {
        self.width + self.spread * t
    }

    /// The cone after a specular bounce at distance `t`: same spread.
    #[inline]
    pub fn specular(&self, t: f32) -> Cone {
        Cone {
            width: self.width_at(t),
            spread: self.spread,
        }
    }

    /// The cone after a non-specular bounce at distance `t`: the spread
    /// becomes at least [`ROUGH_SPREAD`]; never narrower.
    #[inline]
    pub fn rough(&self, t: f32) -> Cone {
        Cone {
            width: self.width_at(t),
            spread: self.spread.max(ROUGH_SPREAD),
        }
    }
}

/// What a camera ray's cone is built from: the angle one pixel subtends on
/// the axis and the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpread {
    pub pixel_angle: f32,
    pub forward: Vec3,
}

impl CameraSpread {
    /// For a pinhole camera with vertical field of view `fov_y` degrees and
    /// `height` pixels looking along `forward`: the pixel pitch on a film
    /// at unit distance, 2·tan(fov/2)/height.
    pub fn new(fov_y: f32, height: u32, forward: Vec3) -> Self {
        CameraSpread {
            pixel_angle: 2.0 * (fov_y.to_radians() * 0.5).tan() / height.max(1) as f32,
            forward: forward.normalize(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primary_footprint_is_the_pixel_cone_width() {
        // 90° fov, 100 px high: one pixel at distance 1 is 2/100 wide; a
        // plane 7 units down the axis is seen with footprint 0.14.
        let cam = CameraSpread::new(90.0, 100, Vec3::new(0.0, 0.0, -2.0));
        let cone = Cone::camera(&cam, Vec3::new(0.0, 0.0, -1.0));
        assert!((cone.width_at(7.0) - 0.14).abs() < 1e-6);
        // 60° off axis the pixel subtends cos²60° = ¼ of that angle
        let d = Vec3::new(60f32.to_radians().sin(), 0.0, -60f32.to_radians().cos());
        let off = Cone::camera(&cam, d);
        assert!((off.width_at(7.0) - 0.14 * 0.25).abs() < 1e-6);
    }

    #[test]
    fn a_diffuse_bounce_grows_the_footprint_and_never_shrinks_it() {
        let narrow = Cone {
            width: 0.01,
            spread: 0.002,
        };
        let after = narrow.rough(5.0);
        assert_eq!(after.width, narrow.width_at(5.0));
        assert_eq!(after.spread, ROUGH_SPREAD);
        assert!(after.width_at(3.0) > narrow.specular(5.0).width_at(3.0));
        // already wider than a rough lobe: kept
        let wide = Cone {
            width: 0.5,
            spread: 0.3,
        };
        assert_eq!(wide.rough(2.0).spread, 0.3);
        for t in [0.0, 0.5, 10.0] {
            assert!(wide.rough(2.0).width_at(t) >= wide.width_at(2.0));
            assert!(narrow.rough(1.0).width_at(t) >= narrow.specular(1.0).width_at(t));
        }
        // a specular bounce keeps the spread
        assert_eq!(narrow.specular(5.0).spread, narrow.spread);
    }
}
