//! A material whose parameters vary over the surface: a base material,
//! with its diffuse albedo read from a texture and/or its shading normal
//! perturbed by a tangent-space normal map (`docs/scene-format.md`,
//! "Textures"). Resolved at each hit into the base material's scattering
//! with the looked-up values (`crate::integrator::path`).

use std::sync::Arc;

use super::Material;
use crate::texture::{Texture, TextureRef};

/// A base material with texture-driven parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Textured {
    /// What scatters; never itself `Textured`.
    pub base: Material,
    /// The diffuse albedo (a `diffuse` base only), linear RGB.
    pub albedo: Option<TextureRef>,
    /// A tangent-space normal map: RGB in [0, 1] read as 2c − 1, z along
    /// the shading normal, x along the tangent (increasing u), y along the
    /// bitangent (increasing v).
    pub normal: Option<Arc<Texture>>,
}

impl Textured {
    /// The textures it reads.
    pub fn textures(&self) -> impl Iterator<Item = &Arc<Texture>> {
        self.albedo
            .iter()
            .map(|a| &a.texture)
            .chain(self.normal.iter())
    }
}
