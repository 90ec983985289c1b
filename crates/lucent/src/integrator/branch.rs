//! A path between two vertices, the small stack of paths a coat split off
//! (`docs/bssrdf.md` §6 "The coat"), and Russian roulette (pbrt-v4
//! §13.1.1).

use super::aov::Event;
use super::footprint::Cone;
use super::lobe::{Bounce, PrevVertex, Vertex};
use super::nee::NeeAt;
use super::Interaction;
use crate::geometry::{Ray, Vec3};
use crate::sampling::{Draw, SampleRng};

/// Bounces after which Russian roulette may end a path.
pub(crate) const RR_START: u32 = 3;

/// Paths waiting to be traced after the current one ends. A path pushes
/// at most one branch per depth below the coat's split depth, and a branch
/// starts one depth below the vertex that pushed it; the pair's paths add
/// at most three at the camera vertex (`subsurface::split`), which pushes
/// nothing below it: the stack is never full.
pub(crate) const MAX_BRANCHES: usize = 4;

/// A path to trace: its ray, throughput, the last non-specular vertex and
/// its lobe pdf (for the emission MIS weight), whether it has scattered
/// off a non-specular lobe (for the regularized coat), its depth, the
/// class of its first event (for the light-path passes), and its
/// footprint cone (for subsurface level of detail,
/// [`crate::materials::lod`]).
#[derive(Clone, Copy)]
pub(crate) struct Branch {
    pub(crate) ray: Ray,
    /// The object `ray` leaves, if it cannot meet it
    /// ([`super::Context::leaving`]).
    pub(crate) from: Option<u32>,
    pub(crate) beta: Vec3,
    /// None after the camera or a specular bounce, where no light sample
    /// competed for this direction.
    pub(crate) prev: Option<PrevVertex>,
    /// Some vertex before this ray scattered with a non-specular lobe: a
    /// smooth coat met from here on reflects as the regularized one
    /// (`docs/bssrdf.md` §6, "Regularized coat").
    pub(crate) scattered: bool,
    pub(crate) depth: u32,
    pub(crate) event: Event,
    pub(crate) cone: Cone,
}

impl Branch {
    /// Goes on along `b`, which leaves the object `from` (if it cannot
    /// meet it), with the footprint `cone`; a lobe's bounce (one with a
    /// previous vertex) marks the path as scattered.
    #[inline(always)]
    pub(crate) fn go_on(&mut self, b: Bounce, from: Option<u32>, cone: Cone) {
        (self.ray, self.beta, self.prev) = (b.ray, b.beta, b.prev);
        self.scattered |= b.prev.is_some();
        self.from = from;
        self.cone = cone;
    }

    /// Goes on along `ray` with the throughput it has and no previous
    /// vertex (a specular continuation), still leaving the object it
    /// leaves, with the footprint `cone`.
    #[inline(always)]
    pub(crate) fn straight_on(&mut self, ray: Ray, cone: Cone) {
        let b = Bounce {
            ray,
            beta: self.beta,
            prev: None,
        };
        self.go_on(b, self.from, cone);
    }
}

/// Where a path is at a hit: the interaction, ωo, the distance along the
/// ray, the depth, whether it is the first hit of a recorded path, and the
/// footprint a specular or a lobe continuation has from there.
pub(crate) struct At<'a> {
    pub(crate) si: &'a Interaction,
    pub(crate) wo: Vec3,
    #[cfg_attr(not(feature = "subsurface"), allow(dead_code))]
    pub(crate) t: f32,
    pub(crate) depth: u32,
    /// The hit's barycentrics (u, v) on its triangle.
    pub(crate) bary: [f32; 2],
    pub(crate) first: bool,
    pub(crate) cone_specular: Cone,
    pub(crate) cone_rough: Cone,
}

/// Where a path goes from a hit.
pub(crate) enum Next<'v, 's> {
    /// On from a vertex, with light sampled there as `NeeAt` asks.
    Vertex(&'v Vertex<'s>, NeeAt),
    /// Along the path's ray, already set (after roulette).
    Bounce,
    /// Nowhere: the path ends.
    #[cfg_attr(not(feature = "subsurface"), allow(dead_code))]
    End,
}

/// A fixed-capacity stack of [`Branch`]es (no allocation per sample).
#[derive(Default)]
pub(crate) struct Branches {
    items: [Option<Branch>; MAX_BRANCHES],
    len: usize,
}

impl Branches {
    /// Never full (see [`MAX_BRANCHES`]).
    #[cfg(feature = "subsurface")]
    pub(crate) fn push(&mut self, b: Branch) {
        self.items[self.len] = Some(b);
        self.len += 1;
    }

    pub(crate) fn pop(&mut self) -> Option<Branch> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        self.items[self.len].take()
    }
}

/// Russian roulette after `RR_START` bounces: survive with probability
/// min(1, max β) and reweight; false ends the path.
pub(crate) fn roulette(depth: u32, beta: &mut Vec3, rng: &mut SampleRng) -> bool {
    if depth < RR_START {
        return true;
    }
    let survive = beta.max_element().min(1.0);
    if survive <= 0.0 || rng.uniform() >= survive {
        return false;
    }
    *beta /= survive;
    true
}
