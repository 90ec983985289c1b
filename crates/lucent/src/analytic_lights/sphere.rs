//! Sphere lights: a sphere of radius r emitting radiance L from its
//! outside into every outward direction (uniformly, or shaped by a
//! [`Spot`]), sampled by the solid angle of the cone it subtends from the
//! shaded point (pbrt-v4 §12.2.2), so a tiny sphere is a point light
//! without a singularity. It is not in the ray accelerator: rays that
//! cross it see its light and go on (it casts no shadow).
//! `docs/scene-format.md`, "`[[lights]]`".

use super::cone::Cone;
use super::sample::DirSample;
use super::spot::Spot;
use crate::geometry::{Ray, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    pub center: Vec3,
    pub radius: f32,
    pub radiance: Vec3,
    pub spot: Option<Spot>,
}

impl SphereLight {
    /// The cone the sphere subtends from `p`; None from inside it.
    fn cone(&self, p: Vec3) -> Option<(Cone, f32)> {
        let to = self.center - p;
        let d2 = to.length_squared();
        let r2 = self.radius * self.radius;
        if d2 <= r2 {
            return None;
        }
        let d = d2.sqrt();
        Some((Cone::from_sin2(to / d, r2 / d2), d))
    }

    /// The radiance leaving the sphere in unit direction `travel`.
    pub fn radiance_towards(&self, travel: Vec3) -> Vec3 {
        match &self.spot {
            Some(s) => self.radiance * s.factor(travel),
            None => self.radiance,
        }
    }

    /// A direction from `p` towards the sphere, uniform in its cone, with
    /// the distance to the sphere's near surface along it.
    pub fn sample(&self, p: Vec3, u: [f32; 2]) -> Option<DirSample> {
        let (cone, d) = self.cone(p)?;
        let (wi, _, sin2) = cone.sample(u);
        let cos = wi.dot(cone.axis);
        let r2 = self.radius * self.radius;
        let dist = d * cos - (r2 - d * d * sin2).max(0.0).sqrt();
        let pdf = cone.pdf();
        Some(DirSample {
            wi,
            dist,
            weight: self.radiance_towards(-wi) / pdf,
            pdf,
        })
    }

    /// The solid-angle density [`sample`](Self::sample) gives each direction
    /// from `p` that meets the sphere.
    pub fn pdf(&self, p: Vec3) -> f32 {
        self.cone(p).map_or(0.0, |(c, _)| c.pdf())
    }

    /// Where `ray` (from outside) enters the sphere, in units of its `d`,
    /// if before `t_max`.
    pub fn hit(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let f = ray.o - self.center;
        let r2 = self.radius * self.radius;
        if f.length_squared() <= r2 {
            return None;
        }
        let a = ray.d.length_squared();
        // The closest approach, then the half chord: no b² − ac cancellation
        // for a small sphere far away.
        let t_close = -f.dot(ray.d) / a;
        let q = f + ray.d * t_close;
        let h2 = r2 - q.length_squared();
        if h2 < 0.0 || t_close <= 0.0 {
            return None;
        }
        let t = t_close - (h2 / a).sqrt();
        (t > 0.0 && t < t_max).then_some(t)
    }
}
