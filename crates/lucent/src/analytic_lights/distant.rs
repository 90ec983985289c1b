//! Distant lights: radiance L from every direction within a cone of
//! angular diameter 2θmax about `to_light` (a sun, whose shadows have a
//! penumbra of that angle), sampled uniformly in the cone; with a
//! diameter of 0 a delta light of irradiance E. Escaping rays inside the
//! cone find its light. `docs/scene-format.md`, "`[[lights]]`".

use super::cone::Cone;
use super::sample::DirSample;
use crate::geometry::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistantLight {
    /// The cone of directions towards the light; 1 − cos θmax = 0: a delta.
    pub cone: Cone,
    /// L inside the cone; E (irradiance facing it) for a delta.
    pub radiance: Vec3,
}

impl DistantLight {
    /// Whether the light is a single direction (no penumbra, not found by
    /// escaping rays).
    pub fn is_delta(&self) -> bool {
        self.cone.one_minus_cos <= 0.0
    }

    /// A direction towards the light, uniform in its cone; a delta's one
    /// direction with an infinite pdf.
    pub fn sample(&self, u: [f32; 2]) -> DirSample {
        if self.is_delta() {
            return DirSample {
                wi: self.cone.axis,
                dist: f32::INFINITY,
                weight: self.radiance,
                pdf: f32::INFINITY,
            };
        }
        let (wi, _, _) = self.cone.sample(u);
        DirSample {
            wi,
            dist: f32::INFINITY,
            weight: self.radiance / self.cone.pdf(),
            pdf: self.cone.pdf(),
        }
    }

    /// The radiance an escaping ray of unit direction `d` finds, and the
    /// solid-angle density of sampling it; None outside the cone.
    pub fn escaped(&self, d: Vec3) -> Option<(Vec3, f32)> {
        if self.is_delta() || !self.cone.contains(d) {
            return None;
        }
        Some((self.radiance, self.cone.pdf()))
    }
}
