//! Surface materials: Lambertian, smooth dielectric and subsurface (a
//! dielectric boundary over the Burley BSSRDF); each variant's scattering
//! lives in its own file. Fresnel reflectance is [`crate::fresnel`], shared
//! with the BSSRDF.

pub mod dielectric;
pub mod diffuse;
#[cfg(feature = "subsurface")]
pub mod estimator_options;
pub mod lod;
#[cfg(feature = "subsurface")]
pub mod microfacet;
#[cfg(feature = "subsurface")]
pub mod subsurface;

#[cfg(feature = "subsurface")]
use std::sync::Arc;

use crate::geometry::Vec3;
#[cfg(feature = "subsurface")]
pub use estimator_options::{CurvatureMode, EstimatorOptions, WalkBoundary, OPTIONS};
pub use lod::LodMode;
#[cfg(feature = "subsurface")]
pub use subsurface::{Subsurface, SubsurfaceOverrides};

#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection with albedo ρ (RGB).
    Diffuse { albedo: Vec3 },
    /// A smooth dielectric interface with relative index of refraction η
    /// (inside over outside): specular reflection and refraction.
    Dielectric { eta: f32 },
    /// A dielectric boundary over a scattering medium: the Burley BSSRDF
    /// (only with the `subsurface` feature).
    #[cfg(feature = "subsurface")]
    Subsurface(Arc<Subsurface>),
}

impl Material {
    /// Whether this is a subsurface material.
    #[cfg(feature = "subsurface")]
    pub(crate) fn is_subsurface(&self) -> bool {
        matches!(self, Material::Subsurface(_))
    }

    /// Whether this is a subsurface material: never, in a build without
    /// the `subsurface` feature.
    #[cfg(not(feature = "subsurface"))]
    pub(crate) fn is_subsurface(&self) -> bool {
        false
    }
}
