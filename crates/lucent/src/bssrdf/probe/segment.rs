//! What the probe sampler hands the integrator and gets back
//! (`docs/bssrdf.md` §5): the probe segment, the plane model of a probe
//! along the normal, and a weighed entry point.

use crate::geometry::{Frame, Ray, Vec3};

/// A sampled probe (pbrt-v4 `BSSRDFProbeSegment`): the segment on which the
/// integrator asks the accel for every hit on the object, and what
/// [`ProbeSampler::weigh`](super::ProbeSampler::weigh) needs to weigh the hit it picks.
#[derive(Clone, Copy, Debug)]
pub struct ProbeSegment {
    /// Starts where the probe line enters the sphere of radius Rmax around
    /// xo and runs along −V (unit direction).
    pub ray: Ray,
    /// The chord's length 2h, h = √(Rmax² − r²): the query's t range is
    /// [0, `t_max`].
    pub t_max: f32,
    /// The exit point xo and its shading frame.
    pub(super) xo: Vec3,
    pub(super) frame: Frame,
    /// The axis probabilities P(a) at xo (T, B, N).
    pub(super) probs: [f64; 3],
    /// The channel the radius was sampled for.
    pub(super) channel: usize,
}

/// A probe along the normal N at xo as the tangent plane there would weigh
/// it ([`ProbeSampler::sample_probe_and_plane`](super::ProbeSampler::sample_probe_and_plane)): the model of the plane
/// control variate (`integrator::control_variate`). On that plane T and B
/// probes never land, so a hit at xo + d has the density P(N)·p_disk(r),
/// r = |d|, and
///
///   E[1[V = N] · weight · h(d)] = ∫_disk Rd(|d|) h(d) dA
///
/// for any h: with h = 1, the plane integral A_plane
/// ([`ProbeSampler::planar_reflectance`](super::ProbeSampler::planar_reflectance)); with h odd in d, 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneModel {
    /// Rd(r) / (P(N)·p_disk(r)) per channel (the channel strategy's, as in
    /// [`ProbeSampler::weigh`](super::ProbeSampler::weigh)).
    pub weight: Vec3,
    /// d = r (cos φ T + sin φ B), the disk point's offset from xo (world).
    pub offset: Vec3,
    /// P(N), the probability of the normal axis at xo.
    pub p_normal: f32,
}

/// An entry point weighed by [`ProbeSampler::weigh`](super::ProbeSampler::weigh).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeEntry {
    /// xi, reconstructed along the probe ray (see [`ProbeSampler::weigh`](super::ProbeSampler::weigh)).
    pub point: Vec3,
    /// Rd(|xo − xi|) / p(xi) × (hits on the segment), per channel; the
    /// integrator multiplies by the directional factors and incident light.
    pub weight: Vec3,
}
