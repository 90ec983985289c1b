//! Surface materials: Lambertian, smooth and rough dielectric, conductor,
//! coated diffuse ("plastic") and subsurface (a dielectric boundary over
//! the Burley BSSRDF), and any of them with textured parameters; each
//! variant's scattering lives in its own file. Fresnel reflectance is [`crate::fresnel`], shared
//! with the BSSRDF.

#[cfg(feature = "subsurface")]
pub mod accuracy;
pub mod albedo_table;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
#[cfg(feature = "subsurface")]
pub mod estimator_options;
#[cfg(test)]
mod lobe_checks;
pub mod lod;
pub mod metals;
pub mod microfacet;
pub mod plastic;
pub mod rough_dielectric;
pub mod roughness_steps;
#[cfg(feature = "subsurface")]
pub mod subsurface;
pub mod textured;
#[cfg(feature = "subsurface")]
pub mod textured_medium;

use std::sync::Arc;

use crate::geometry::Vec3;
pub use conductor::Conductor;
#[cfg(feature = "subsurface")]
pub use estimator_options::{CurvatureMode, EstimatorOptions, WalkBoundary, OPTIONS};
pub use lod::LodMode;
pub use plastic::Plastic;
pub use rough_dielectric::RoughDielectric;
#[cfg(feature = "subsurface")]
pub use subsurface::Subsurface;
pub use textured::{Bump, RoughnessMap, TextureUse, Textured};

#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflection with albedo ρ (RGB).
    Diffuse { albedo: Vec3 },
    /// A smooth dielectric interface with relative index of refraction η
    /// (inside over outside): specular reflection and refraction.
    Dielectric { eta: f32 },
    /// A rough dielectric interface (GGX): glossy reflection and
    /// refraction.
    RoughDielectric(RoughDielectric),
    /// A metal: GGX reflection with a complex index of refraction.
    Conductor(Arc<Conductor>),
    /// A dielectric coat over a Lambertian base.
    Plastic(Arc<Plastic>),
    /// A dielectric boundary over a scattering medium: the Burley BSSRDF
    /// (only with the `subsurface` feature).
    #[cfg(feature = "subsurface")]
    Subsurface(Arc<Subsurface>),
    /// A base material with parameters read from textures at each hit.
    Textured(Arc<Textured>),
}

impl Material {
    /// Whether a hit on it reads texture coordinates.
    pub fn reads_textures(&self) -> bool {
        matches!(self, Material::Textured(_))
    }

    /// The material that scatters: the base of a textured one, else itself.
    pub fn base(&self) -> &Material {
        match self {
            Material::Textured(t) => &t.base,
            m => m,
        }
    }

    /// Whether this is a subsurface material (textured or not).
    #[cfg(feature = "subsurface")]
    pub(crate) fn is_subsurface(&self) -> bool {
        matches!(self.base(), Material::Subsurface(_))
    }

    /// Whether this is a subsurface material: never, in a build without
    /// the `subsurface` feature.
    #[cfg(not(feature = "subsurface"))]
    pub(crate) fn is_subsurface(&self) -> bool {
        false
    }
}
