//! A material whose parameters vary over the surface: a base material,
//! with its diffuse albedo read from a texture and/or its shading normal
//! perturbed by a tangent-space normal map or a height (bump) map, a
//! glossy base or a coat whose roughness is read from a texture, or a
//! subsurface base whose albedo, lengths and coat roughness are read from
//! textures at the exit point (`docs/scene-format.md`, "Textures";
//! `docs/bssrdf.md` §13). Resolved at
//! each hit into the base material's scattering with the looked-up values
//! (`crate::integrator::path`).

use std::sync::Arc;

use super::roughness_steps::RoughnessSteps;
use super::Material;
use crate::texture::{Texture, TextureRef};

/// A base material with texture-driven parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Textured {
    /// What scatters; never itself `Textured`.
    pub base: Material,
    /// The albedo, linear RGB: a `diffuse` base's, or a subsurface base's
    /// A (then a factor on the material's `albedo`, see [`Self::medium`]).
    pub albedo: Option<TextureRef>,
    /// A tangent-space normal map: RGB in [0, 1] read as 2c − 1, z along
    /// the shading normal, x along the tangent (increasing u), y along the
    /// bitangent (increasing v).
    pub normal: Option<Arc<Texture>>,
    /// A height map (the mean of its channels, times `scale` scene units)
    /// whose slopes tilt the shading normal; never with `normal`.
    pub bump: Option<Bump>,
    /// A subsurface base's factor per channel on its lengths (`dmfp`).
    pub dmfp: Option<TextureRef>,
    /// The roughness of a conductor, rough dielectric, plastic coat or
    /// subsurface coat.
    pub roughness: Option<RoughnessMap>,
    /// How a subsurface base's parameters follow from `albedo` and `dmfp`
    /// at a point; None for other bases.
    #[cfg(feature = "subsurface")]
    pub medium: Option<super::textured_medium::MediumRecipe>,
    /// Which parameter reads which texture, as the scene names them (for
    /// the render plan).
    pub names: Vec<TextureUse>,
}

/// A roughness texture: at a point, the mean of its channels times
/// `scale`, clamped to [0, 1]; with the albedo tables of the roughness
/// steps those values span where the base's energy compensation reads
/// one (None for a rough dielectric, which has none).
#[derive(Clone, Debug, PartialEq)]
pub struct RoughnessMap {
    pub texture: Arc<Texture>,
    pub scale: f32,
    pub steps: Option<RoughnessSteps>,
}

impl RoughnessMap {
    /// The roughness at `uv` for a footprint `width` UV units wide.
    #[inline]
    pub fn at(&self, uv: glam::Vec2, width: f32) -> f32 {
        let c = self.texture.lookup(uv, width);
        ((c.x + c.y + c.z) / 3.0 * self.scale).clamp(0.0, 1.0)
    }

    /// The least and greatest roughness the map gives.
    pub fn range(texture: &Texture, scale: f32) -> (f32, f32) {
        let (lo, hi) = texture.mean_range();
        let (a, b) = (lo * scale, hi * scale);
        (a.min(b).clamp(0.0, 1.0), a.max(b).clamp(0.0, 1.0))
    }
}

/// A bump map: a height texture and the height of a texel of value 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Bump {
    pub texture: Arc<Texture>,
    pub scale: f32,
}

/// A parameter read from a texture: its key (`albedo_texture`,
/// `normal_map`, `map_Kd`, …) and the texture's name or file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TextureUse {
    pub key: &'static str,
    pub texture: String,
}

impl Textured {
    /// A textured `base` with `albedo` and/or a `normal` map.
    pub fn new(base: Material, albedo: Option<TextureRef>, normal: Option<Arc<Texture>>) -> Self {
        Textured {
            base,
            albedo,
            normal,
            bump: None,
            dmfp: None,
            roughness: None,
            #[cfg(feature = "subsurface")]
            medium: None,
            names: Vec::new(),
        }
    }

    /// The same, with the textures' `names` recorded.
    pub fn named(mut self, names: Vec<TextureUse>) -> Self {
        self.names = names;
        self
    }

    /// The textures it reads.
    pub fn textures(&self) -> impl Iterator<Item = &Arc<Texture>> {
        self.albedo
            .iter()
            .map(|a| &a.texture)
            .chain(self.normal.iter())
            .chain(self.bump.iter().map(|b| &b.texture))
            .chain(self.dmfp.iter().map(|a| &a.texture))
            .chain(self.roughness.iter().map(|r| &r.texture))
    }
}
