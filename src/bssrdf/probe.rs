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
//!   4√3 · n_active · A / CDF(Rmax)^(renormalize) (× total), independent of
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

use super::fast::FastProbe;
use super::params::SubsurfaceParams;
use super::profile;
use super::radius::{RadialDist, RadiusSampler};
use crate::accel::{Accel, Hit, ProbeHits};
use crate::error::{Constraint, Param, ParamError};
use crate::geometry::{Frame, Ray, Vec3};
use crate::sampling::Draw;

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

/// One sampled entry point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSample {
    /// The accel hit (mesh `geom`, triangle `prim`, barycentrics).
    pub hit: Hit,
    /// xi, reconstructed along the probe ray (see the comment in `sample`).
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
    /// The f32 evaluation of the weights, for the exact samplers when the
    /// channels' d are within its range; None falls back to f64.
    fast: Option<FastProbe>,
}

impl ProbeSampler {
    /// Prepares the sampler. A material with no active channel is valid: it
    /// samples nothing ([`sample`](Self::sample) returns None).
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
        let fast = match opts.radius {
            RadiusSampler::Analytic | RadiusSampler::Mixture => FastProbe::new(
                params.d,
                scale,
                std::array::from_fn(|c| dists[c].as_ref().map_or(0.0, |d| d.profile_mass())),
                std::array::from_fn(|c| dists[c].is_some()),
                rmax,
            ),
            RadiusSampler::Uniform | RadiusSampler::Table { .. } => None,
        };
        Ok(ProbeSampler {
            opts: *opts,
            scale,
            d: params.d,
            dists,
            active,
            n_active,
            rmax,
            fast,
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
        // Disk radii from the squares of the other two local coordinates:
        // |d|² − (d·V)² would cancel when r ≪ |d|.
        let sq = axes.map(|v| d.dot(v).powi(2));
        let mut pdf = [0.0; 3];
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
                    pdf[c] += probs[a] * dist.pdf(r_a) * cos;
                }
            }
        }
        pdf
    }

    /// Samples an entry point xi for exit point `xo` with shading frame
    /// `frame`, on mesh `geom`; `face_normals` is
    /// [`face_normals`](crate::integrator::interaction::face_normals) of that
    /// mesh (the render computes them once, so a probe hit costs a load
    /// instead of a cross product and a normalization).
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
        face_normals: &[Vec3],
        hits: &mut ProbeHits,
    ) -> Option<ProbeSample> {
        if self.n_active == 0 {
            return None;
        }
        // Through u32, whose saturating conversions are a few instructions
        // shorter than usize's: n_active ≤ 3 and the clamp below make the
        // result the same for every input.
        let ci = ((u.channel * self.n_active as u32 as f64) as u32 as usize).min(self.n_active - 1);
        let ch = self.active[ci];
        let dist = self.dists[ch].as_ref()?;
        // The radius first: its sampler may call libm, and nothing of the
        // frame is live across that call yet.
        let r = dist.sample_radius(u.radius);
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
        // The angle in f32: its rounding moves p0 by ~1e-7·r, below the f32
        // rounding of p0 itself.
        let (sin, cos) = crate::sampling::sin_cos_turns(u.angle as f32);
        let h = (self.rmax * self.rmax - r * r).max(0.0).sqrt();
        let xo64 = xo.as_dvec3();
        let p0 = xo64 + (t1 * cos as f64 + t2 * sin as f64) * r + v * h;
        let ray = Ray::new(p0.as_vec3(), (-v).as_vec3());
        accel.hits_on_segment(&ray, (2.0 * h) as f32, geom, u.seed, hits);
        let kept = hits.hits();
        if kept.is_empty() {
            return None;
        }
        // kept.len() ≤ MAX_PROBE_HITS: u32 as above (the length through i32,
        // which converts to f64 in one instruction, where LLVM turns u32
        // into the long unsigned 64-bit sequence), and the count through
        // i64 (exact: it is far below 2⁶³)
        let hit = kept[((u.hit * kept.len() as i32 as f64) as u32 as usize).min(kept.len() - 1)];
        let total = hits.total() as i64 as f64;

        // xi from the ray, not the barycentrics: its error is ~ε·Rmax, while
        // barycentrics on a large triangle err by ~ε·(triangle size), which
        // matters when d is small against the triangles (big flat quads).
        let xi = ray.o.as_dvec3() + ray.d.as_dvec3() * hit.t as f64;
        let normal = face_normals[hit.prim as usize];
        if normal == Vec3::ZERO {
            return None;
        }
        let n_hit = normal.as_dvec3();
        let dvec = xi - xo64;
        let w = match &self.fast {
            Some(fast) => self.weights_f32(fast, dvec, frame, n_hit, ch)?,
            None => self.weights_f64(dvec, frame, n_hit, ch)?,
        };
        Some(ProbeSample {
            hit,
            point: xi.as_vec3(),
            normal,
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
    /// the f64 reference.
    fn weights_f64(&self, d: DVec3, frame: &Frame, n_hit: DVec3, ch: usize) -> Option<[f32; 3]> {
        let pdf = self.pdf_area_d(d, frame, n_hit);
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

    /// The same in f32 ([`super::fast`]).
    #[inline]
    fn weights_f32(
        &self,
        fast: &FastProbe,
        d: DVec3,
        frame: &Frame,
        n_hit: DVec3,
        ch: usize,
    ) -> Option<[f32; 3]> {
        let axes = [frame.t, frame.b, frame.n].map(|v| v.as_dvec3());
        let local = axes.map(|v| d.dot(v));
        let cos = axes.map(|v| v.dot(n_hit).abs() as f32);
        let probs = self.axis_probs().map(|p| p as f32);
        fast.weights(local, cos, probs, self.single(ch), self.n_active)
    }
}

#[cfg(test)]
// Tests index parallel per-channel arrays by channel number.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::accel::MAX_PROBE_HITS;
    use crate::bssrdf::radius::TableSpacing;
    use crate::geometry::Mesh;
    use crate::integrator::interaction::face_normals;
    use crate::sampling::Rng;

    /// A brute-force [`Accel`]: every query loops over every triangle with a
    /// Möller–Trumbore test in f64. Slow, obviously right, and independent of
    /// the BVH and Embree backends.
    struct Brute {
        meshes: Vec<Mesh>,
    }

    fn tri_hit(ray: &Ray, [a, b, c]: [Vec3; 3], tmin: f32, tmax: f32) -> Option<(f32, f32, f32)> {
        let (o, d) = (ray.o.as_dvec3(), ray.d.as_dvec3());
        let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-300 {
            return None;
        }
        let inv = 1.0 / det;
        let s = o - a;
        let u = s.dot(p) * inv;
        let q = s.cross(e1);
        let v = d.dot(q) * inv;
        let t = e2.dot(q) * inv;
        if u < 0.0 || v < 0.0 || u + v > 1.0 || t < tmin as f64 || t > tmax as f64 {
            return None;
        }
        Some((t as f32, u as f32, v as f32))
    }

    impl Accel for Brute {
        fn name(&self) -> &'static str {
            "brute"
        }
        fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
            let mut best: Option<Hit> = None;
            for (g, m) in self.meshes.iter().enumerate() {
                for prim in 0..m.triangle_count() as u32 {
                    if let Some((t, u, v)) = tri_hit(ray, m.triangle(prim), tmin, tmax) {
                        if best.is_none_or(|b| t < b.t) {
                            best = Some(Hit {
                                t,
                                geom: g as u32,
                                prim,
                                u,
                                v,
                            });
                        }
                    }
                }
            }
            best
        }
        fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
            self.intersect(ray, tmin, tmax).is_some()
        }
        fn hits_on_segment(&self, ray: &Ray, tmax: f32, geom: u32, seed: u32, out: &mut ProbeHits) {
            out.reset(seed);
            let m = &self.meshes[geom as usize];
            for prim in 0..m.triangle_count() as u32 {
                if let Some((t, u, v)) = tri_hit(ray, m.triangle(prim), 0.0, tmax) {
                    out.record(Hit {
                        t,
                        geom,
                        prim,
                        u,
                        v,
                    });
                }
            }
            out.finish();
        }
    }

    /// Square planes of half-size `l` at heights `zs` (normal +z), one mesh.
    fn planes(l: f32, zs: &[f32]) -> Mesh {
        let mut p = Vec::new();
        let mut idx = Vec::new();
        for &z in zs {
            let k = p.len() as u32;
            p.extend([
                Vec3::new(-l, -l, z),
                Vec3::new(l, -l, z),
                Vec3::new(l, l, z),
                Vec3::new(-l, l, z),
            ]);
            idx.extend([[k, k + 1, k + 2], [k, k + 2, k + 3]]);
        }
        Mesh::new(p, idx, None)
    }

    struct Stats {
        mean: [f64; 3],
        se: [f64; 3],
        max: f64,
        found: usize,
    }

    /// Runs n probes at xo and averages the weights (None counts as 0).
    fn run(s: &ProbeSampler, accel: &Brute, xo: Vec3, frame: &Frame, n: usize, key: u64) -> Stats {
        run_on(s, accel, &accel.meshes[0], xo, frame, n, key)
    }

    fn run_on(
        s: &ProbeSampler,
        accel: &dyn Accel,
        mesh: &Mesh,
        xo: Vec3,
        frame: &Frame,
        n: usize,
        key: u64,
    ) -> Stats {
        let mut rng = Rng::from_key(key);
        let mut hits = ProbeHits::new();
        let (mut s1, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
        let (mut max, mut found) = (0.0f64, 0);
        let normals = face_normals(mesh);
        for _ in 0..n {
            let u = ProbeRandoms::from_rng(&mut rng);
            if let Some(ps) = s.sample(xo, frame, &u, accel, 0, &normals, &mut hits) {
                found += 1;
                assert!(ps.normal.is_finite() && (ps.normal.length() - 1.0).abs() < 1e-5);
                assert!(ps.point.is_finite());
                for c in 0..3 {
                    let w = ps.weight[c] as f64;
                    assert!(w.is_finite() && w >= 0.0, "weight {:?}", ps.weight);
                    s1[c] += w;
                    s2[c] += w * w;
                    max = max.max(w);
                }
            }
        }
        let nf = n as f64;
        let mean = s1.map(|x| x / nf);
        let se = std::array::from_fn(|c| ((s2[c] / nf - mean[c] * mean[c]).max(0.0) / nf).sqrt());
        Stats {
            mean,
            se,
            max,
            found,
        }
    }

    fn all_options() -> Vec<ProbeOptions> {
        let mut v = Vec::new();
        for axes in [ProbeAxes::Normal, ProbeAxes::Mis3] {
            for channel in [ChannelStrategy::Single, ChannelStrategy::Mis] {
                for radius in [
                    RadiusSampler::Uniform,
                    RadiusSampler::table(64),
                    RadiusSampler::Table {
                        size: 64,
                        spacing: TableSpacing::Uniform,
                    },
                    RadiusSampler::Analytic,
                    RadiusSampler::Mixture,
                ] {
                    for renormalize in [false, true] {
                        v.push(ProbeOptions {
                            axes,
                            channel,
                            radius,
                            rmax_quantile: 0.999,
                            renormalize,
                        });
                    }
                }
            }
        }
        v
    }

    /// A frame whose normal is tilted by `deg` degrees from +z (a shading
    /// normal that differs from the geometric one), so that T and B probes
    /// hit the plane too and the axis MIS is exercised.
    fn tilted(deg: f32) -> Frame {
        let a = deg.to_radians();
        Frame::from_normal(Vec3::new(a.sin() * 0.6, a.sin() * 0.8, a.cos()).normalize())
    }

    /// Test materials with channels 10× apart, except for the Uniform
    /// sampler: its weight A·R(r)·πRmax² has a log-divergent second moment
    /// at r → 0 (cut only by RHO_MIN), so a channel with d ≪ Rmax gives a
    /// sample mean that is unreliable at any test budget. That is the
    /// baseline's known weakness, not an error.
    fn params_for(opts: &ProbeOptions, scale: f64) -> SubsurfaceParams {
        let d = if opts.radius == RadiusSampler::Uniform {
            [1.0, 0.8, 0.6]
        } else {
            [1.0, 0.35, 0.1]
        };
        SubsurfaceParams {
            albedo: [0.8, 0.5, 0.3],
            d: d.map(|d| d * scale),
            eta: 1.3,
            medium: None,
        }
    }

    fn assert_close(st: &Stats, truth: [f64; 3], what: &str) {
        for c in 0..3 {
            let tol = 5.0 * st.se[c] + 1e-9;
            assert!(
                (st.mean[c] - truth[c]).abs() < tol,
                "{what} ch{c}: {} ± {} vs {}",
                st.mean[c],
                st.se[c],
                truth[c]
            );
        }
    }

    #[test]
    fn flat_plane_reflects_a_times_cdf_rmax_for_every_option() {
        // The plane (half-size 100 d_max) covers the probe sphere (19.9 d_max),
        // so it is infinite for the estimator: the mean weight must be
        // A·CDF(Rmax) per channel, or A renormalized, for every axis choice,
        // channel strategy, radius sampler, and for a shading normal tilted
        // against the plane (all three axes then hit it obliquely).
        let accel = Brute {
            meshes: vec![planes(100.0, &[0.0])],
        };
        let xo = Vec3::new(0.37, -0.21, 0.0); // off the quad's diagonal
        for (i, opts) in all_options().iter().enumerate() {
            let params = params_for(opts, 1.0);
            let s = ProbeSampler::new(&params, opts).unwrap();
            let truth = s.planar_reflectance();
            for c in 0..3 {
                let mass = profile::cdf(s.rmax(), params.d[c]);
                let want = params.albedo[c] * if opts.renormalize { 1.0 } else { mass };
                assert!((truth[c] - want).abs() < 1e-12);
            }
            for (j, deg) in [0.0f32, 40.0].into_iter().enumerate() {
                let what = format!("{opts:?} tilt {deg}°");
                if opts.radius == RadiusSampler::Uniform {
                    // P(weight > w) ~ w⁻² (see params_for): the sample
                    // variance underestimates the error, so allow 10% too.
                    let st = run(&s, &accel, xo, &tilted(deg), 300_000, (i * 8 + j) as u64);
                    for c in 0..3 {
                        let err = (st.mean[c] - truth[c]).abs();
                        assert!(
                            err < 5.0 * st.se[c] + 0.1 * truth[c],
                            "{what} ch{c}: {} vs {}",
                            st.mean[c],
                            truth[c]
                        );
                    }
                } else {
                    let st = run(&s, &accel, xo, &tilted(deg), 60_000, (i * 8 + j) as u64);
                    assert_close(&st, truth, &what);
                }
            }
        }
    }

    #[test]
    fn ketchup_blue_is_exactly_zero() {
        let params =
            SubsurfaceParams::from_preset("Ketchup", 1.0, profile::Fit::Searchlight).unwrap();
        let accel = Brute {
            meshes: vec![planes(2000.0, &[0.0])],
        };
        for (i, opts) in all_options().iter().enumerate() {
            let s = ProbeSampler::new(&params, opts).unwrap();
            let mut rng = Rng::from_key(i as u64);
            let mut hits = ProbeHits::new();
            let mut found = 0;
            for _ in 0..5_000 {
                let u = ProbeRandoms::from_rng(&mut rng);
                if let Some(ps) = s.sample(
                    Vec3::new(0.3, 0.1, 0.0),
                    &tilted(20.0),
                    &u,
                    &accel,
                    0,
                    &face_normals(&accel.meshes[0]),
                    &mut hits,
                ) {
                    found += 1;
                    assert_eq!(ps.weight.z.to_bits(), 0f32.to_bits(), "{opts:?}");
                    assert!(ps.weight.x.is_finite() && ps.weight.y.is_finite());
                }
            }
            assert!(found > 1000, "{opts:?}: {found}");
        }
        let s = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
        assert_eq!(s.planar_reflectance()[2], 0.0);
        assert_eq!(s.rd(0.5)[2], 0.0);
    }

    #[test]
    fn spectralon_renders_finite_white_and_not_above_a() {
        // σa = 0: d comes from the absorption floor (params.rs); a flat slab
        // reflects A·CDF(Rmax) = 0.999 ≤ A = 1, and exactly A renormalized.
        let params =
            SubsurfaceParams::from_preset("spectralon", 1.0, profile::Fit::Searchlight).unwrap();
        let accel = Brute {
            meshes: vec![planes(1000.0, &[0.0])],
        };
        for renormalize in [false, true] {
            let opts = ProbeOptions {
                renormalize,
                ..ProbeOptions::default()
            };
            let s = ProbeSampler::new(&params, &opts).unwrap();
            assert!(s.rmax().is_finite() && s.rmax() < 100.0, "{}", s.rmax());
            let st = run(
                &s,
                &accel,
                Vec3::new(0.37, -0.21, 0.0),
                &tilted(20.0),
                40_000,
                5,
            );
            assert_close(&st, s.planar_reflectance(), "spectralon");
            for c in 0..3 {
                assert!(st.mean[c] > 0.95 && s.planar_reflectance()[c] <= 1.0 + 1e-12);
            }
        }
    }

    #[test]
    fn several_hits_pick_one_and_multiply_by_the_count() {
        // Parallel planes at depths k·δ inside the probe sphere. Along N the
        // probe crosses all of them; one hit is kept with weight × total.
        // ∫_{plane at depth z, within the sphere} R dA = CDF(Rmax) − CDF(|z|).
        let params = SubsurfaceParams {
            albedo: [0.9, 0.6, 0.4],
            d: [1.0, 0.8, 0.5],
            eta: 1.3,
            medium: None,
        };
        // 3 planes, then 100 (more than MAX_PROBE_HITS = 64: the query keeps a
        // random 64 and counts them all)
        for (count, delta) in [(3usize, 0.7f32), (100, 0.15)] {
            assert!(count <= 3 || count > MAX_PROBE_HITS);
            let zs: Vec<f32> = (0..count).map(|k| -(k as f32) * delta).collect();
            let accel = Brute {
                meshes: vec![planes(60.0, &zs)],
            };
            for opts in [
                ProbeOptions::default(),
                ProbeOptions::seed(RadiusSampler::Analytic),
                ProbeOptions {
                    radius: RadiusSampler::Mixture,
                    ..ProbeOptions::default()
                },
            ] {
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let truth: [f64; 3] = std::array::from_fn(|c| {
                    let d = params.d[c];
                    let rm = s.rmax();
                    params.albedo[c]
                        * zs.iter()
                            .map(|&z| {
                                (profile::cdf(rm, d) - profile::cdf((z.abs() as f64).min(rm), d))
                                    .max(0.0)
                            })
                            .sum::<f64>()
                });
                let st = run(
                    &s,
                    &accel,
                    Vec3::new(0.31, -0.17, 0.0),
                    &Frame::from_normal(Vec3::Z),
                    40_000,
                    count as u64,
                );
                assert_close(&st, truth, &format!("{count} planes {opts:?}"));
                // and ignoring the count would be far off
                assert!(truth[0] > 1.8 * s.planar_reflectance()[0]);
            }
        }
    }

    #[test]
    fn tiny_and_huge_d() {
        // d = 1e-6 on a unit plane (f32 positions near the origin) still
        // gives A·CDF(Rmax); d = 1e6 on the same plane: the profile mass on
        // the plane is ~1e-6, probes almost never hit, nothing is NaN.
        let accel = Brute {
            meshes: vec![planes(1.0, &[0.0])],
        };
        for (k, opts) in all_options().iter().enumerate() {
            let tiny = params_for(opts, 1e-6);
            let s = ProbeSampler::new(&tiny, opts).unwrap();
            let xo = Vec3::new(3.1e-7, -1.3e-7, 0.0);
            let st = run(&s, &accel, xo, &tilted(30.0), 20_000, 100 + k as u64);
            for c in 0..3 {
                let t = s.planar_reflectance()[c];
                // f32 quantization of xo and hits (~1e-13 here) is 1e-7 d.
                assert!(
                    (st.mean[c] - t).abs() < 5.0 * st.se[c] + 1e-3 * t,
                    "{opts:?} ch{c}: {} ± {} vs {t}",
                    st.mean[c],
                    st.se[c]
                );
            }
            let huge = tiny.scaled(1e12);
            let s = ProbeSampler::new(&huge, opts).unwrap();
            let st = run(
                &s,
                &accel,
                Vec3::new(0.1, 0.2, 0.0),
                &tilted(30.0),
                20_000,
                200 + k as u64,
            );
            assert!(st.found < 20_000 / 10, "{opts:?}: {}", st.found);
            // the whole plane holds about ∫∫ A/(4π d r) dA = A·8L asinh(1)/(4π d) ≈ 4e-7 A
            for c in 0..3 {
                assert!(st.mean[c] < 1e-3, "{opts:?}: {:?}", st.mean);
            }
        }
    }

    #[test]
    fn grazing_hits_are_bounded_by_mis3() {
        // The shading normal is tilted 88° from the plane's normal: probes
        // along N meet the plane at |V·N| = cos 88° ≈ 0.035. Both estimators
        // are unbiased, but Normal's weights reach 1/0.035 × larger values,
        // while Mis3's are bounded by 4√3·n_active·A (module docs).
        let params = SubsurfaceParams {
            albedo: [0.8, 0.8, 0.8],
            d: [1.0, 0.7, 0.4],
            eta: 1.3,
            medium: None,
        };
        let accel = Brute {
            meshes: vec![planes(100.0, &[0.0])],
        };
        let frame = tilted(88.0);
        let xo = Vec3::new(0.37, -0.21, 0.0);
        let bound = 4.0 * 3f64.sqrt() * 3.0 * 0.8;
        let mut maxes = Vec::new();
        for axes in [ProbeAxes::Normal, ProbeAxes::Mis3] {
            for radius in [RadiusSampler::Analytic, RadiusSampler::Mixture] {
                let opts = ProbeOptions {
                    axes,
                    radius,
                    ..ProbeOptions::default()
                };
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let st = run(&s, &accel, xo, &frame, 100_000, 7);
                assert_close(&st, s.planar_reflectance(), &format!("{opts:?}"));
                println!(
                    "grazing 88°, {axes:?} {radius:?}: max weight {:.2} (Mis3 bound {bound:.2}), mean {:.4}, rel. s.e. {:.2e}",
                    st.max,
                    st.mean[0],
                    st.se[0] / st.mean[0]
                );
                if axes == ProbeAxes::Mis3 {
                    assert!(st.max <= bound * (1.0 + 1e-4), "{}", st.max);
                }
                maxes.push(st.max);
            }
        }
        // the normal-only probe's maximum is far above the bound
        assert!(
            maxes[0] > 2.0 * bound && maxes[1] > 2.0 * bound,
            "{maxes:?}"
        );
    }

    #[test]
    fn probes_that_find_nothing_return_none() {
        let params = SubsurfaceParams {
            albedo: [0.8, 0.5, 0.3],
            d: [1.0, 0.35, 0.1],
            eta: 1.3,
            medium: None,
        };
        // the only surface is far beyond Rmax
        let accel = Brute {
            meshes: vec![planes(10.0, &[-1000.0])],
        };
        for opts in all_options() {
            let s = ProbeSampler::new(&params, &opts).unwrap();
            let st = run(
                &s,
                &accel,
                Vec3::ZERO,
                &Frame::from_normal(Vec3::Z),
                2_000,
                1,
            );
            assert_eq!(st.found, 0);
        }
        // an empty mesh
        let empty = Brute {
            meshes: vec![Mesh::new(vec![], vec![], None)],
        };
        let s = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
        assert_eq!(
            run(&s, &empty, Vec3::ZERO, &Frame::from_normal(Vec3::Z), 100, 2).found,
            0
        );
        // no active channel: valid material, never samples
        let black = SubsurfaceParams {
            albedo: [0.0; 3],
            d: [1.0; 3],
            eta: 1.3,
            medium: None,
        };
        let s = ProbeSampler::new(&black, &ProbeOptions::default()).unwrap();
        assert_eq!(s.rmax(), 0.0);
        let plane = Brute {
            meshes: vec![planes(10.0, &[0.0])],
        };
        assert_eq!(
            run(&s, &plane, Vec3::ZERO, &Frame::from_normal(Vec3::Z), 100, 3).found,
            0
        );
        // and a degenerate (zero-area) triangle is skipped, not divided by
        let degenerate = Brute {
            meshes: vec![Mesh::new(
                vec![
                    Vec3::new(-1.0, 0.0, 0.0),
                    Vec3::new(1.0, 0.0, 0.0),
                    Vec3::new(0.0, 0.0, 0.0),
                ],
                vec![[0, 1, 2]],
                None,
            )],
        };
        let s = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
        assert_eq!(
            run(
                &s,
                &degenerate,
                Vec3::ZERO,
                &Frame::from_normal(Vec3::Z),
                1000,
                4
            )
            .found,
            0
        );
    }

    #[test]
    fn extreme_random_numbers_are_finite() {
        let params = SubsurfaceParams {
            albedo: [0.8, 0.5, 0.3],
            d: [1.0, 0.35, 0.1],
            eta: 1.3,
            medium: None,
        };
        let accel = Brute {
            meshes: vec![planes(100.0, &[0.0])],
        };
        let top = 1.0 - f64::EPSILON / 2.0;
        let mut hits = ProbeHits::new();
        for opts in all_options() {
            let s = ProbeSampler::new(&params, &opts).unwrap();
            for &a in &[0.0, top] {
                for &b in &[0.0, top] {
                    for &r in &[0.0, 1e-300, top] {
                        let u = ProbeRandoms {
                            axis: a,
                            channel: b,
                            radius: r,
                            angle: a,
                            hit: b,
                            seed: 0,
                        };
                        let frame = tilted(35.0);
                        if let Some(ps) = s.sample(
                            Vec3::new(0.37, -0.21, 0.0),
                            &frame,
                            &u,
                            &accel,
                            0,
                            &face_normals(&accel.meshes[0]),
                            &mut hits,
                        ) {
                            assert!(
                                ps.weight.is_finite() && ps.weight.min_element() >= 0.0,
                                "{opts:?} {u:?}: {:?}",
                                ps.weight
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn real_bvh_backend_gives_the_same_energy() {
        // The same ground truths through lucent's BVH (watertight test,
        // two-level tree) instead of the brute-force loop: a tilted-frame
        // plane, and 100 stacked planes (probe-hit overflow).
        use crate::accel::{build, Backend};
        use std::sync::Arc;
        let params = SubsurfaceParams {
            albedo: [0.9, 0.6, 0.4],
            d: [1.0, 0.35, 0.1],
            eta: 1.3,
            medium: None,
        };
        let xo = Vec3::new(0.31, -0.17, 0.0);
        let zs: Vec<f32> = (0..100).map(|k| -(k as f32) * 0.15).collect();
        for (mesh, stacked) in [(planes(100.0, &[0.0]), false), (planes(60.0, &zs), true)] {
            let meshes = Arc::new(vec![mesh]);
            let bvh = build(&meshes, Backend::Bvh).unwrap();
            for opts in [
                ProbeOptions::default(),
                ProbeOptions::seed(RadiusSampler::table(256)),
                ProbeOptions {
                    channel: ChannelStrategy::Single,
                    radius: RadiusSampler::Mixture,
                    renormalize: true,
                    ..ProbeOptions::default()
                },
            ] {
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let rm = s.rmax();
                let truth: [f64; 3] = if stacked {
                    std::array::from_fn(|c| {
                        let d = params.d[c];
                        let k = s.planar_reflectance()[c] / profile::cdf(rm, d);
                        k * zs
                            .iter()
                            .map(|&z| {
                                (profile::cdf(rm, d) - profile::cdf((z.abs() as f64).min(rm), d))
                                    .max(0.0)
                            })
                            .sum::<f64>()
                    })
                } else {
                    s.planar_reflectance()
                };
                let frame = if stacked {
                    Frame::from_normal(Vec3::Z)
                } else {
                    tilted(40.0)
                };
                let st = run_on(&s, bvh.as_ref(), &meshes[0], xo, &frame, 40_000, 77);
                assert_close(&st, truth, &format!("bvh stacked={stacked} {opts:?}"));
            }
        }
    }

    /// Relative standard deviation per probe sample and cost per probe
    /// (2-triangle brute-force accel, so mostly the estimator's own cost),
    /// for every sampler on a plane seen with an aligned and a 60°-tilted
    /// shading frame. Run with
    /// `cargo test --lib bench_probe -- --ignored --nocapture --test-threads=1`.
    #[test]
    #[ignore]
    fn bench_probe_variance_and_cost() {
        use std::time::Instant;
        let params =
            SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight).unwrap();
        let accel = Brute {
            meshes: vec![planes(1000.0, &[0.0])],
        };
        let xo = Vec3::new(0.37, -0.21, 0.0);
        for deg in [0.0f32, 60.0] {
            for opts in all_options().into_iter().filter(|o| !o.renormalize) {
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let n = 200_000;
                let t0 = Instant::now();
                let st = run(&s, &accel, xo, &tilted(deg), n, 9);
                let ns = t0.elapsed().as_nanos() as f64 / n as f64;
                let rel: Vec<String> = (0..3)
                    .map(|c| format!("{:.2}", st.se[c] * (n as f64).sqrt() / st.mean[c]))
                    .collect();
                println!(
                    "tilt {deg:2}° {:?} {:?} {:?}: rel. sd/sample [{}], {ns:.0} ns/probe",
                    opts.axes,
                    opts.channel,
                    opts.radius,
                    rel.join(", ")
                );
            }
        }
    }

    #[test]
    fn f32_weights_match_the_f64_reference() {
        // The f32 path against the f64 one on entry points spread over the
        // probe sphere, many nearly on an axis (disk radius down to 1e-12
        // Rmax, below the RHO_MIN clamp), for materials whose channels span
        // up to the f32 path's range of r/d, in scene units from 1e-6 to 1e6.
        use crate::sampling::uniform_sphere;
        let marble = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight);
        let skin = SubsurfaceParams::from_preset("skin1", 1.0, profile::Fit::Searchlight);
        let wide = SubsurfaceParams {
            albedo: [0.9, 0.0, 0.3],
            d: [1.0, 0.7, 0.0835],
            eta: 1.3,
            medium: None,
        };
        let mut materials = vec![marble.unwrap(), skin.unwrap(), wide];
        materials.push(materials[0].scaled(1e-6));
        materials.push(materials[1].scaled(1e6));
        let mut rng = Rng::from_key(99);
        let mut worst = 0.0f64;
        for params in &materials {
            for axes in [ProbeAxes::Normal, ProbeAxes::Mis3] {
                for channel in [ChannelStrategy::Single, ChannelStrategy::Mis] {
                    for radius in [RadiusSampler::Analytic, RadiusSampler::Mixture] {
                        for renormalize in [false, true] {
                            let opts = ProbeOptions {
                                axes,
                                channel,
                                radius,
                                rmax_quantile: 0.999,
                                renormalize,
                            };
                            let s = ProbeSampler::new(params, &opts).unwrap();
                            let fast = s.fast.as_ref().expect("f32 path in range");
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
                                let f = s.weights_f32(fast, d, &frame, n_hit, ch);
                                let r = s.weights_f64(d, &frame, n_hit, ch);
                                let (Some(f), Some(r)) = (f, r) else {
                                    assert_eq!(f.is_some(), r.is_some(), "{opts:?} {d} {n_hit}");
                                    continue;
                                };
                                for c in 0..3 {
                                    // relative, but not among subnormal weights
                                    let e = ((f[c] - r[c]) as f64).abs() / (r[c] as f64).max(1e-35);
                                    // exp(−ρ/3) inherits the f32 rounding of its
                                    // argument times ρ/3 (a few ulp, 6e-8 each),
                                    // in Rd and in the density: the bound grows
                                    // with r/d (≤ 240 on this path).
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
        // the other samplers, and a channel ratio beyond the range, use f64
        let opts = ProbeOptions::seed(RadiusSampler::table(64));
        assert!(ProbeSampler::new(&materials[0], &opts)
            .unwrap()
            .fast
            .is_none());
        let mut far = materials[2];
        far.d[2] = 0.05;
        let s = ProbeSampler::new(&far, &ProbeOptions::default()).unwrap();
        assert!(s.fast.is_none());
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
}
