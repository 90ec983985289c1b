//! The probe-ray estimator of the BSSRDF's spatial integral (King et al.
//! 2013, "BSSRDF Importance Sampling"; pbrt-v3 §15.4.2
//! `SeparableBSSRDF::Sample_Sp` / `Pdf_Sp`; `docs/bssrdf.md` §5).
//!
//! At an exit point xo: pick a projection axis V and a channel, sample a
//! radius and an angle on the disk ⟂ V, and build the probe segment through
//! the sphere of radius Rmax around xo; the integrator runs the query, and
//! this module weighs the hits it finds, keeping one in proportion to its
//! weight ([`pick_by_score`]). The axis rules ([`ProbeAxes`]: normal-only,
//! mis3, curvature with ε from [`tangent_probability`]), the channel
//! strategies ([`ChannelStrategy`]), renormalization, and the weight bound
//! of each: `docs/bssrdf.md` §12.1. Channels with A = 0 or d = 0 are never
//! chosen, never divided by, and always get weight 0.

use glam::DVec3;

use super::density::ProbeDensity;
use super::params::SubsurfaceParams;
use super::profile;
use super::radius::{RadialDist, RadiusSampler};
use crate::error::{Constraint, Param, ParamError};
use crate::geometry::{Frame, Ray, Vec3};
use crate::sampling::Draw;

/// Which axes probes are shot along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ProbeAxes {
    /// Along the shading normal only: normal-only axes (King et al. 2013),
    /// a research variant.
    Normal,
    /// N, T, B with probabilities ½, ¼, ¼ and the balance heuristic.
    Mis3,
    /// N, T, B with probabilities 1 − 2ε, ε, ε and the balance heuristic,
    /// ε = [`tangent_probability`] of the curvature at xo times the widest
    /// channel's d: ε_min where the profile sees a flat surface, ¼ (mis3)
    /// where it wraps around the surface.
    #[default]
    Curvature,
}

impl ProbeAxes {
    pub const ALL: [ProbeAxes; 3] = [ProbeAxes::Normal, ProbeAxes::Mis3, ProbeAxes::Curvature];

    /// The name the scene format and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            ProbeAxes::Normal => "normal",
            ProbeAxes::Mis3 => "mis3",
            ProbeAxes::Curvature => "curvature",
        }
    }

    /// G in the bound G · n_active · A / CDF(Rmax)^(renormalize) on the
    /// weight of one hit (before the hit count; module docs): 4√3 for
    /// mis3, √3/ε_min for curvature; None for normal-only, whose weights
    /// grow without bound at grazing hits.
    pub fn weight_bound(self) -> Option<f64> {
        match self {
            ProbeAxes::Normal => None,
            ProbeAxes::Mis3 => Some(3f64.sqrt() / 0.25),
            ProbeAxes::Curvature => Some(3f64.sqrt() / TANGENT_PROB_MIN),
        }
    }

    /// The variant named `s` (case-insensitive).
    pub fn parse(s: &str) -> Option<ProbeAxes> {
        ProbeAxes::ALL
            .into_iter()
            .find(|a| a.name().eq_ignore_ascii_case(s))
    }
}

/// The smallest probability of each tangent axis under
/// [`ProbeAxes::Curvature`]: it keeps every surface within Rmax reachable
/// (so the estimator stays unbiased on any geometry) and bounds the weight
/// of a hit by (√3/ε_min)·n_active·A (module docs). 0.005 to suit the plane
/// control variate (`integrator::control_variate`), which models only
/// probes along N, so a smaller ε leaves it more of the probes; the bound
/// grows as 1/ε_min (docs/accuracy.md, "The plane control variate", for the
/// trade measured); the grazing scene keeps ε = ¼.
pub(crate) const TANGENT_PROB_MIN: f64 = 0.005;

/// κ·d at and beyond which [`ProbeAxes::Curvature`] uses mis3's ¼.
pub const TANGENT_PROB_FULL_AT: f64 = 1.0;

/// The probability ε of each of T and B under [`ProbeAxes::Curvature`] at
/// an exit point where the surface's curvature times the widest channel's d
/// is `kd` (≥ 0):
///
///   ε = ε_min + (¼ − ε_min) · exp(−(π/6)(1/kd − 1/kd_full)),  kd < kd_full,
///
/// and ¼ beyond kd_full = [`TANGENT_PROB_FULL_AT`]. exp(−π/(6 kd)) is the
/// slow lobe e^{−r/3d} of R at arc length r = π/(2κ), where a sphere of
/// curvature κ has turned 90° from xo and probes along N meet it edge-on:
/// the share of the profile that only T and B probes reach well. It is
/// negligible on a smooth body (e^{−5.5} at kd = 0.087, a 10 mm marble
/// sphere) and reaches ¼ where the profile wraps around the surface
/// (scenes/grazing.toml: kd ≈ 1.2). A NaN kd gives ¼, the robust end.
pub fn tangent_probability(kd: f64) -> f64 {
    let (min, full) = (TANGENT_PROB_MIN, TANGENT_PROB_FULL_AT);
    if kd.is_nan() || kd >= full {
        return 0.25;
    }
    if kd <= 0.0 {
        return min;
    }
    let s = (-(std::f64::consts::PI / 6.0) * (1.0 / kd - 1.0 / full)).exp();
    min + (0.25 - min) * s
}

/// How the color channels share one probe sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ChannelStrategy {
    /// Estimate only the channel the radius was sampled for: one channel
    /// per sample (King et al. 2013), a research variant.
    Single,
    /// Estimate all channels with the balance heuristic over channels.
    #[default]
    Mis,
}

impl ChannelStrategy {
    /// The name the scene format and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            ChannelStrategy::Single => "single",
            ChannelStrategy::Mis => "mis",
        }
    }
}

/// Options of the probe estimator; `Default` is the recommended setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeOptions {
    pub axes: ProbeAxes,
    pub channel: ChannelStrategy,
    pub radius: RadiusSampler,
    /// Rmax is this quantile of the widest active channel's profile.
    pub rmax_quantile: f64,
    /// Divide Rd by CDF(Rmax) so truncation loses no energy.
    pub renormalize: bool,
}

impl Default for ProbeOptions {
    fn default() -> Self {
        ProbeOptions {
            axes: ProbeAxes::Curvature,
            channel: ChannelStrategy::Mis,
            radius: RadiusSampler::Analytic,
            rmax_quantile: 0.999,
            renormalize: false,
        }
    }
}

impl ProbeOptions {
    /// The configuration of the course report (README "The math") with a
    /// given radius sampler: normal axis, one channel per sample, no
    /// renormalization.
    pub fn seed_document(radius: RadiusSampler) -> Self {
        ProbeOptions {
            axes: ProbeAxes::Normal,
            channel: ChannelStrategy::Single,
            radius,
            rmax_quantile: 0.999,
            renormalize: false,
        }
    }

    pub fn validate(&self) -> Result<(), ParamError> {
        self.radius.validate()?;
        let q = self.rmax_quantile;
        if !(q > 0.0 && q < 1.0) {
            return Err(ParamError::new(
                Param::RmaxQuantile,
                q,
                Constraint::Open(0.0, 1.0),
            ));
        }
        Ok(())
    }
}

/// The random numbers one probe consumes, each uniform in [0, 1) (and a
/// seed for the probe-hit subset when a segment has more than
/// `MAX_PROBE_HITS` hits).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeRandoms {
    pub axis: f64,
    pub channel: f64,
    pub radius: f64,
    pub angle: f64,
    pub hit: f64,
    pub seed: u32,
}

impl ProbeRandoms {
    /// Four draws instead of six: only the radius needs 53 bits (its
    /// inverse CDF resolves the tails); the discrete choices and the angle
    /// share draws at 32 bits each.
    pub fn from_rng(rng: &mut impl Draw) -> Self {
        let radius = rng.uniform_f64();
        let [axis, channel] = rng.uniform2_f64_32();
        let [angle, hit] = rng.uniform2_f64_32();
        ProbeRandoms {
            axis,
            channel,
            radius,
            angle,
            hit,
            seed: rng.next_u32(),
        }
    }
}

/// A sampled probe (pbrt-v4 `BSSRDFProbeSegment`): the segment on which the
/// integrator asks the accel for every hit on the object, and what
/// [`ProbeSampler::weigh`] needs to weigh the hit it picks.
#[derive(Clone, Copy, Debug)]
pub struct ProbeSegment {
    /// Starts where the probe line enters the sphere of radius Rmax around
    /// xo and runs along −V (unit direction).
    pub ray: Ray,
    /// The chord's length 2h, h = √(Rmax² − r²): the query's t range is
    /// [0, `t_max`].
    pub t_max: f32,
    /// The exit point xo and its shading frame.
    xo: Vec3,
    frame: Frame,
    /// The axis probabilities P(a) at xo (T, B, N).
    probs: [f64; 3],
    /// The channel the radius was sampled for.
    channel: usize,
}

/// The part of a probe sample both probes of an antithetic pair share
/// ([`ProbeSampler::sample_probe_pair`]): channel, radius, the axis
/// probabilities and the axis V with the plane (T', B') ⟂ V.
#[derive(Clone, Copy)]
struct Shared {
    channel: usize,
    /// The sampled axis (T, B, N: 0, 1, 2).
    axis: usize,
    r: f64,
    h: f64,
    probs: [f64; 3],
    axes: [DVec3; 3],
}

/// A probe along the normal N at xo as the tangent plane there would weigh
/// it ([`ProbeSampler::sample_probe_and_plane`]): the model of the plane
/// control variate (`integrator::control_variate`). On that plane T and B
/// probes never land, so a hit at xo + d has the density P(N)·p_disk(r),
/// r = |d|, and
///
///   E[1[V = N] · weight · h(d)] = ∫_disk Rd(|d|) h(d) dA
///
/// for any h: with h = 1, the plane integral A_plane
/// ([`ProbeSampler::planar_reflectance`]); with h odd in d, 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneModel {
    /// Rd(r) / (P(N)·p_disk(r)) per channel (the channel strategy's, as in
    /// [`ProbeSampler::weigh`]).
    pub weight: Vec3,
    /// d = r (cos φ T + sin φ B), the disk point's offset from xo (world).
    pub offset: Vec3,
    /// P(N), the probability of the normal axis at xo.
    pub p_normal: f32,
}

/// An entry point weighed by [`ProbeSampler::weigh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeEntry {
    /// xi, reconstructed along the probe ray (see [`ProbeSampler::weigh`]).
    pub point: Vec3,
    /// Rd(|xo − xi|) / p(xi) × (hits on the segment), per channel; the
    /// integrator multiplies by the directional factors and incident light.
    pub weight: Vec3,
}

/// The index of the hit one probe keeps among several, in proportion to
/// `scores` (each kept hit's Rd/p summed over channels, from
/// [`ProbeSampler::weigh`] with a count of 1), from the probe's `hit`
/// random number, and the factor that makes the pick unbiased:
///
/// ```text
/// P(k) = s_k / Σ_j s_j,   weight = Rd/p(x_k) × (total / kept) × Σ_j s_j / s_k,
/// ```
///
/// so E[weight·L] = (total/kept) Σ_{kept} Rd/p·L, the uniform pick's mean
/// (the kept hits are a uniform subset of the `total`). A segment that
/// crosses the body twice — a thin tile's top and bottom, both walls of a
/// sphere's far side — keeps the near, heavy hit nearly always instead of
/// half the time (docs/accuracy.md, "Sharp edges and thin bodies"). Hits of score 0 are
/// never picked; None when every score is 0 (nothing to scatter from).
pub fn pick_by_score(u: &ProbeRandoms, scores: &[f32], total: usize) -> Option<(usize, f32)> {
    let sum: f32 = scores.iter().sum();
    if !sum.is_finite() {
        return None;
    }
    let goal = u.hit as f32 * sum;
    let mut acc = 0.0;
    // the last hit with a score > 0 absorbs rounding in the running sum;
    // none (every score 0): nothing to pick
    let mut pick = scores.iter().rposition(|&s| s > 0.0)?;
    // goal ≥ 0, so a hit of score 0 never ends the scan: the running sum
    // it leaves unchanged was not above goal before it either
    for (k, &s) in scores.iter().enumerate() {
        acc += s;
        if goal < acc {
            pick = k;
            break;
        }
    }
    let factor = (total as f32 / scores.len() as f32) * (sum / scores[pick]);
    Some((pick, factor))
}

/// ⌊u·n⌋ for u ∈ [0, 1], n ≥ 1, clamped to n − 1. For u < 1 the product
/// never rounds up to n (below 2⁵³, n·(1 − 2⁻⁵³) is at least half an ulp
/// under n, or exact below a power of two); the clamp keeps the closed
/// end u = 1 in range.
#[inline]
fn uniform_index(u: f64, n: usize) -> usize {
    ((u * n as f64) as usize).min(n - 1)
}

/// Axis order in arrays below: T, B, N.
const AXIS_N: usize = 2;

/// The probe sampler of one material: parameters, options and the per
/// channel radius distributions, built once (the table, if any, is shared).
#[derive(Clone, Debug)]
pub struct ProbeSampler {
    opts: ProbeOptions,
    /// A per channel, divided by CDF(Rmax) when renormalizing.
    scale: [f64; 3],
    d: [f64; 3],
    dists: [Option<RadialDist>; 3],
    active: [usize; 3],
    n_active: usize,
    rmax: f64,
    /// The widest active channel's d: the length curvature is measured in.
    d_max: f64,
    /// p(xi) and Rd at an entry point.
    density: ProbeDensity,
    /// [`planar_reflectance`](Self::planar_reflectance), computed once
    /// (the control variate reads it at every camera hit).
    planar: [f64; 3],
}

impl ProbeSampler {
    /// Prepares the sampler. A material with no active channel is valid: it
    /// samples nothing ([`sample_probe`](Self::sample_probe) returns None).
    pub fn new(params: &SubsurfaceParams, opts: &ProbeOptions) -> Result<Self, ParamError> {
        params.validate()?;
        opts.validate()?;
        let rmax = profile::quantile(opts.rmax_quantile) * params.max_active_d();
        let mut active = [0; 3];
        let mut n_active = 0;
        let mut dists: [Option<RadialDist>; 3] = [None, None, None];
        let mut scale = [0.0; 3];
        for c in 0..3 {
            if !params.active(c) {
                continue;
            }
            let dist = RadialDist::new(opts.radius, params.d[c], rmax)?;
            scale[c] = params.albedo[c]
                / if opts.renormalize {
                    dist.profile_mass()
                } else {
                    1.0
                };
            dists[c] = Some(dist);
            active[n_active] = c;
            n_active += 1;
        }
        let density = ProbeDensity::new(opts.radius, params.d, scale, &dists, rmax);
        let planar = std::array::from_fn(|c| match &dists[c] {
            Some(dist) => scale[c] * dist.profile_mass(),
            None => 0.0,
        });
        Ok(ProbeSampler {
            opts: *opts,
            scale,
            d: params.d,
            dists,
            active,
            n_active,
            rmax,
            d_max: params.max_active_d(),
            density,
            planar,
        })
    }

    pub fn options(&self) -> &ProbeOptions {
        &self.opts
    }

    /// The probe sphere's radius (scene units); 0 without active channels.
    pub fn rmax(&self) -> f64 {
        self.rmax
    }

    /// What the estimator converges to on an infinite flat surface, per
    /// channel: A·CDF(Rmax), or A when renormalizing.
    #[inline]
    pub fn planar_reflectance(&self) -> [f64; 3] {
        self.planar
    }

    /// Rd(r) per channel as the estimator uses it (A·R, or A·R/CDF(Rmax)).
    #[inline]
    pub fn rd(&self, r: f64) -> [f64; 3] {
        std::array::from_fn(|c| match self.dists[c] {
            Some(_) => self.scale[c] * profile::profile(r, self.d[c]),
            None => 0.0,
        })
    }

    /// Axis probabilities (T, B, N) at an exit point where the surface's
    /// curvature is `curvature` (1/scene units, ≥ 0; only
    /// [`ProbeAxes::Curvature`] reads it).
    #[inline]
    pub fn axis_probs(&self, curvature: f32) -> [f64; 3] {
        match self.opts.axes {
            ProbeAxes::Normal => [0.0, 0.0, 1.0],
            ProbeAxes::Mis3 => [0.25, 0.25, 0.5],
            ProbeAxes::Curvature => {
                let e = tangent_probability(curvature as f64 * self.d_max);
                [e, e, 1.0 - 2.0 * e]
            }
        }
    }

    /// Samples a probe for exit point `xo` with shading frame `frame`, where
    /// the surface's curvature is `curvature` (1/scene units; see
    /// [`axis_probs`](Self::axis_probs)) (pbrt-v4 `SampleSp`): a channel c, a
    /// radius r from its disk density, an axis V and an angle φ; the probe
    /// runs along −V through xo + r(cos φ T' + sin φ B') (T', B' span the
    /// plane ⟂ V) across the sphere of radius Rmax. None when no channel is
    /// active.
    pub fn sample_probe(
        &self,
        xo: Vec3,
        frame: &Frame,
        curvature: f32,
        u: &ProbeRandoms,
    ) -> Option<ProbeSegment> {
        let shared = self.sample_shared(frame, curvature, u)?;
        Some(self.segment(xo, frame, &shared, u.angle))
    }

    /// The two probes of an antithetic pair from one set of randoms `u`:
    /// [`sample_probe`](Self::sample_probe) at φ and at φ + π (angle
    /// `(u.angle + ½).fract()` in turns), each bit for bit what
    /// `sample_probe` gives for its angle. The channel, radius and axis —
    /// the radius inverse CDF and the axis probabilities, most of a
    /// probe's sampling work — are computed once for both (`crate::kernels`).
    pub(crate) fn sample_probe_pair(
        &self,
        xo: Vec3,
        frame: &Frame,
        curvature: f32,
        u: &ProbeRandoms,
    ) -> Option<[ProbeSegment; 2]> {
        let shared = self.sample_shared(frame, curvature, u)?;
        Some([
            self.segment(xo, frame, &shared, u.angle),
            self.segment(xo, frame, &shared, (u.angle + 0.5).fract()),
        ])
    }

    /// [`sample_probe`](Self::sample_probe), bit for bit, and for a probe
    /// along the normal its [`PlaneModel`]: what it would weigh were the
    /// surface the tangent plane at xo (None for probes along T or B).
    pub fn sample_probe_and_plane(
        &self,
        xo: Vec3,
        frame: &Frame,
        curvature: f32,
        u: &ProbeRandoms,
    ) -> Option<(ProbeSegment, Option<PlaneModel>)> {
        let shared = self.sample_shared(frame, curvature, u)?;
        Some((
            self.segment(xo, frame, &shared, u.angle),
            self.plane_model(frame, &shared, u.angle),
        ))
    }

    /// [`sample_probe_pair`](Self::sample_probe_pair), bit for bit, and
    /// the first probe's [`PlaneModel`] (the twin's is the same with the
    /// offset negated).
    pub(crate) fn sample_probe_pair_and_plane(
        &self,
        xo: Vec3,
        frame: &Frame,
        curvature: f32,
        u: &ProbeRandoms,
    ) -> Option<([ProbeSegment; 2], Option<PlaneModel>)> {
        let shared = self.sample_shared(frame, curvature, u)?;
        Some((
            [
                self.segment(xo, frame, &shared, u.angle),
                self.segment(xo, frame, &shared, (u.angle + 0.5).fract()),
            ],
            self.plane_model(frame, &shared, u.angle),
        ))
    }

    /// The plane model of the probe of `shared` at `angle` (turns) when its
    /// axis is the normal: the disk point's offset d = r (cos φ T + sin φ B)
    /// and the weight [`weigh`](Self::weigh) gives a hit there on the plane
    /// through xo ⟂ N, where probes along T and B run parallel to the
    /// surface and only N's density counts.
    #[inline(always)]
    fn plane_model(&self, frame: &Frame, shared: &Shared, angle: f64) -> Option<PlaneModel> {
        if shared.axis != AXIS_N {
            return None;
        }
        let (sin, cos) = crate::sampling::sin_cos_turns(angle as f32);
        let [_, t1, t2] = shared.axes;
        let d = (t1 * cos as f64 + t2 * sin as f64) * shared.r;
        let w = self.weights(d, frame, frame.n.as_dvec3(), shared.probs, shared.channel)?;
        Some(PlaneModel {
            weight: Vec3::from_array(w),
            offset: d.as_vec3(),
            p_normal: shared.probs[AXIS_N] as f32,
        })
    }

    /// What a probe samples before its angle: the channel c, the radius r
    /// and the axis V (with the plane T', B' ⟂ V).
    #[inline(always)]
    fn sample_shared(&self, frame: &Frame, curvature: f32, u: &ProbeRandoms) -> Option<Shared> {
        if self.n_active == 0 {
            return None;
        }
        // docs/bssrdf.md §5 step 1: a channel c, a radius r ~ p_c, an axis
        // V with probability p_axis(V), an angle φ.
        let channel = self.active[uniform_index(u.channel, self.n_active)];
        let dist = self.dists[channel].as_ref()?;
        let r = dist.sample_radius(u.radius);
        let (t, b, n) = (frame.t.as_dvec3(), frame.b.as_dvec3(), frame.n.as_dvec3());
        // N below P(N), then T, then B (for mis3: ½, ¼, ¼).
        let probs = self.axis_probs(curvature);
        let axis = if u.axis < probs[AXIS_N] {
            AXIS_N
        } else if u.axis < probs[AXIS_N] + probs[0] {
            0
        } else {
            1
        };
        let (v, t1, t2) = match axis {
            0 => (t, b, n),
            1 => (b, n, t),
            _ => (n, t, b),
        };
        // The chord's half length h = √(Rmax² − r²).
        let h = (self.rmax * self.rmax - r * r).max(0.0).sqrt();
        Some(Shared {
            channel,
            axis,
            r,
            h,
            probs,
            axes: [v, t1, t2],
        })
    }

    /// The probe of `shared` at angle `angle` (turns).
    #[inline(always)]
    fn segment(&self, xo: Vec3, frame: &Frame, shared: &Shared, angle: f64) -> ProbeSegment {
        let Shared {
            channel,
            r,
            h,
            probs,
            axes: [v, t1, t2],
            ..
        } = *shared;
        // The angle in f32: its rounding moves p0 by ~1e-7·r, below the f32
        // rounding of p0 itself.
        let (sin, cos) = crate::sampling::sin_cos_turns(angle as f32);
        // Step 2: p0 = xo + r (cos φ T' + sin φ B') + h V, segment p0 → p0 − 2h V.
        let p0 = xo.as_dvec3() + (t1 * cos as f64 + t2 * sin as f64) * r + v * h;
        ProbeSegment {
            ray: Ray::new(p0.as_vec3(), (-v).as_vec3()),
            t_max: (2.0 * h) as f32,
            xo,
            frame: *frame,
            probs,
            channel,
        }
    }

    /// Weighs the hit at distance `t` along `seg` on a triangle with unit
    /// normal `n_hit`, as if picked uniformly among `total` hits on the
    /// segment (pbrt-v4 `ProbeIntersectionToSample`; `docs/bssrdf.md` §5
    /// step 4, where `total` is k). The integrator calls it with the count
    /// for a segment's only hit, and with `total` = 1 for each of several,
    /// whose pick [`pick_by_score`] then scales:
    ///
    ///   weight = Rd(|xo − xi|) / p(xi) × total,
    ///
    /// p the balance-heuristic density of the module docs. None for a
    /// degenerate triangle (`n_hit` = 0) or where p is 0 (a surface
    /// parallel to every probe axis used); the estimate is then 0, which is
    /// correct (nothing there to scatter from).
    pub fn weigh(
        &self,
        seg: &ProbeSegment,
        t: f32,
        n_hit: Vec3,
        total: usize,
    ) -> Option<ProbeEntry> {
        if n_hit == Vec3::ZERO {
            return None;
        }
        // xi from the ray, not the barycentrics: its error is ~ε·Rmax, while
        // barycentrics on a large triangle err by ~ε·(triangle size), which
        // matters when d is small against the triangles (big flat quads).
        let xi = seg.ray.o.as_dvec3() + seg.ray.d.as_dvec3() * t as f64;
        let d = xi - seg.xo.as_dvec3();
        // Rd(|xo − xi|) / p(xi) per channel
        let w = self.weights(d, &seg.frame, n_hit.as_dvec3(), seg.probs, seg.channel)?;
        // × total: the hit was picked with probability 1/total
        Some(ProbeEntry {
            point: xi.as_vec3(),
            weight: Vec3::from_array(w) * total as f32,
        })
    }

    /// The sampled channel when each sample estimates only one.
    fn single(&self, ch: usize) -> Option<usize> {
        match self.opts.channel {
            ChannelStrategy::Single => Some(ch),
            ChannelStrategy::Mis => None,
        }
    }

    /// Rd(|d|)/p(xi) per channel (before the hit count) for an entry point
    /// at xi = xo + d with unit normal `n_hit`, `ch` the sampled channel:
    /// the frame's local coordinates of d, the cosines |V_a·N| and the axis
    /// probabilities P(a) at xo, handed to [`ProbeDensity::weights`].
    #[inline]
    fn weights(
        &self,
        d: DVec3,
        frame: &Frame,
        n_hit: DVec3,
        probs: [f64; 3],
        ch: usize,
    ) -> Option<[f32; 3]> {
        let axes = [frame.t, frame.b, frame.n].map(|v| v.as_dvec3());
        let local = axes.map(|v| d.dot(v));
        let cos = axes.map(|v| v.dot(n_hit).abs() as f32);
        let probs = probs.map(|p| p as f32);
        self.density
            .weights(local, cos, probs, self.single(ch), self.n_active)
    }
}

/// The f64 transcription of the density and weights, term by term from the
/// module docs with libm's `exp`: the oracle of [`ProbeDensity`]'s f32
/// lanes.
#[cfg(test)]
impl ProbeSampler {
    /// Per channel, the surface-area density with which a probe sampled for
    /// that channel lands on xi (normal `n_hit`), summed over axes with
    /// their probabilities (pbrt-v3 `Pdf_Sp` without the channel sum).
    /// Inactive channels give 0.
    fn pdf_area_d(&self, d: DVec3, frame: &Frame, kappa: f32, n_hit: DVec3) -> [f64; 3] {
        let per_axis = self.pdf_area_axes(d, frame, kappa, n_hit);
        std::array::from_fn(|c| per_axis.iter().map(|p| p[c]).sum())
    }

    /// [`pdf_area_d`](Self::pdf_area_d)'s terms, axis by axis (T, B, N):
    /// P(a) p_c(r_a) |V_a·N| per channel c.
    fn pdf_area_axes(&self, d: DVec3, frame: &Frame, kappa: f32, n_hit: DVec3) -> [[f64; 3]; 3] {
        let axes = [frame.t.as_dvec3(), frame.b.as_dvec3(), frame.n.as_dvec3()];
        let probs = self.axis_probs(kappa);
        // Disk radii from the squares of the other two local coordinates:
        // |d|² − (d·V)² would cancel when r ≪ |d|.
        let sq = axes.map(|v| d.dot(v).powi(2));
        let mut pdf = [[0.0; 3]; 3];
        for a in 0..3 {
            if probs[a] == 0.0 {
                continue;
            }
            // Rounding can put a hit just outside the sphere; keep its
            // projection on the disk so the sampled axis never scores 0.
            let r_a = (sq[(a + 1) % 3] + sq[(a + 2) % 3]).sqrt().min(self.rmax);
            let cos = axes[a].dot(n_hit).abs();
            if cos == 0.0 {
                continue;
            }
            for &c in &self.active[..self.n_active] {
                if let Some(dist) = &self.dists[c] {
                    pdf[a][c] += probs[a] * dist.pdf(r_a) * cos;
                }
            }
        }
        pdf
    }

    /// The surface-area density with which one probe (channel, axis, radius
    /// and angle all sampled) reaches an entry point xi = xo + d with unit
    /// normal `n_hit`, before the pick among the segment's hits: the
    /// channel is uniform among the active ones, so Σ_c pdf_c / n_active.
    /// 0 beyond Rmax, where no chord of the probe sphere reaches. Where
    /// every probe segment has one hit it is the density of the sampled xi;
    /// the integrator's tests compare the two.
    pub(crate) fn pdf_area(&self, d: DVec3, frame: &Frame, kappa: f32, n_hit: DVec3) -> f64 {
        if self.n_active == 0 || d.length() > self.rmax {
            return 0.0;
        }
        self.pdf_area_d(d, frame, kappa, n_hit).iter().sum::<f64>() / self.n_active as f64
    }

    /// [`pdf_area`](Self::pdf_area) axis by axis (T, B, N): the density of
    /// reaching xi with a probe along that axis. Where the segment through
    /// xi along axis a has k_a hits, xi is chosen with density
    /// Σ_a pdf_area_axes_mean[a] / k_a.
    pub(crate) fn pdf_area_axes_mean(
        &self,
        d: DVec3,
        frame: &Frame,
        kappa: f32,
        n_hit: DVec3,
    ) -> [f64; 3] {
        if self.n_active == 0 || d.length() > self.rmax {
            return [0.0; 3];
        }
        self.pdf_area_axes(d, frame, kappa, n_hit)
            .map(|p| p.iter().sum::<f64>() / self.n_active as f64)
    }

    /// Rd(|d|)/p(xi) per channel (before the hit count) for an entry point
    /// at xi = xo + d with unit normal `n_hit`, `ch` the sampled channel:
    /// the f64 oracle.
    fn weights_f64(
        &self,
        d: DVec3,
        frame: &Frame,
        kappa: f32,
        n_hit: DVec3,
        ch: usize,
    ) -> Option<[f32; 3]> {
        let pdf = self.pdf_area_d(d, frame, kappa, n_hit);
        let dist3 = d.length();
        let p = match self.single(ch) {
            Some(ch) => pdf[ch],
            None => pdf.iter().sum::<f64>(),
        } / self.n_active as f64;
        if !(p > 0.0 && p.is_finite()) {
            return None;
        }
        let w = |c: usize| (self.scale[c] * profile::profile(dist3, self.d[c]) / p) as f32;
        Some(match self.single(ch) {
            Some(ch) => std::array::from_fn(|c| if c == ch { w(c) } else { 0.0 }),
            None => std::array::from_fn(w),
        })
    }
}

#[cfg(test)]
// Tests index parallel per-channel arrays by channel number.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn weights_match_the_f64_oracle() {
        // ProbeDensity's f32 lanes against the f64 transcription on entry
        // points spread over the probe sphere, many nearly on an axis (disk
        // radius down to 1e-12 Rmax, below the RHO_MIN clamp), for every
        // radius sampler and materials whose channels span r/d up to 240
        // within Rmax, in scene units from 1e-6 to 1e6, and one (`far`) up
        // to 397, past exp4's range (module docs of `density`).
        use crate::sampling::uniform_sphere;
        let marble = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight);
        let skin = SubsurfaceParams::from_preset("skin1", 1.0, profile::Fit::Searchlight);
        let wide = SubsurfaceParams {
            albedo: [0.9, 0.0, 0.3],
            d: [1.0, 0.7, 0.0835],
            eta: 1.3,
            medium: None,
        };
        let mut far = wide;
        far.d[2] = 0.05;
        let mut materials = vec![marble.unwrap(), skin.unwrap(), wide, far];
        materials.push(materials[0].scaled(1e-6));
        materials.push(materials[1].scaled(1e6));
        // beyond this r/d, exp4's lane may be 0 (e^{−ρ/3} < e^{−87})
        let rho_lanes = 255.0;
        let mut rng = Rng::from_key(99);
        let mut kappa_rng = Rng::from_key(100);
        let mut curv_rng = Rng::from_key(101);
        let mut worst = 0.0f64;
        for params in &materials {
            for axes in ProbeAxes::ALL {
                for channel in [ChannelStrategy::Single, ChannelStrategy::Mis] {
                    for radius in [
                        RadiusSampler::Uniform,
                        RadiusSampler::table(64),
                        RadiusSampler::Analytic,
                        RadiusSampler::Mixture,
                    ] {
                        for renormalize in [false, true] {
                            let opts = ProbeOptions {
                                axes,
                                channel,
                                radius,
                                rmax_quantile: 0.999,
                                renormalize,
                            };
                            let s = ProbeSampler::new(params, &opts).unwrap();
                            // the curvature rule draws its own cases, so the
                            // others see the points they always did
                            let rng = if axes == ProbeAxes::Curvature {
                                &mut curv_rng
                            } else {
                                &mut rng
                            };
                            for _ in 0..2_000 {
                                let frame = Frame::from_normal(uniform_sphere(rng.uniform2()));
                                let mut local = [0.0f64; 3];
                                let a = (rng.uniform() * 3.0) as usize % 3;
                                let rm = s.rmax();
                                let perp = rm * 10f64.powf(-12.0 * rng.uniform_f64());
                                let phi = std::f64::consts::TAU * rng.uniform_f64();
                                local[(a + 1) % 3] = perp * phi.cos();
                                local[(a + 2) % 3] = perp * phi.sin();
                                // along the axis, inside the sphere
                                local[a] = (rm * rm - perp * perp).max(0.0).sqrt()
                                    * (2.0 * rng.uniform_f64() - 1.0);
                                let local = if rng.uniform() < 0.5 {
                                    local
                                } else {
                                    // anywhere in the sphere
                                    let u = uniform_sphere(rng.uniform2()).as_dvec3();
                                    (u * rng.uniform_f64().cbrt() * rm).to_array()
                                };
                                let (t, b, n) =
                                    (frame.t.as_dvec3(), frame.b.as_dvec3(), frame.n.as_dvec3());
                                let d = t * local[0] + b * local[1] + n * local[2];
                                let n_hit = uniform_sphere(rng.uniform2()).as_dvec3().normalize();
                                let ch = s.active
                                    [(rng.uniform() * s.n_active as f32) as usize % s.n_active];
                                // curvature from flat to ~100/Rmax: ε over
                                // its whole range under `Curvature`
                                // (its own stream: the cases above are the
                                // ones this test always drew)
                                let kappa = (100.0 * kappa_rng.uniform_f64().powi(2) / rm) as f32;
                                let probs = s.axis_probs(kappa);
                                let f = s.weights(d, &frame, n_hit, probs, ch);
                                let r = s.weights_f64(d, &frame, kappa, n_hit, ch);
                                // a single channel's density beyond ρ ≈ 240
                                // underflows f32 (probability of such a
                                // sample < 1e-34)
                                let single_out = channel == ChannelStrategy::Single
                                    && d.length() / params.d[ch] > 240.0;
                                if let Some(f) = f {
                                    assert!(
                                        f.iter().all(|w| w.is_finite() && *w >= 0.0),
                                        "{params:?} {opts:?} {f:?} {r:?} {d} {ch}"
                                    );
                                }
                                let (Some(f), Some(r)) = (f, r) else {
                                    assert!(
                                        f.is_some() == r.is_some() || (f.is_none() && single_out),
                                        "{opts:?} {d} {n_hit}"
                                    );
                                    continue;
                                };
                                for c in 0..3 {
                                    if single_out || d.length() / params.d[c] > rho_lanes {
                                        continue;
                                    }
                                    // relative, but not among subnormal weights
                                    let e = ((f[c] - r[c]) as f64).abs() / (r[c] as f64).max(1e-35);
                                    // exp(−ρ/3) inherits the f32 rounding of its
                                    // argument times ρ/3 (a few ulp, 6e-8 each),
                                    // in Rd and in the density: the bound grows
                                    // with r/d.
                                    let rho = d.length() / params.d[c];
                                    let tol = 1e-6 + 3.6e-7 * rho / 3.0;
                                    assert!(
                                        e < tol,
                                        "{params:?} {opts:?} ch{c}: {} vs {} at {local:?}",
                                        f[c],
                                        r[c]
                                    );
                                    worst = worst.max(e / tol);
                                }
                            }
                        }
                    }
                }
            }
        }
        println!("f32 weights: worst relative error {worst:.3} of the bound");
    }

    #[test]
    fn hits_are_kept_in_proportion_to_their_score_and_scaled_back() {
        let u = |hit: f64| ProbeRandoms {
            axis: 0.0,
            channel: 0.0,
            radius: 0.5,
            angle: 0.0,
            hit,
            seed: 0,
        };
        // scores 1, 0, 3: the zero is never kept; P = ¼, ¾
        let scores = [1.0f32, 0.0, 3.0];
        let n = 10_000;
        let mut kept = [0usize; 3];
        let mut mean = 0.0f64;
        for i in 0..n {
            let (k, f) = pick_by_score(&u((i as f64 + 0.5) / n as f64), &scores, 3).unwrap();
            kept[k] += 1;
            // E[score × factor] = Σ scores × total/kept = 4 (all kept here)
            mean += (scores[k] * f) as f64 / n as f64;
            assert!(f > 0.0 && f.is_finite());
        }
        assert_eq!(kept, [2_500, 0, 7_500]);
        assert!((mean - 4.0).abs() < 1e-4, "{mean}");
        // the query kept 3 of 12 hits: × 12/3
        let (k, f) = pick_by_score(&u(0.1), &scores, 12).unwrap();
        assert_eq!((k, f), (0, 4.0 * 4.0));
        // u at the top of [0, 1) still picks a hit with a score
        assert_eq!(pick_by_score(&u(1.0 - 1e-12), &[2.0, 0.0], 2).unwrap().0, 0);
        // nothing to scatter from, or a broken score: no pick
        assert!(pick_by_score(&u(0.3), &[0.0, 0.0], 2).is_none());
        assert!(pick_by_score(&u(0.3), &[1.0, f32::NAN], 2).is_none());
        assert!(pick_by_score(&u(0.3), &[1.0, f32::INFINITY], 2).is_none());
    }

    #[test]
    fn uniform_indices_cover_every_slot_and_stay_in_range_at_both_ends() {
        let below_one = 1.0 - f64::EPSILON / 2.0;
        for n in [1usize, 2, 3, 5, 7, 1 << 20, (1 << 20) + 3] {
            assert_eq!(uniform_index(0.0, n), 0);
            assert_eq!(uniform_index(below_one, n), n - 1, "n = {n}");
            assert_eq!(uniform_index(1.0, n), n - 1, "n = {n}");
            for k in 0..n.min(64) {
                // the middle of slot k maps to k
                assert_eq!(uniform_index((k as f64 + 0.5) / n as f64, n), k);
            }
        }
    }

    #[test]
    fn tangent_probability_runs_from_eps_min_to_a_quarter() {
        // ε_min on a flat surface, ¼ (mis3) from κd = 1 on, continuous and
        // nondecreasing in between; what is not a curvature gives ¼.
        assert_eq!(tangent_probability(0.0), TANGENT_PROB_MIN);
        assert_eq!(tangent_probability(-1.0), TANGENT_PROB_MIN);
        assert_eq!(tangent_probability(TANGENT_PROB_FULL_AT), 0.25);
        assert_eq!(tangent_probability(f64::INFINITY), 0.25);
        assert_eq!(tangent_probability(f64::NAN), 0.25);
        let below = tangent_probability(TANGENT_PROB_FULL_AT * (1.0 - 1e-9));
        assert!((below - 0.25).abs() < 1e-8, "{below}");
        let mut last = 0.0;
        for i in 0..=1000 {
            let e = tangent_probability(i as f64 * 1e-3);
            assert!(
                (TANGENT_PROB_MIN..=0.25).contains(&e) && e >= last,
                "{i}: {e}"
            );
            last = e;
        }
        // the 10 mm marble sphere (κd ≈ 0.087): ε has risen by e^{−5.5} ≈
        // 0.4 % of its way from ε_min to ¼
        let share = (tangent_probability(0.087) - TANGENT_PROB_MIN) / (0.25 - TANGENT_PROB_MIN);
        assert!(share < 5e-3, "{share}");
        // the axis probabilities of a sampler sum to 1, N gets the rest
        let p = SubsurfaceParams {
            albedo: [0.5; 3],
            d: [2.0, 1.0, 0.5],
            eta: 1.3,
            medium: None,
        };
        let s = ProbeSampler::new(&p, &ProbeOptions::default()).unwrap();
        assert_eq!(s.options().axes, ProbeAxes::Curvature);
        for kappa in [0.0f32, 0.05, 0.2, 0.5, 10.0] {
            let pr = s.axis_probs(kappa);
            let e = tangent_probability(kappa as f64 * 2.0);
            assert_eq!(pr, [e, e, 1.0 - 2.0 * e], "κ {kappa}");
        }
        // the weight bound's factor: √3/ε_min, and mis3's 4√3
        let g = ProbeAxes::Curvature.weight_bound().unwrap();
        assert!((g - 3f64.sqrt() / TANGENT_PROB_MIN).abs() < 1e-12);
        assert!((ProbeAxes::Mis3.weight_bound().unwrap() - 4.0 * 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(ProbeAxes::Normal.weight_bound(), None);
        for a in ProbeAxes::ALL {
            assert_eq!(ProbeAxes::parse(&a.name().to_uppercase()), Some(a));
        }
        assert_eq!(ProbeAxes::parse("tangent"), None);
    }

    #[test]
    fn tangent_probability_follows_the_slow_lobe_at_a_quarter_turn() {
        // Between ε_min and ¼, ε rises as the profile's slow lobe e^{−r/3d}
        // at the arc length r = π/(2κ) where a sphere of curvature κ has
        // turned 90° from xo, normalized to 1 at κd = kd_full: computed
        // here from that geometry (d = 1, κ = kd), not from the formula.
        let slow_lobe_at_quarter_turn = |kd: f64| {
            let (d, kappa) = (1.0, kd);
            let r = std::f64::consts::FRAC_PI_2 / kappa;
            (-r / (3.0 * d)).exp()
        };
        let full = slow_lobe_at_quarter_turn(TANGENT_PROB_FULL_AT);
        for kd in [0.087, 0.2, 0.35, 0.5, 0.75, 0.9] {
            let e = tangent_probability(kd);
            let share = (e - TANGENT_PROB_MIN) / (0.25 - TANGENT_PROB_MIN);
            let want = slow_lobe_at_quarter_turn(kd) / full;
            assert!(
                (share - want).abs() <= 1e-12 + 1e-9 * want,
                "κd {kd}: share {share}, slow lobe {want}"
            );
        }
    }

    #[test]
    fn options_validate() {
        let p = SubsurfaceParams {
            albedo: [0.5; 3],
            d: [1.0; 3],
            eta: 1.3,
            medium: None,
        };
        for q in [0.0, 1.0, f64::NAN] {
            let e = ProbeSampler::new(
                &p,
                &ProbeOptions {
                    rmax_quantile: q,
                    ..ProbeOptions::default()
                },
            )
            .unwrap_err();
            assert_eq!(e.param, crate::error::Param::RmaxQuantile, "{e}");
        }
        let s = ProbeSampler::new(&p, &ProbeOptions::default()).unwrap();
        assert!((s.rmax() - profile::quantile(0.999)).abs() < 1e-12);
    }

    /// The pair's two segments are, bit for bit, what `sample_probe` gives
    /// at φ and at the twin's angle (φ + ½ turn): sharing the channel,
    /// radius and axis between them changes nothing (`crate::kernels`).
    #[test]
    fn probe_pair_is_two_probes_at_opposite_angles_bit_for_bit() {
        let params = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight);
        let params = params.unwrap();
        let mut rng = Rng::from_key(7);
        let frame = Frame::from_normal(Vec3::new(0.3, -0.5, 0.8).normalize());
        let xo = Vec3::new(0.25, -1.5, 3.0);
        let mut n = 0;
        for axes in ProbeAxes::ALL {
            let opts = ProbeOptions {
                axes,
                ..ProbeOptions::default()
            };
            let s = ProbeSampler::new(&params, &opts).unwrap();
            for i in 0..2000 {
                let u = ProbeRandoms::from_rng(&mut rng);
                let kappa = (i % 7) as f32 * 0.4;
                let twin = ProbeRandoms {
                    angle: (u.angle + 0.5).fract(),
                    ..u
                };
                let [a, b] = s.sample_probe_pair(xo, &frame, kappa, &u).unwrap();
                for (got, want) in [
                    (a, s.sample_probe(xo, &frame, kappa, &u)),
                    (b, s.sample_probe(xo, &frame, kappa, &twin)),
                ] {
                    let want = want.unwrap();
                    assert_eq!(
                        (got.ray.o, got.ray.d, got.t_max, got.probs, got.channel),
                        (want.ray.o, want.ray.d, want.t_max, want.probs, want.channel),
                        "{axes:?}, probe {i}"
                    );
                    assert_eq!((got.xo, got.frame.n), (want.xo, want.frame.n));
                    n += 1;
                }
                // the twin lies across xo: the two disk offsets are opposite
                let (oa, ob) = (a.ray.o - xo, b.ray.o - xo);
                let v = -a.ray.d;
                let (da, db) = (oa - v * oa.dot(v), ob - v * ob.dot(v));
                assert!(
                    (da + db).length() <= 1e-5 * (1.0 + da.length()),
                    "{da} {db}"
                );
            }
        }
        assert_eq!(n, 2 * 2000 * ProbeAxes::ALL.len());
    }

    #[test]
    fn the_plane_model_is_the_probe_on_the_tangent_plane() {
        // For a probe along N the model's offset d is where the probe line
        // crosses the tangent plane through xo, its weight what `weigh`
        // gives a single hit there on a surface of normal N, and P(N) the
        // axis probability; the pair's model is its first probe's. Probes
        // along T or B have none. The segments are `sample_probe`'s and
        // `sample_probe_pair`'s, bit for bit.
        let params = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight);
        let s = ProbeSampler::new(&params.unwrap(), &ProbeOptions::default()).unwrap();
        let mut rng = Rng::from_key(17);
        let frame = Frame::from_normal(Vec3::new(0.3, -0.5, 0.8).normalize());
        let xo = Vec3::new(0.25, -1.5, 3.0);
        let (mut along_n, mut tangent) = (0, 0);
        for i in 0..4000 {
            let u = ProbeRandoms::from_rng(&mut rng);
            // κ·d from 0 to ~1.3: ε from ε_min to ¼
            let kappa = (i % 9) as f32 * 0.2;
            let (seg, plane) = s.sample_probe_and_plane(xo, &frame, kappa, &u).unwrap();
            let want = s.sample_probe(xo, &frame, kappa, &u).unwrap();
            assert_eq!(
                (seg.ray.o, seg.ray.d, seg.t_max),
                (want.ray.o, want.ray.d, want.t_max)
            );
            let ([a, b], pair_plane) = s
                .sample_probe_pair_and_plane(xo, &frame, kappa, &u)
                .unwrap();
            let [wa, wb] = s.sample_probe_pair(xo, &frame, kappa, &u).unwrap();
            assert_eq!((a.ray.o, b.ray.o, a.ray.d), (wa.ray.o, wb.ray.o, wa.ray.d));
            assert_eq!(plane, pair_plane);
            let on_n = seg.ray.d.dot(frame.n) < -0.999;
            let Some(pm) = plane else {
                assert!(!on_n, "probe {i} along N without a model");
                tangent += 1;
                continue;
            };
            assert!(on_n, "probe {i}: a model for a probe along T or B");
            along_n += 1;
            let (o, d, n) = (seg.ray.o, seg.ray.d, frame.n);
            let t = (xo - o).dot(n) / d.dot(n);
            let p = o + d * t;
            let r = s.rmax() as f32;
            assert!(
                (p - (xo + pm.offset)).length() < 1e-5 * r,
                "probe {i}: crosses at {p}, model at {}",
                xo + pm.offset
            );
            assert!(pm.offset.dot(n).abs() < 1e-5 * r && pm.offset.length() <= r * 1.0001);
            let w = s.weigh(&seg, t, n, 1).unwrap().weight;
            assert!(
                (w - pm.weight).abs().max_element() <= 1e-3 * w.max_element(),
                "probe {i}: weigh {w} against the model's {}",
                pm.weight
            );
            assert_eq!(pm.p_normal, s.axis_probs(kappa)[AXIS_N] as f32);
        }
        assert!(
            along_n > 2500 && tangent > 300,
            "{along_n} along N, {tangent} along T/B"
        );
    }
}
