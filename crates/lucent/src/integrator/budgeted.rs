//! The path integrator's estimator of subsurface hits: the diffusion
//! BSSRDF's probes ([`super::subsurface`]), or the random walk
//! ([`super::randomwalk`]) at an object the accuracy budget gave it
//! (`crate::integrator::plan::budget`, `docs/bssrdf.md` §14). A render in
//! which no object walks (`Plan::walks`) does not come here: it runs
//! [`super::path::radiance`], diffusion at every hit, chosen once per
//! render by [`super::IntegratorKind::radiance`].

use super::aov::Recorder;
use super::path::sample;
use super::randomwalk::RandomWalk;
use super::scatter::{Scatter, SubsurfaceHit, SubsurfaceScatter};
use super::state::{PathState, Scratch};
use super::subsurface::Diffusion;
use super::{Clock, Context, Counters, Effect};
use crate::geometry::{Ray, Vec3};
use crate::sampling::SampleRng;

/// The radiance arriving along `camera_ray`: one sample of L, subsurface
/// hits estimated as each object's choice says. Same contract as
/// [`super::path::radiance`].
pub fn radiance<R: Recorder, T: Clock>(
    ctx: &Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
    rec: &mut R,
) -> Vec3 {
    sample::<R, T, _>(ctx, camera_ray, rng, scratch, counters, rec, &mut Budgeted)
}

/// Diffusion, or the walk where the object's choice is the walk.
struct Budgeted;

impl SubsurfaceScatter for Budgeted {
    const EFFECT: Effect = Effect::Probe;

    #[inline(always)]
    fn scatter<'s, R: Recorder>(
        &mut self,
        ctx: &'s Context,
        hit: &SubsurfaceHit<'_, 's>,
        beta: &mut Vec3,
        st: &mut PathState<R>,
    ) -> Scatter<'s> {
        if ctx.scene.objects[hit.si.geom as usize].walk {
            return RandomWalk.scatter(ctx, hit, beta, st);
        }
        Diffusion.scatter(ctx, hit, beta, st)
    }
}
