//! Surface materials. The enum grows as lucent does (a subsurface variant
//! joins it with the BSSRDF); each variant's scattering lives in its own file.

pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod subsurface;

use std::sync::Arc;

use crate::geometry::Vec3;
pub use subsurface::{Subsurface, SubsurfaceOverrides};

#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection with albedo ρ (RGB).
    Diffuse { albedo: Vec3 },
    /// A smooth dielectric interface with relative index of refraction η
    /// (inside over outside): specular reflection and refraction.
    Dielectric { eta: f32 },
    /// A dielectric boundary over a scattering medium: the Burley BSSRDF.
    Subsurface(Arc<Subsurface>),
}
