//! Which of the `[[lights]]` a vertex samples: one, picked in proportion
//! to the luminance of the power it gives the scene, so that a weak light
//! beside a strong one takes few of the samples (`docs/scene-format.md`,
//! "`[[lights]]`"). A sphere emits Φ = π r² L Ω (Ω = 4π, or its spot's
//! solid angle); a distant light delivers its irradiance E over the disk
//! of the scene's bounding sphere, Φ = π R² E. With no light of positive
//! finite power, each is picked uniformly.

use super::Light;
use crate::sampling::{luminance, Distribution1D};

use std::f64::consts::PI;

/// The probabilities of picking each light.
#[derive(Clone, Debug, Default)]
pub struct LightPick {
    dist: Distribution1D,
}

impl LightPick {
    /// The pick among `lights` in a scene whose bounding sphere has radius
    /// `scene_radius` (a non-finite or non-positive radius counts as 1).
    pub fn new(lights: &[Light], scene_radius: f32) -> Self {
        let r = if scene_radius.is_finite() && scene_radius > 0.0 {
            scene_radius as f64
        } else {
            1.0
        };
        let mut w: Vec<f64> = lights.iter().map(|l| power(l, r)).collect();
        if !(w.iter().all(|x| x.is_finite()) && w.iter().sum::<f64>() > 0.0) {
            w = vec![1.0; lights.len()];
        }
        LightPick {
            dist: Distribution1D::new(&w),
        }
    }

    /// The light a random number `u` ∈ [0, 1) picks (the lights must not
    /// be empty).
    #[inline]
    pub fn index(&self, u: f32) -> usize {
        self.dist.sample_index(u)
    }

    /// The probability of picking light `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.dist.pmf(i)
    }
}

/// The luminance of the power light `l` gives a scene of bounding radius
/// `r` (W in the scene's units, up to a constant common to all lights).
pub fn power(l: &Light, r: f64) -> f64 {
    match l {
        Light::Sphere(s) => {
            let omega = s.spot.as_ref().map_or(4.0 * PI, |sp| sp.solid_angle());
            let rs = s.radius as f64;
            PI * rs * rs * omega * luminance(s.radiance) as f64
        }
        Light::Distant(d) => {
            // E = L π sin²θmax, sin²θmax = (1 − cos)(1 + cos); a delta
            // light's radiance is its irradiance
            let e = if d.is_delta() {
                luminance(d.radiance) as f64
            } else {
                let omc = d.cone.one_minus_cos as f64;
                luminance(d.radiance) as f64 * PI * omc * (2.0 - omc)
            };
            PI * r * r * e
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic_lights::{Cone, DistantLight, SphereLight};
    use crate::geometry::Vec3;

    fn sphere(radius: f32, l: f32) -> Light {
        Light::Sphere(SphereLight {
            center: Vec3::ZERO,
            radius,
            radiance: Vec3::splat(l),
            spot: None,
        })
    }

    /// The probabilities sum to one and follow the powers: a sphere of
    /// twice the radius has four times the power, a distant light of
    /// irradiance E over a scene of radius R has π R² E. Caught: a
    /// uniform pick, a radius not squared, a distant light's power
    /// without the scene's size.
    #[test]
    fn lights_are_picked_in_proportion_to_their_power() {
        let sun = Light::Distant(DistantLight {
            cone: Cone::from_sin2(Vec3::Y, 0.0),
            radiance: Vec3::splat(2.0),
        });
        let lights = [sphere(1.0, 1.0), sphere(2.0, 1.0), sun];
        let pick = LightPick::new(&lights, 3.0);
        let want = [4.0 * PI * PI, 16.0 * PI * PI, PI * 9.0 * 2.0];
        let total: f64 = want.iter().sum();
        let sum: f32 = (0..3).map(|i| pick.pmf(i)).sum();
        assert!((sum - 1.0).abs() < 1e-6, "Σ pmf = {sum}");
        for (i, w) in want.iter().enumerate() {
            let p = pick.pmf(i) as f64;
            assert!((p - w / total).abs() < 1e-6, "light {i}: {p}");
        }
        // the random number picks by the cumulative probabilities
        let edge = (want[0] / total) as f32;
        assert_eq!(pick.index(edge * 0.999), 0);
        assert_eq!(pick.index(edge * 1.001), 1);
        assert_eq!(pick.index(0.9999), 2);
        // no power at all: uniform
        let dark = LightPick::new(&[sphere(1.0, 0.0), sphere(2.0, 0.0)], 1.0);
        assert_eq!((dark.pmf(0), dark.pmf(1)), (0.5, 0.5));
    }
}
