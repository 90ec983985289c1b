//! Which estimator renders the image ([`IntegratorKind`]): the path
//! tracer with the probe estimator, or the volumetric random walk.

use super::aov;
use super::context::Context;
use super::effects::Clock;
use super::path;
#[cfg(feature = "subsurface")]
use super::randomwalk;
use crate::accel::Traversal;
use crate::stats::Counters;

/// Which estimator renders the image. Both treat surfaces, lights and the
/// environment alike; they differ at subsurface objects.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IntegratorKind {
    /// [`path::radiance`]: the diffusion BSSRDF sampled with probe rays.
    #[default]
    Path,
    /// [`randomwalk::radiance`]: a volumetric random walk in the medium
    /// (only with the `subsurface` feature).
    #[cfg(feature = "subsurface")]
    RandomWalk,
}

impl IntegratorKind {
    /// The traversal a render with this estimator uses when the scene asks
    /// for `asked` ([`Traversal`]): the random walk is always watertight (a
    /// walk that slipped out of a closed medium through a crack would leave
    /// it at the wrong place); the path integrator takes what is asked.
    pub fn traversal(self, asked: Traversal) -> Traversal {
        match self {
            IntegratorKind::Path => asked,
            #[cfg(feature = "subsurface")]
            IntegratorKind::RandomWalk => Traversal::Watertight,
        }
    }

    /// One sample of the radiance along `ray` with this estimator; its
    /// parts go to `rec` ([`aov`]), its effects' time to `T`
    /// ([`super::effects`]).
    pub fn radiance<R: aov::Recorder, T: Clock>(
        self,
        ctx: &Context,
        ray: crate::geometry::Ray,
        rng: &mut crate::sampling::SampleRng,
        scratch: &mut path::Scratch,
        counters: &mut Counters,
        rec: &mut R,
    ) -> crate::geometry::Vec3 {
        match self {
            // diffusion, or the walk where an accuracy budget chose it;
            // a render where none did never asks a hit's material
            #[cfg(feature = "subsurface")]
            IntegratorKind::Path if ctx.plan.walks => {
                super::budgeted::radiance::<R, T>(ctx, ray, rng, scratch, counters, rec)
            }
            IntegratorKind::Path => path::radiance::<R, T>(ctx, ray, rng, scratch, counters, rec),
            #[cfg(feature = "subsurface")]
            IntegratorKind::RandomWalk => {
                randomwalk::radiance::<R, T>(ctx, ray, rng, scratch, counters, rec)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_render_traverses_as_the_scene_asks_except_the_random_walk_always_watertight() {
        for t in [Traversal::Watertight, Traversal::Fast] {
            assert_eq!(IntegratorKind::Path.traversal(t), t);
            #[cfg(feature = "subsurface")]
            assert_eq!(
                IntegratorKind::RandomWalk.traversal(t),
                Traversal::Watertight
            );
        }
    }
}
