//! The diffusion BSSRDF at a subsurface hit xo (`docs/bssrdf.md` §5, §6,
//! §10, §11): the coat at xo ([`coat`]), the probe ray(s) for the entry
//! point xi ([`entries`]), the plane control variate's model at xo
//! ([`cv_model`]), and how the bounce loop reads a hit with more than one
//! vertex ([`split`]).

mod coat;
mod cv_model;
mod entries;
mod probe_at;
mod split;

pub(crate) use coat::COAT_SPLIT_DEPTH;
pub(crate) use split::resolve;

use super::aov::Recorder;
use super::scatter::{Scatter, SubsurfaceHit, SubsurfaceScatter};
use super::state::PathState;
use super::{Context, Effect};
use crate::geometry::Vec3;

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
