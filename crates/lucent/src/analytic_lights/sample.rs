//! A direction sampled towards a light.

use crate::geometry::Vec3;

/// A direction `wi` (unit) towards a light, the distance along it to the
/// light's surface (infinite for a distant light), the light's radiance
/// over the density (`weight` = L / pdf; a delta's irradiance E), and the
/// solid-angle `pdf` (infinite for a delta: no lobe sample can find it).
#[derive(Clone, Copy, Debug)]
pub struct DirSample {
    pub wi: Vec3,
    pub dist: f32,
    pub weight: Vec3,
    pub pdf: f32,
}
