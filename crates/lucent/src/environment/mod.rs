//! The environment: the light arriving from infinitely far away along
//! rays that leave the scene, either one constant radiance or a
//! latitude-longitude HDR image ([`map`]) read from OpenEXR or Radiance
//! `.hdr` ([`image`]) and importance-sampled ([`distribution`]);
//! `docs/scene-format.md`, "`[environment]`".

pub mod distribution;
pub mod image;
pub mod map;

use std::sync::Arc;

use crate::geometry::Vec3;

pub use map::{EnvMap, EnvSample};

/// What rays that leave the scene see.
#[derive(Clone, Debug)]
pub enum Environment {
    /// The same radiance from every direction; found by escaping rays
    /// only (not light-sampled).
    Constant(Vec3),
    /// An image, light-sampled at every vertex that samples lights.
    Map(Arc<EnvMap>),
}

impl Environment {
    /// The radiance arriving from unit direction `d`.
    #[inline]
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        match self {
            Environment::Constant(c) => *c,
            Environment::Map(m) => m.radiance(d),
        }
    }

    /// The image, when there is one to sample.
    #[inline]
    pub fn map(&self) -> Option<&EnvMap> {
        match self {
            Environment::Constant(_) => None,
            Environment::Map(m) => Some(m),
        }
    }

    /// No light at all.
    pub fn is_black(&self) -> bool {
        match self {
            Environment::Constant(c) => c.max_element() <= 0.0,
            Environment::Map(_) => false,
        }
    }
}
