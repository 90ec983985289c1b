//! The probe-ray estimator of the BSSRDF's spatial integral (King et al.
//! 2013, "BSSRDF Importance Sampling"; pbrt-v3 §15.4.2
//! `SeparableBSSRDF::Sample_Sp` / `Pdf_Sp`; `docs/bssrdf.md` §5).
//!
//! To estimate ∫_A Rd(|xo − xi|) g(xi) dA(xi) at an exit point xo, pick a
//! projection axis V and a channel, sample a radius r and an angle φ on the
//! disk ⟂ V, and shoot a probe segment through the sphere of radius Rmax
//! around xo, parallel to V, at that disk point. Every hit xi on the same
//! object is a candidate; its surface-area density is
//! p_disk(r)·|V·N(xi)|. One hit is picked uniformly among those the query
//! kept and weighted by the number the segment had ([`ProbeHits::total`]):
//! the kept ones are a uniform random subset, so every hit of the segment is
//! picked with probability 1/total and the estimator stays unbiased.
//!
//! Options:
//! - [`ProbeAxes::Normal`]: probe along N only (the seed). Grazing hits
//!   (|V·N| → 0) give unbounded weights.
//! - [`ProbeAxes::Mis3`]: N, T, B with probabilities ½, ¼, ¼, combined with
//!   the balance heuristic over axes: the density of a hit is
//!   Σ_a p_a p_disk(r_a) |V_a·N|, with r_a the radius of xi − xo projected ⟂
//!   V_a. Since Σ_a (V_a·N)² = 1 some axis has |V_a·N| ≥ 1/√3, and since
//!   r_a ≤ |xo − xi| and R decreases, p_disk(r_a) ≥ R(|xo − xi|) for the
//!   exact samplers: the weight of one hit is at most
//!   4√3 · n_active · A / CDF(Rmax)^[renormalize] (× total), independent of
//!   the geometry.
//! - [`ChannelStrategy::Single`]: pick one active channel uniformly and
//!   estimate only it (the others get 0 from this sample) — the seed.
//! - [`ChannelStrategy::Mis`]: pick a channel uniformly, estimate all of them
//!   with the balance-heuristic density Σ_c p_c / n_active.
//! - `renormalize`: divide Rd by CDF(Rmax) per channel, so the truncation to
//!   Rmax loses no energy (a flat slab reflects exactly A instead of
//!   A·CDF(Rmax)).
//!
//! Channels with A = 0 or d = 0 are never chosen, never divided by, and
//! always get weight 0.

use glam::DVec3;

use super::params::SubsurfaceParams;
use super::profile;
use super::radius::{RadialDist, RadiusSampler};
use crate::accel::{Accel, Hit, ProbeHits};
use crate::geometry::{Frame, Mesh, Ray, Vec3};
use crate::sampling::Rng;

/// Which axes probes are shot along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ProbeAxes {
    /// Along the shading normal only (the seed).
    Normal,
    /// N, T, B with probabilities ½, ¼, ¼ and the balance heuristic.
    #[default]
    Mis3,
}

/// How the color channels share one probe sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ChannelStrategy {
    /// Estimate only the channel the radius was sampled for (the seed).
    Single,
    /// Estimate all channels with the balance heuristic over channels.
    #[default]
    Mis,
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
            axes: ProbeAxes::Mis3,
            channel: ChannelStrategy::Mis,
            radius: RadiusSampler::Analytic,
            rmax_quantile: 0.999,
            renormalize: false,
        }
    }
}

impl ProbeOptions {
    /// The seed's configuration with a given radius sampler: normal axis,
    /// one channel per sample, no renormalization.
    pub fn seed(radius: RadiusSampler) -> Self {
        ProbeOptions {
            axes: ProbeAxes::Normal,
            channel: ChannelStrategy::Single,
            radius,
            rmax_quantile: 0.999,
            renormalize: false,
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        self.radius.validate()?;
        let q = self.rmax_quantile;
        if !(q > 0.0 && q < 1.0) {
            return Err(format!("rmax_quantile: {q} must be in (0, 1)"));
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
    pub fn from_rng(rng: &mut Rng) -> Self {
        ProbeRandoms {
            axis: rng.uniform_f64(),
            channel: rng.uniform_f64(),
            radius: rng.uniform_f64(),
            angle: rng.uniform_f64(),
            hit: rng.uniform_f64(),
            seed: rng.next_u32(),
        }
    }
}

/// One sampled entry point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSample {
    /// The accel hit (mesh `geom`, triangle `prim`, barycentrics).
    pub hit: Hit,
    /// xi, from the barycentrics.
    pub point: Vec3,
    /// Unit geometric normal of the hit triangle, oriented by its winding
    /// (outward for a consistently wound closed mesh); not flipped toward xo.
    pub normal: Vec3,
    /// Rd(|xo − xi|) / pdf(xi) × (hits on the segment), per channel; the
    /// integrator multiplies by the directional factors and incident light.
    pub weight: Vec3,
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
}

impl ProbeSampler {
    /// Prepares the sampler. A material with no active channel is valid: it
    /// samples nothing ([`sample`](Self::sample) returns None).
    pub fn new(params: &SubsurfaceParams, opts: &ProbeOptions) -> Result<Self, String> {
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
        Ok(ProbeSampler {
            opts: *opts,
            scale,
            d: params.d,
            dists,
            active,
            n_active,
            rmax,
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
    pub fn planar_reflectance(&self) -> [f64; 3] {
        std::array::from_fn(|c| match &self.dists[c] {
            Some(dist) => self.scale[c] * dist.profile_mass(),
            None => 0.0,
        })
    }

    /// Rd(r) per channel as the estimator uses it (A·R, or A·R/CDF(Rmax)).
    #[inline]
    pub fn rd(&self, r: f64) -> [f64; 3] {
        std::array::from_fn(|c| match self.dists[c] {
            Some(_) => self.scale[c] * profile::profile(r, self.d[c]),
            None => 0.0,
        })
    }

    /// Axis probabilities (T, B, N).
    #[inline]
    fn axis_probs(&self) -> [f64; 3] {
        match self.opts.axes {
            ProbeAxes::Normal => [0.0, 0.0, 1.0],
            ProbeAxes::Mis3 => [0.25, 0.25, 0.5],
        }
    }

    /// Per channel, the surface-area density with which a probe sampled for
    /// that channel lands on xi (normal `n_hit`), summed over axes with
    /// their probabilities (pbrt-v3 `Pdf_Sp` without the channel sum).
    /// Inactive channels give 0.
    pub fn pdf_area(&self, xo: Vec3, frame: &Frame, xi: Vec3, n_hit: Vec3) -> [f64; 3] {
        let d = xi.as_dvec3() - xo.as_dvec3();
        self.pdf_area_d(d, frame, n_hit.as_dvec3().normalize_or_zero())
    }

    #[inline]
    fn pdf_area_d(&self, d: DVec3, frame: &Frame, n_hit: DVec3) -> [f64; 3] {
        let axes = [frame.t.as_dvec3(), frame.b.as_dvec3(), frame.n.as_dvec3()];
        let probs = self.axis_probs();
        let d2 = d.length_squared();
        let mut pdf = [0.0; 3];
        for a in 0..3 {
            if probs[a] == 0.0 {
                continue;
            }
            let along = d.dot(axes[a]);
            // Rounding can put a hit just outside the sphere; keep its
            // projection on the disk so the sampled axis never scores 0.
            let r_a = (d2 - along * along).max(0.0).sqrt().min(self.rmax);
            let cos = axes[a].dot(n_hit).abs();
            if cos == 0.0 {
                continue;
            }
            for &c in &self.active[..self.n_active] {
                if let Some(dist) = &self.dists[c] {
                    pdf[c] += probs[a] * dist.pdf(r_a) * cos;
                }
            }
        }
        pdf
    }

    /// Samples an entry point xi for exit point `xo` with shading frame
    /// `frame`, on mesh `geom` (`mesh` is that mesh, for the hit normal).
    ///
    /// `hits` is a scratch buffer reused across calls (no allocation here).
    /// Returns None when the probe finds nothing, or hits only degenerate
    /// triangles or a surface parallel to every probe axis used; the
    /// estimate is then 0, which is correct (nothing there to scatter from).
    #[allow(clippy::too_many_arguments)]
    pub fn sample(
        &self,
        xo: Vec3,
        frame: &Frame,
        u: &ProbeRandoms,
        accel: &dyn Accel,
        geom: u32,
        mesh: &Mesh,
        hits: &mut ProbeHits,
    ) -> Option<ProbeSample> {
        if self.n_active == 0 {
            return None;
        }
        // Axis and its disk basis (T', B' span the plane ⟂ V).
        let (t, b, n) = (frame.t.as_dvec3(), frame.b.as_dvec3(), frame.n.as_dvec3());
        let axis = match self.opts.axes {
            ProbeAxes::Normal => AXIS_N,
            ProbeAxes::Mis3 => {
                if u.axis < 0.5 {
                    AXIS_N
                } else if u.axis < 0.75 {
                    0
                } else {
                    1
                }
            }
        };
        let (v, t1, t2) = match axis {
            0 => (t, b, n),
            1 => (b, n, t),
            _ => (n, t, b),
        };
        let ci = ((u.channel * self.n_active as f64) as usize).min(self.n_active - 1);
        let ch = self.active[ci];
        let dist = self.dists[ch].as_ref()?;
        let (r, _) = dist.sample(u.radius);
        let phi = 2.0 * std::f64::consts::PI * u.angle;
        let h = (self.rmax * self.rmax - r * r).max(0.0).sqrt();
        let xo64 = xo.as_dvec3();
        let p0 = xo64 + (t1 * phi.cos() + t2 * phi.sin()) * r + v * h;
        let ray = Ray::new(p0.as_vec3(), (-v).as_vec3());
        accel.hits_on_segment(&ray, (2.0 * h) as f32, geom, u.seed, hits);
        let kept = hits.hits();
        if kept.is_empty() {
            return None;
        }
        let hit = kept[((u.hit * kept.len() as f64) as usize).min(kept.len() - 1)];
        let total = hits.total() as f64;

        let [a, bv, cv] = mesh.triangle(hit.prim).map(|p| p.as_dvec3());
        let (bu, bw) = (hit.u as f64, hit.v as f64);
        let xi = a * (1.0 - bu - bw) + bv * bu + cv * bw;
        let n_hit = (bv - a).cross(cv - a).normalize_or_zero();
        if n_hit == DVec3::ZERO {
            return None;
        }
        let dvec = xi - xo64;
        let pdf = self.pdf_area_d(dvec, frame, n_hit);
        let dist3 = dvec.length();
        let mut w = [0.0f64; 3];
        match self.opts.channel {
            ChannelStrategy::Single => {
                let p = pdf[ch] / self.n_active as f64;
                if !(p > 0.0 && p.is_finite()) {
                    return None;
                }
                w[ch] = self.scale[ch] * profile::profile(dist3, self.d[ch]) / p * total;
            }
            ChannelStrategy::Mis => {
                let p = pdf.iter().sum::<f64>() / self.n_active as f64;
                if !(p > 0.0 && p.is_finite()) {
                    return None;
                }
                for &c in &self.active[..self.n_active] {
                    w[c] = self.scale[c] * profile::profile(dist3, self.d[c]) / p * total;
                }
            }
        }
        Some(ProbeSample {
            hit,
            point: xi.as_vec3(),
            normal: n_hit.as_vec3(),
            weight: Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32),
        })
    }
}
