//! What a subsurface hit turns into, and the trait by which the bounce
//! loop asks an estimator for it: the diffusion BSSRDF's probes
//! ([`super::subsurface`]) or the random walk ([`super::randomwalk`])
//! (`docs/bssrdf.md` §1, §5, §7). Without the `subsurface` feature no
//! material calls for it.
#![cfg_attr(not(feature = "subsurface"), allow(dead_code))]

use super::aov::{Event, Recorder};
#[cfg(not(feature = "subsurface"))]
use super::lobe::Subsurface;
use super::lobe::Vertex;
use super::state::PathState;
use super::{Context, Effect, Interaction};
use crate::geometry::{Ray, Vec3};
#[cfg(feature = "subsurface")]
use crate::materials::Subsurface;

/// A hit on a subsurface object at xo: its material, the interaction, ωo,
/// the path's depth there, the width of its footprint
/// ([`crate::materials::lod`]) and whether the path has scattered off a
/// non-specular lobe before (the diffusion estimator's coat is then the
/// regularized one, `docs/bssrdf.md` §6).
pub(crate) struct SubsurfaceHit<'h, 's> {
    pub(crate) ss: &'s Subsurface,
    pub(crate) si: &'h Interaction,
    pub(crate) wo: Vec3,
    pub(crate) depth: u32,
    pub(crate) width: f32,
    pub(crate) scattered: bool,
}

/// An estimator of light transport through subsurface objects. The bounce
/// loop is generic over it, so each implementation gets its own
/// monomorphised loop.
pub(crate) trait SubsurfaceScatter {
    /// The effect whose time the loop charges a call with.
    const EFFECT: Effect;
    /// What `hit` turns into; may scale the throughput `beta`.
    fn scatter<'s, R: Recorder>(
        &mut self,
        ctx: &'s Context,
        hit: &SubsurfaceHit<'_, 's>,
        beta: &mut Vec3,
        st: &mut PathState<R>,
    ) -> Scatter<'s>;
}

/// Without the `subsurface` feature there are no subsurface hits: the
/// material type is uninhabited, so this handler is never called.
#[cfg(not(feature = "subsurface"))]
pub(crate) struct NoSubsurface;

#[cfg(not(feature = "subsurface"))]
impl SubsurfaceScatter for NoSubsurface {
    const EFFECT: Effect = Effect::Probe;
    fn scatter<'s, R: Recorder>(
        &mut self,
        _: &'s Context,
        hit: &SubsurfaceHit<'_, 's>,
        _: &mut Vec3,
        _: &mut PathState<R>,
    ) -> Scatter<'s> {
        match *hit.ss {}
    }
}

/// What a subsurface hit turns into: a vertex that scatters light with a
/// lobe (next-event estimation, then lobe sampling), a ray that continues
/// without one (a specular bounce, or leaving a medium; with the class of
/// that event for the light-path passes, [`super::aov`]), or the end of the
/// path.
// Returned by value once per subsurface hit and read in place (the loop
// borrows the vertex from it); boxing the large variant would allocate in
// the hot path.
#[allow(clippy::large_enum_variant)]
pub(crate) enum Scatter<'a> {
    Vertex(Vertex<'a>),
    Continue(Ray, Event),
    Absorbed,
    /// A subsurface hit under a coat, or with more than one vertex.
    #[cfg(feature = "subsurface")]
    Coated(super::coated::Coated<'a>),
    /// A random walk that sampled lights through its boundary
    /// ([`super::walk_nee`]): the light it found (the path's throughput
    /// included) and, unless it was absorbed, the refracted ray it left
    /// along, with the scattering point it left from. `source`: the light
    /// triangle of the walk's last connection that brought light (the
    /// passes attribute all of it there).
    #[cfg(feature = "subsurface")]
    WalkLit {
        light: Vec3,
        source: u32,
        exit: Option<(Ray, Option<Through>)>,
    },
}

/// A walk's exit straight after a scattering point `x`, through the
/// triangle (`geom`, `prim`) of a boundary of index `eta`: emission its
/// refracted ray finds next may be the connection's to count
/// ([`super::walk_nee`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Through {
    pub(crate) x: Vec3,
    pub(crate) geom: u32,
    pub(crate) prim: u32,
    pub(crate) eta: f32,
}
