//! The lights that are not emitting meshes: sphere lights (with an
//! optional spot cone) and distant lights (a sun of some angular
//! diameter). Each is sampled by a direction from the shaded point with
//! its solid-angle density, for next-event estimation weighed by MIS
//! against lobe sampling (`crate::integrator`'s `analytic_nee`).
//! `docs/scene-format.md`, "`[[lights]]`".

pub mod cone;
pub mod distant;
pub mod sample;
pub mod sphere;
pub mod spot;
pub mod units;

pub use cone::Cone;
pub use distant::DistantLight;
pub use sample::DirSample;
pub use sphere::SphereLight;
pub use spot::Spot;

use crate::geometry::Vec3;

/// One light of `[[lights]]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    Sphere(SphereLight),
    Distant(DistantLight),
}

impl Light {
    /// A direction from `p` towards the light (two randoms); None where it
    /// cannot light `p` (inside a sphere light).
    pub fn sample(&self, p: Vec3, u: [f32; 2]) -> Option<DirSample> {
        match self {
            Light::Sphere(s) => s.sample(p, u),
            Light::Distant(d) => Some(d.sample(u)),
        }
    }

    /// "sphere", "spot" or "distant", for the plan.
    pub fn kind(&self) -> &'static str {
        match self {
            Light::Sphere(SphereLight { spot: Some(_), .. }) => "spot",
            Light::Sphere(_) => "sphere",
            Light::Distant(_) => "distant",
        }
    }
}
