//! A curvature correction of the diffusion BSSRDF's weight
//! (`docs/bssrdf.md` §10): the profile Rd describes a half-space, and on a
//! convex body it returns too little light. The weight of a probe hit from
//! xo to xi is multiplied by √(f(κo)·f(κi)), f(κ) = A_sphere(ρ)/(A·g(R)) at
//! the local mean curvature κ = 1/R ([`mean_curvature`](crate::geometry::curvature::mean_curvature)), A_sphere from
//! [`super::curvature_table`]; f = 1 exactly where κ ≤ 0. f is clamped to
//! [[`MIN_FACTOR`], [`MAX_FACTOR`]], so every weight bound of the probe
//! estimator grows by at most [`MAX_FACTOR`]. Media without a recorded
//! medium get no correction.
//!
//! The deficit's derivation, the curvature estimate and the model's
//! precision: `docs/bssrdf.md` §12.2; measured per preset:
//! `docs/accuracy.md`, "Curvature correction".

use super::albedo_table::TableError;
use super::curvature_table::CurvatureTable;
use super::params::{diffuse_mfp, SubsurfaceParams};
use super::probe::ProbeSampler;
use super::profile;
use super::tabulated::TabulatedProfile;
use crate::geometry::Vec3;
use std::sync::Arc;

/// The largest factor applied to a weight (on a body far smaller than the
/// diffusion length, where the half-space profile has nothing left to
/// rescale): the estimator's weight bounds grow by at most this.
pub const MAX_FACTOR: f64 = 4.0;

/// The smallest factor (h slightly above 1 within the table's noise on
/// large bodies).
pub const MIN_FACTOR: f64 = 0.9;

/// The exit point's curvature κo and its factor f(κo)
/// ([`CurvatureCorrection::at_exit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ExitFactor {
    kappa: f32,
    f: [f32; 3],
}

/// One channel's data: A, d, ℓd, and h at the table's ρ nodes.
#[derive(Clone, Debug, PartialEq)]
struct Channel {
    albedo: f64,
    d: f64,
    /// The tabulated profile, if the sampler uses one (else the fit's).
    tabulated: Option<Arc<TabulatedProfile>>,
    ld: f64,
    h: Vec<f64>,
}

/// The correction of one material (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct CurvatureCorrection {
    table: &'static CurvatureTable,
    /// None for an inactive channel (factor 1).
    channels: [Option<Channel>; 3],
    rmax: f64,
    /// The longest active channel's ℓd: κ is tabulated as κ·ℓd.
    ld_max: f64,
    /// f per channel at κ·ℓd = 2^(LOG2_FIRST + j/STEPS_PER_OCTAVE),
    /// j = 0 … LUT_LEN − 1 ([`Self::exact_factor`] at the nodes).
    lut: Vec<[f32; 3]>,
    /// Whether [`Self::factor`] is [`Self::exact_factor`] (no table: a
    /// correction built per hit for textured parameters).
    exact: bool,
}

/// The lookup table's first node, κ·ℓd = 2^LOG2_FIRST (a sphere of 1024
/// diffusion lengths of the longest channel).
const LOG2_FIRST: f32 = -10.0;
/// 1 / 2^LOG2_FIRST.
const FIRST_NODE_INV: f32 = 1024.0;
/// Nodes per factor 2 in κ.
const STEPS_PER_OCTAVE: f32 = 16.0;
/// 2^-10 … 2^6 (a sphere of 1/64 ℓd, where f is at its clamp).
const LUT_LEN: usize = 16 * 16 + 1;

impl CurvatureCorrection {
    /// The correction for `params` sampled by `sampler` (its Rmax); None
    /// when the parameters record no medium. Err only if the embedded
    /// table does not load (a build defect; the message names the line).
    pub fn new(
        params: &SubsurfaceParams,
        sampler: &ProbeSampler,
    ) -> Result<Option<Self>, &'static TableError> {
        let Some(mut cc) = Self::new_exact(params, sampler)? else {
            return Ok(None);
        };
        cc.exact = false;
        let ld_max = cc.ld_max;
        if ld_max > 0.0 && ld_max.is_finite() {
            cc.lut = (0..LUT_LEN)
                .map(|j| {
                    let kl = (LOG2_FIRST + j as f32 / STEPS_PER_OCTAVE).exp2() as f64;
                    cc.exact_factor(kl / ld_max).map(|f| f as f32)
                })
                .collect();
        }
        Ok(Some(cc))
    }

    /// [`Self::new`] without the lookup table, cheap to build: its
    /// [`factor`](Self::factor) is [`exact_factor`](Self::exact_factor)
    /// (for parameters that change from hit to hit, `docs/bssrdf.md` §13).
    pub fn new_exact(
        params: &SubsurfaceParams,
        sampler: &ProbeSampler,
    ) -> Result<Option<Self>, &'static TableError> {
        let table = CurvatureTable::get()?;
        let Some(m) = params.medium else {
            return Ok(None);
        };
        let channels = std::array::from_fn(|c| {
            if !params.active(c) {
                return None;
            }
            let ss = m.sigma_s[c] * (1.0 - m.g);
            let sa = m.sigma_a[c];
            let alpha = ss / (ss + sa);
            // Media that absorb nothing clamp to the table's first x node.
            let x = (1.0 - alpha).max(0.0).sqrt();
            Some(Channel {
                albedo: params.albedo[c],
                d: params.d[c],
                tabulated: sampler.dist(c).and_then(|d| d.tabulated_profile().cloned()),
                ld: diffuse_mfp(ss, sa),
                h: table.row(x, params.eta as f64),
            })
        });
        let ld_max = channels
            .iter()
            .flatten()
            .map(|c: &Channel| c.ld)
            .fold(0.0, f64::max);
        Ok(Some(CurvatureCorrection {
            table,
            channels,
            rmax: sampler.rmax(),
            ld_max,
            lut: Vec::new(),
            exact: true,
        }))
    }

    /// f(κ) per channel from the lookup table: linear in log2 κ between
    /// nodes (relative error against [`Self::exact_factor`] below 2e-3,
    /// 1e-2 next to the clamp at [`MAX_FACTOR`]; tested), linear in κ from 1 at κ = 0 to the first node (the
    /// table's first-order tail), the last node beyond the last. Exactly
    /// 1 for κ ≤ 0 (and NaN). [`Self::exact_factor`] in f32 for a
    /// correction built by [`Self::new_exact`].
    pub fn factor(&self, kappa: f32) -> [f32; 3] {
        if self.exact {
            return self.exact_factor(kappa as f64).map(|f| f as f32);
        }
        let kl = kappa * self.ld_max as f32;
        if kl.is_nan() || kl <= 0.0 || self.lut.is_empty() {
            return [1.0; 3];
        }
        let t = (kl.log2() - LOG2_FIRST) * STEPS_PER_OCTAVE;
        if t <= 0.0 {
            // kl / 2^LOG2_FIRST ∈ (0, 1]
            let w = kl * FIRST_NODE_INV;
            return self.lut[0].map(|f| 1.0 + (f - 1.0) * w);
        }
        let last = LUT_LEN - 1;
        if t >= last as f32 {
            return self.lut[last];
        }
        let j = t as usize;
        let w = t - j as f32;
        let (a, b) = (self.lut[j], self.lut[j + 1]);
        std::array::from_fn(|c| a[c] + (b[c] - a[c]) * w)
    }

    /// f(κ) per channel, for a mean curvature κ (1/scene units), by the
    /// equations of the module docs; exactly 1 for κ ≤ 0 and inactive
    /// channels.
    pub fn exact_factor(&self, k: f64) -> [f64; 3] {
        if k.is_nan() || k <= 0.0 {
            return [1.0; 3];
        }
        std::array::from_fn(|c| match &self.channels[c] {
            None => 1.0,
            Some(ch) => {
                let radius = 1.0 / k;
                let h = self.table.at_rho(&ch.h, radius / ch.ld);
                let a_sphere = 1.0 - h * (1.0 - ch.albedo);
                let cdf = |r: f64| match &ch.tabulated {
                    Some(p) => p.cdf(r),
                    None => profile::cdf(r, ch.d),
                };
                let g = cdf((2.0 * radius).min(self.rmax)) / cdf(self.rmax);
                let f = a_sphere / (ch.albedo * g);
                if f.is_finite() {
                    f.clamp(MIN_FACTOR, MAX_FACTOR)
                } else {
                    MAX_FACTOR
                }
            }
        })
    }

    /// The factor of a probe hit from a point of curvature `kappa_o` to
    /// one of curvature `kappa_i`: √(f(κo)·f(κi)) per channel; None when
    /// both are ≤ 0 (the weight stays as it is, bit for bit).
    pub fn weight(&self, kappa_o: f32, kappa_i: f32) -> Option<Vec3> {
        self.weight_from(&self.at_exit(kappa_o), kappa_i)
    }

    /// The exit point's half of [`weight`](Self::weight): κo and f(κo),
    /// computed once for all the probes from one exit point (the
    /// antithetic pair's two; `crate::kernels`).
    pub(crate) fn at_exit(&self, kappa_o: f32) -> ExitFactor {
        ExitFactor {
            kappa: kappa_o,
            f: self.factor(kappa_o),
        }
    }

    /// [`weight`](Self::weight) from the exit point's [`at_exit`](Self::at_exit):
    /// the same value, bit for bit.
    pub(crate) fn weight_from(&self, exit: &ExitFactor, kappa_i: f32) -> Option<Vec3> {
        self.weight_from_factor(exit, kappa_i, self.factor(kappa_i))
    }

    /// [`at_exit`](Self::at_exit) with f(κo) already known (a cache of
    /// [`factor`](Self::factor)): the same value, bit for bit.
    pub(crate) fn at_exit_with(&self, kappa_o: f32, f_o: [f32; 3]) -> ExitFactor {
        ExitFactor {
            kappa: kappa_o,
            f: f_o,
        }
    }

    /// [`weight_from`](Self::weight_from) with f(κi) already known (`f_i`,
    /// a cache of [`factor`](Self::factor)): the same value, bit for bit.
    #[inline]
    pub(crate) fn weight_from_factor(
        &self,
        exit: &ExitFactor,
        kappa_i: f32,
        f_i: [f32; 3],
    ) -> Option<Vec3> {
        if !(exit.kappa > 0.0 || kappa_i > 0.0) {
            return None;
        }
        let (fo, fi) = (exit.f, f_i);
        Some(Vec3::new(
            (fo[0] * fi[0]).sqrt(),
            (fo[1] * fi[1]).sqrt(),
            (fo[2] * fi[2]).sqrt(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::{Fit, ProbeOptions};

    fn marble(scale: f64) -> (SubsurfaceParams, CurvatureCorrection) {
        let p = SubsurfaceParams::from_preset("marble", scale, Fit::Searchlight).unwrap();
        let s = ProbeSampler::new(&p, &ProbeOptions::default()).unwrap();
        (p, CurvatureCorrection::new(&p, &s).unwrap().unwrap())
    }

    #[test]
    fn flat_and_concave_surfaces_are_untouched() {
        let (_, cc) = marble(1.0);
        assert_eq!(cc.factor(0.0), [1.0; 3]);
        assert_eq!(cc.factor(-0.3), [1.0; 3]);
        assert_eq!(cc.factor(f32::NAN), [1.0; 3]);
        assert_eq!(cc.weight(0.0, 0.0), None);
        assert_eq!(cc.weight(-1.0, 0.0), None);
        // a curvature far below 1/ℓd: f → 1 continuously
        let f = cc.factor(1e-7);
        assert!(f.iter().all(|&v| (v - 1.0).abs() < 1e-4), "{f:?}");
    }

    /// On a sphere f is what turns the estimator's mean A·g(R) into the
    /// table's A_sphere, it exceeds 1 and grows as the sphere shrinks, and
    /// the hit's factor is symmetric in xo and xi.
    #[test]
    fn factor_restores_the_sphere_albedo() {
        let (p, cc) = marble(1.0);
        let t = CurvatureTable::get().unwrap();
        let m = p.medium.unwrap();
        let ld: [f64; 3] = std::array::from_fn(|c| diffuse_mfp(m.sigma_s[c], m.sigma_a[c]));
        let ld_max = ld.iter().cloned().fold(0.0, f64::max);
        let mut prev = [0.0; 3];
        for k in [4.0, 1.0, 0.25] {
            let radius = k * ld_max;
            let f = cc.exact_factor(1.0 / radius);
            for c in 0..3 {
                let alpha = m.sigma_s[c] / (m.sigma_s[c] + m.sigma_a[c]);
                let h = t.h(radius / ld[c], (1.0 - alpha).sqrt(), p.eta as f64);
                let want = 1.0 - h * (1.0 - p.albedo[c]);
                let mean = p.albedo[c] * profile::cdf((2.0 * radius).min(cc.rmax), p.d[c])
                    / profile::cdf(cc.rmax, p.d[c]);
                let got = mean * f[c];
                if f[c] < MAX_FACTOR {
                    assert!(
                        (got - want).abs() < 1e-4 * want,
                        "k {k} c {c}: {got} vs {want}"
                    );
                }
                assert!(
                    f[c] > 1.0 && f[c] > prev[c],
                    "k {k} c {c}: {f:?} after {prev:?}"
                );
            }
            prev = f;
        }
        let w = cc.weight(0.3, 0.05).unwrap();
        assert_eq!(w, cc.weight(0.05, 0.3).unwrap());
        let (fo, fi) = (cc.factor(0.3), cc.factor(0.05));
        assert!((w.x - (fo[0] * fi[0]).sqrt()).abs() < 1e-6);
    }

    /// A hit between a flat or concave point (f = 1) and a convex one (f >
    /// 1), e.g. from the flat base of a dome onto the dome, carries √f of
    /// the convex point, whichever end is xo.
    #[test]
    fn a_hit_between_a_flat_and_a_convex_point_carries_the_root_of_one_factor() {
        let (_, cc) = marble(1.0);
        let k = 0.3;
        let f = cc.factor(k);
        assert!(f.iter().all(|&v| v > 1.0), "{f:?}");
        let want = Vec3::new(f[0].sqrt(), f[1].sqrt(), f[2].sqrt());
        for flat in [0.0, -0.5] {
            for w in [cc.weight(flat, k), cc.weight(k, flat)] {
                let w = w.expect("a convex end must change the weight");
                assert!((w - want).abs().max_element() < 1e-6, "{w} vs {want}");
            }
        }
    }

    /// The lookup the renderer uses against the equations, over curvatures
    /// from a sphere of 10⁵ diffusion lengths to one of 1/100, for two
    /// materials (marble, skin1) at two scales.
    #[test]
    fn the_lookups_tail_follows_the_exact_factor_to_first_order() {
        // Below the table's first node (bodies over 1024 diffusion lengths)
        // f − 1 is first order in κ, and the lookup is linear from 1: it
        // must match the exact factor's deviation from 1 to 1 % of itself
        // (f − 1 is 1.5e-5 … 1.7e-3 there over the presets, below the
        // interpolation tolerance of the test below, so that test cannot
        // see the tail's sign or slope).
        for name in ["marble", "skin1", "ketchup", "wholemilk"] {
            let p = SubsurfaceParams::from_preset(name, 1.0, Fit::Searchlight).unwrap();
            let s = ProbeSampler::new(&p, &ProbeOptions::default()).unwrap();
            let cc = CurvatureCorrection::new(&p, &s).unwrap().unwrap();
            for frac in [0.1, 0.37, 0.5, 0.93] {
                let k = frac * 2f64.powi(-10) / cc.ld_max;
                let (got, want) = (cc.factor(k as f32), cc.exact_factor(k));
                for c in 0..3 {
                    let dev = want[c] - 1.0;
                    assert!(dev > 0.0, "{name} ch{c}: f − 1 = {dev}");
                    assert!(
                        (got[c] as f64 - want[c]).abs() <= 0.01 * dev + 2e-7,
                        "{name} κℓd {:e} ch{c}: {} vs {}",
                        frac * 2f64.powi(-10),
                        got[c],
                        want[c]
                    );
                }
            }
        }
    }

    #[test]
    fn lookup_matches_the_exact_factor() {
        for (name, scale) in [("marble", 1.0), ("skin1", 1.0), ("skin1", 0.01)] {
            let p = SubsurfaceParams::from_preset(name, scale, Fit::Searchlight).unwrap();
            let s = ProbeSampler::new(&p, &ProbeOptions::default()).unwrap();
            let cc = CurvatureCorrection::new(&p, &s).unwrap().unwrap();
            let mut worst = 0.0f64;
            for i in 0..=2000 {
                let kl = 10f64.powf(-5.0 + 7.0 * i as f64 / 2000.0);
                let k = kl / cc.ld_max;
                let (got, want) = (cc.factor(k as f32), cc.exact_factor(k));
                for c in 0..3 {
                    let e = (got[c] as f64 / want[c] - 1.0).abs();
                    // Next to the clamp at MAX_FACTOR f has a kink that
                    // linear interpolation rounds off: 1 % there.
                    if want[c] > 0.9 * MAX_FACTOR {
                        assert!(e < 1e-2, "{name}: κℓd {kl:e} ch{c}: {got:?} vs {want:?}");
                    } else {
                        worst = worst.max(e);
                    }
                }
            }
            assert!(worst < 2e-3, "{name} at {scale}: {worst}");
        }
    }

    /// The exit half computed once gives the same weight as `weight`, bit
    /// for bit, including the flat and concave cases where it is None.
    #[test]
    fn weight_from_the_exit_half_is_weight() {
        let (_, cc) = marble(1.0);
        let ks = [-1.0f32, 0.0, 1e-7, 0.01, 0.1, 0.5, 1.0, 3.0, 40.0, f32::NAN];
        for &ko in &ks {
            let exit = cc.at_exit(ko);
            for &ki in &ks {
                // √(f(κo)·f(κi)) per channel, None where neither is convex
                let want = (ko > 0.0 || ki > 0.0).then(|| {
                    let (fo, fi) = (cc.factor(ko), cc.factor(ki));
                    Vec3::from_array(std::array::from_fn(|c| (fo[c] * fi[c]).sqrt()))
                });
                let got = cc.weight_from(&exit, ki);
                assert_eq!(got, cc.weight(ko, ki));
                // and from cached factors (the integrator's per-triangle cache)
                let cached = cc.at_exit_with(ko, cc.factor(ko));
                let from_cache = cc.weight_from_factor(&cached, ki, cc.factor(ki));
                assert_eq!(
                    from_cache.map(|v| v.to_array().map(f32::to_bits)),
                    got.map(|v| v.to_array().map(f32::to_bits))
                );
                assert_eq!(
                    got.map(|v| v.to_array().map(f32::to_bits)),
                    want.map(|v| v.to_array().map(f32::to_bits)),
                    "{ko} {ki}"
                );
            }
        }
        // and it is not a constant: the exit point's curvature counts
        let a = cc.weight_from(&cc.at_exit(0.1), 0.1).unwrap();
        let b = cc.weight_from(&cc.at_exit(1.0), 0.1).unwrap();
        assert_ne!(a, b);
    }
}
