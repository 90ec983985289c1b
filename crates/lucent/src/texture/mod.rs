//! Image textures: a MIP pyramid of linear RGB texels ([`mip`]), looked up
//! with bilinear filtering between the two levels a footprint falls between
//! (trilinear), read once per file from PNG, OpenEXR or Radiance `.hdr`
//! ([`mod@file`]) and shared between the materials that name it.
//! `docs/scene-format.md`, "Textures".

pub mod file;
pub mod mip;

use std::sync::Arc;

use glam::Vec2;

use crate::geometry::Vec3;
pub use mip::{Texture, Wrap};

/// How a texture's stored values become the linear values a material
/// reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorSpace {
    /// The sRGB transfer curve is undone (colour maps: albedo).
    Srgb,
    /// Values as stored (data: roughness, normals, HDR images).
    Linear,
}

impl ColorSpace {
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "srgb" => Some(ColorSpace::Srgb),
            "linear" => Some(ColorSpace::Linear),
            _ => None,
        }
    }
}

/// The linear value of an sRGB-encoded value in [0, 1] (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The texture of a material parameter and the factor on its texels.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureRef {
    pub texture: Arc<Texture>,
    pub scale: Vec3,
}

impl TextureRef {
    /// The parameter at `uv` for a footprint `width` UV units wide.
    #[inline]
    pub fn eval(&self, uv: Vec2, width: f32) -> Vec3 {
        self.texture.lookup(uv, width) * self.scale
    }
}
