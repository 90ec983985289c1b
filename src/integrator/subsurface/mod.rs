//! The diffusion BSSRDF at a subsurface hit xo (`docs/bssrdf.md` §5, §6,
//! §10, §11): the coat at xo ([`coat`]), the probe ray(s) for the entry
//! point xi ([`entries`]), the plane control variate's model at xo
//! ([`cv_model`]), and how the bounce loop reads a hit with more than one
//! vertex ([`split`]).

mod coat;
mod cv_model;
mod entries;
mod split;

pub(crate) use split::resolve;

use super::aov::Recorder;
use super::branch::MAX_BRANCHES;
use super::scatter::{Scatter, SubsurfaceHit, SubsurfaceScatter};
use super::state::PathState;
use super::{Context, Effect, Interaction};
use crate::bssrdf::curvature_correction::{CurvatureCorrection, ExitFactor};
use crate::bssrdf::ProbeRandoms;
use crate::geometry::{Frame, Vec3};
use crate::materials::Subsurface;

/// Smooth-coated subsurface hits at depths below this split into the
/// mirror reflection and the medium (both followed); deeper ones choose
/// one. 1: the camera vertex only (`docs/bssrdf.md` §6, "The coat").
pub(crate) const COAT_SPLIT_DEPTH: u32 = 1;
const _: () = assert!(COAT_SPLIT_DEPTH as usize <= MAX_BRANCHES);

/// The probe estimator of the diffusion BSSRDF ([`crate::bssrdf::probe`]).
pub(crate) struct Diffusion;

impl SubsurfaceScatter for Diffusion {
    const EFFECT: Effect = Effect::Probe;

    #[inline(always)]
    fn scatter<'s, R: Recorder>(
        &mut self,
        ctx: &'s Context,
        hit: &SubsurfaceHit<'_, 's>,
        beta: &mut Vec3,
        st: &mut PathState<R>,
    ) -> Scatter<'s> {
        coat::scatter(ctx, hit, beta, st)
    }
}

/// What the probes of one hit share: the material, the hit, its shading
/// frame, the curvature the probe axes see, the mean curvature, the
/// probe's randoms and the curvature correction's exit half, if any.
struct ProbeAt<'h, 's> {
    ss: &'s Subsurface,
    si: &'h Interaction,
    frame_o: Frame,
    kappa: f32,
    k_mean: f32,
    u: ProbeRandoms,
    exit: Option<(&'s CurvatureCorrection, ExitFactor)>,
}
