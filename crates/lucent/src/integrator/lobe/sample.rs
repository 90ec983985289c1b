//! A direction sampled from a lobe: pbrt-v4's `BSDFSample`.

use crate::geometry::Vec3;

/// A direction sampled from a lobe (local frame), with f |cos θ| / pdf
/// and the solid-angle pdf.
#[derive(Clone, Copy)]
pub(crate) struct LobeSample {
    pub(crate) wi: Vec3,
    pub(crate) weight: Vec3,
    pub(crate) pdf: f32,
}

impl LobeSample {
    pub(crate) fn new((wi, weight, pdf): (Vec3, Vec3, f32)) -> Self {
        LobeSample { wi, weight, pdf }
    }

    pub(crate) fn glossy(s: crate::materials::conductor::GlossySample) -> Self {
        LobeSample {
            wi: s.wi,
            weight: s.weight,
            pdf: s.pdf,
        }
    }
}
