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

mod axes;
mod options;
#[cfg(test)]
mod oracle;
mod pick;
mod randoms;
mod segment;
#[cfg(test)]
mod tests;

pub use axes::{tangent_probability, ProbeAxes, TANGENT_PROB_FULL_AT, TANGENT_PROB_MIN};
pub use options::{ChannelStrategy, ProbeOptions, ProfileShape};
pub use pick::pick_by_score;
pub use randoms::ProbeRandoms;
pub use segment::{PlaneModel, ProbeEntry, ProbeSegment};

use std::sync::Arc;

use glam::DVec3;

use super::density::ProbeDensity;
use super::params::SubsurfaceParams;
use super::profile;
use super::profile_table::ProfileTable;
use super::radius::RadialDist;
use super::tabulated::TabulatedProfile;
use crate::error::ParamError;
use crate::geometry::{Frame, Ray, Vec3};

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

/// The tabulated profile of each channel when `opts` asks for it and
/// `params` records a medium; None otherwise (the fit is used). Err-free:
/// the embedded table is checked by its tests, so a failure to load it is
/// a build defect, reported by panicking with the file, line and field.
fn tabulated_profiles(
    params: &SubsurfaceParams,
    opts: &ProbeOptions,
) -> Option<[Option<TabulatedProfile>; 3]> {
    let medium = params.medium.as_ref()?;
    if opts.profile != ProfileShape::Tabulated {
        return None;
    }
    let table = ProfileTable::get().unwrap_or_else(|e| panic!("embedded profile table: {e}"));
    Some(std::array::from_fn(|c| {
        TabulatedProfile::for_channel(table, medium, c, params.eta as f64)
    }))
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
    dists: [Option<RadialDist>; 3],
    active: [usize; 3],
    n_active: usize,
    rmax: f64,
    /// The widest active channel's d (the fit's, for either profile): the
    /// length curvature is measured in.
    d_max: f64,
    /// p(xi) and Rd at an entry point.
    density: ProbeDensity,
    /// [`planar_reflectance`](Self::planar_reflectance), computed once
    /// (the control variate reads it at every camera hit).
    planar: [f64; 3],
    /// [`saturated_curvature`](Self::saturated_curvature), computed once.
    saturated: f32,
}

impl ProbeSampler {
    /// Prepares the sampler. A material with no active channel is valid: it
    /// samples nothing ([`sample_probe`](Self::sample_probe) returns None).
    pub fn new(params: &SubsurfaceParams, opts: &ProbeOptions) -> Result<Self, ParamError> {
        params.validate()?;
        opts.validate()?;
        let tables = tabulated_profiles(params, opts);
        // the widest active channel's quantile, of its own profile
        let fit_rmax = profile::quantile(opts.rmax_quantile) * params.max_active_d();
        let rmax = (0..3)
            .filter(|&c| params.active(c))
            .map(|c| match tables.as_ref().and_then(|t| t[c].as_ref()) {
                Some(p) => p.inverse_cdf(opts.rmax_quantile),
                None => profile::quantile(opts.rmax_quantile) * params.d[c],
            })
            .fold(0.0, f64::max);
        let rmax = if tables.is_some() { rmax } else { fit_rmax };
        let mut active = [0; 3];
        let mut n_active = 0;
        let mut dists: [Option<RadialDist>; 3] = [None, None, None];
        let mut scale = [0.0; 3];
        for c in 0..3 {
            if !params.active(c) {
                continue;
            }
            let dist = match tables.as_ref().and_then(|t| t[c].clone()) {
                Some(p) => RadialDist::tabulated(Arc::new(p), params.d[c], rmax)?,
                None => RadialDist::new(opts.radius, params.d[c], rmax)?,
            };
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
        let saturated = match opts.axes {
            ProbeAxes::Curvature => {
                (TANGENT_PROB_FULL_AT / params.max_active_d() * (1.0 + 2f64.powi(-20))) as f32
            }
            ProbeAxes::Normal | ProbeAxes::Mis3 => 0.0,
        };
        Ok(ProbeSampler {
            opts: *opts,
            scale,
            dists,
            active,
            n_active,
            rmax,
            d_max: params.max_active_d(),
            density,
            planar,
            saturated,
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
        std::array::from_fn(|c| match &self.dists[c] {
            Some(dist) => self.scale[c] * dist.profile_at(r),
            None => 0.0,
        })
    }

    /// Channel `c`'s radius distribution (None for an inactive channel):
    /// its profile's CDF is what the curvature correction integrates.
    pub fn dist(&self, c: usize) -> Option<&RadialDist> {
        self.dists[c].as_ref()
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

    /// A curvature at and beyond which [`axis_probs`](Self::axis_probs)
    /// no longer changes: ¼ each for T and B from κ·d =
    /// [`TANGENT_PROB_FULL_AT`] under [`ProbeAxes::Curvature`] (rounded up
    /// by 2⁻²⁰ so that κ·d ≥ 1 holds after the f32 rounding), 0 under the
    /// rules that read no curvature; ∞ without an active channel.
    #[inline]
    pub fn saturated_curvature(&self) -> f32 {
        self.saturated
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
