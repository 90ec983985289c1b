//! A subsurface hit with more than one vertex: the coat's lobe at xo, the
//! path the coat reflects, the entry point(s) xi and the light samples the
//! plane model drew ahead (`docs/bssrdf.md` §5, §6 "The coat").

use super::lobe::{Bounce, Vertex};
use crate::geometry::Vec3;
use crate::lights::LightSample;

/// What a coated subsurface hit at xo turns into: the coat's lobe at xo
/// (next-event estimation there), a path the coat reflected, and the
/// entry vertex xi where this path goes on.
pub(crate) struct Coated<'a> {
    /// The rough coat's vertex at xo, lit with the throughput before the hit.
    pub(crate) coat: Option<Weighted<'a>>,
    /// The coat's reflected path.
    pub(crate) reflected: Option<Bounce>,
    /// The entry vertex xi (its throughput already in β): this path goes on
    /// there and `reflected` waits on the stack; None: this path goes on
    /// along `reflected`, or ends.
    pub(crate) entry: Option<Vertex<'a>>,
    /// The other entry point of an antithetic pair
    /// ([`super::path::PAIR_DEPTH`]); when Some, light sampled at `entry`
    /// counts ½ too.
    pub(crate) pair: Option<Weighted<'a>>,
    /// With `pair`: the paths that go on from each of the two entry points
    /// (their throughputs already scaled by ½, the pair's share), or 0 when
    /// this path goes on from `entry` alone, chosen from the two, and the
    /// twin is only lit.
    pub(crate) paths_each: u32,
    /// What the plane model drew ahead ([`Ahead`]).
    pub(crate) ahead: Ahead,
}

/// A vertex lit by next-event estimation only, with the throughput its
/// light sample is weighted by.
pub(crate) struct Weighted<'a> {
    pub(crate) vertex: Vertex<'a>,
    pub(crate) beta: Vec3,
}

/// The plane model's part of a subsurface hit
/// ([`super::control_variate`]): when it applies, the light samples drawn
/// ahead for next-event estimation at the entry point (and at its pair's
/// twin), which its model used.
#[derive(Clone, Copy, Default)]
pub(crate) struct Ahead {
    pub(crate) lights: Option<[Option<LightSample>; 2]>,
}
