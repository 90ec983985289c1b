//! What the probes of one subsurface hit share (`docs/bssrdf.md` §5).

use crate::bssrdf::curvature_correction::{CurvatureCorrection, ExitFactor};
use crate::bssrdf::ProbeRandoms;
use crate::geometry::Frame;
use crate::integrator::Interaction;
use crate::materials::Subsurface;

/// What the probes of one hit share: the material, the hit, its shading
/// frame, the curvature the probe axes see, the mean curvature, the
/// probe's randoms and the curvature correction's exit half, if any.
pub(super) struct ProbeAt<'h, 's> {
    pub(super) ss: &'s Subsurface,
    pub(super) si: &'h Interaction,
    pub(super) frame_o: Frame,
    pub(super) kappa: f32,
    pub(super) k_mean: f32,
    pub(super) u: ProbeRandoms,
    pub(super) exit: Option<(&'s CurvatureCorrection, ExitFactor)>,
}
