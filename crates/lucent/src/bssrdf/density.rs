//! The probe estimator's density and profile at one entry point, per
//! channel c (`docs/bssrdf.md` §5; pbrt-v3 `Pdf_Sp`):
//!
//!   p_c(xi) = Σ_a P(a) |V_a·N(xi)| p_disk,c(r_a),   Rd_c(|xo − xi|) = A_c R_c(|xo − xi|),
//!
//! with r_a the radius of xi − xo projected ⟂ the axis V_a. This is the one
//! evaluation the renderer uses, for every sampler; the f64 transcription in
//! [`super::probe`]'s tests is its oracle. The four radii of a hit sit in
//! the lanes of one `Vec4`, so each channel's profile costs one [`exp4`]
//! ([`crate::kernels`]). The layout and the precision argument (the MIS
//! density never underflows): `docs/bssrdf.md` §12.6.

use glam::Vec4;

use super::profile::RHO_MIN;
use super::radius::{RadialDist, RadiusSampler};
use crate::kernels::exp4;

/// How a channel's disk density is formed, scaled by L².
#[derive(Clone, Debug)]
enum Disk {
    /// The exact samplers: L²·p_disk(r) = k (e^{−ρ} + e^{−ρ/3}) / (r/L),
    /// k = L/(8π d CDF(Rmax)) (0 for an inactive channel).
    Profile(f32),
    /// The uniform sampler: L²/(π Rmax²).
    Constant(f32),
    /// A table sampler: L² times its density at the scene-unit radius.
    Table(RadialDist),
    /// The tabulated profile (`super::tabulated`): the density as for
    /// `Table`, and Rd from the same table.
    Tabulated(RadialDist),
}

/// Per-material constants of the density, lengths in units of L.
#[derive(Clone, Debug)]
pub(crate) struct ProbeDensity {
    /// L and 1/L in scene units.
    len: f64,
    inv_len: f64,
    /// Rmax in scene units.
    rmax_scene: f64,
    /// Rmax / L in the three disk-radius lanes, ∞ in the distance lane
    /// (the clamp of the radii; the lanes are built once, not per hit).
    rmax: Vec4,
    /// Per channel, in every lane: −1/(3 d/L), the exponent's scale.
    neg_inv3d: [Vec4; 3],
    /// Per channel, in every lane: RHO_MIN·d/L, the radius clamp of
    /// `profile::profile`; 1 for an inactive channel so it never divides
    /// by 0.
    rmin: [Vec4; 3],
    disk: [Disk; 3],
    /// Per channel: L²·Rd(r)·r/(e^{−ρ} + e^{−ρ/3}) = scale·L/(8π d).
    k_rd: [f32; 3],
    /// Per channel: A, or A/CDF(Rmax) (L²·scale for a tabulated profile).
    scale_l2: [f64; 3],
}

impl ProbeDensity {
    /// `d` and `scale` (A, or A/CDF(Rmax)) per channel, `dists` the radius
    /// distributions of the active channels (None for inactive ones), all
    /// from `sampler`, truncated at `rmax`.
    pub fn new(
        sampler: RadiusSampler,
        d: [f64; 3],
        scale: [f64; 3],
        dists: &[Option<RadialDist>; 3],
        rmax: f64,
    ) -> Self {
        let active: [bool; 3] = std::array::from_fn(|c| dists[c].is_some());
        let len = (0..3)
            .filter(|&c| active[c])
            .map(|c| d[c])
            .fold(0.0, f64::max);
        // no active channel: nothing is ever weighed; any length will do
        let len = if len > 0.0 && len.is_finite() {
            len
        } else {
            1.0
        };
        let per = |f: &dyn Fn(usize) -> f64, off: f32| -> [f32; 3] {
            std::array::from_fn(|c| if active[c] { f(c) as f32 } else { off })
        };
        let pi8 = 8.0 * std::f64::consts::PI;
        let k_pdf = per(
            &|c| len / (pi8 * d[c] * dists[c].as_ref().map_or(0.0, |d| d.profile_mass())),
            0.0,
        );
        let disk = std::array::from_fn(|c| match (&dists[c], sampler) {
            (Some(dist), _) if dist.tabulated_profile().is_some() => Disk::Tabulated(dist.clone()),
            (Some(dist), RadiusSampler::Uniform) => {
                Disk::Constant((len * len * dist.pdf(0.0)) as f32)
            }
            (Some(dist), RadiusSampler::Table { .. }) => Disk::Table(dist.clone()),
            _ => Disk::Profile(k_pdf[c]),
        });
        ProbeDensity {
            len,
            inv_len: 1.0 / len,
            rmax_scene: rmax,
            rmax: {
                let r = (rmax / len) as f32;
                Vec4::new(r, r, r, f32::INFINITY)
            },
            neg_inv3d: per(&|c| len / (3.0 * d[c]), 0.0).map(|v| Vec4::splat(-v)),
            rmin: per(&|c| RHO_MIN * d[c] / len, 1.0).map(Vec4::splat),
            disk,
            k_rd: per(&|c| scale[c] * len / (pi8 * d[c]), 0.0),
            scale_l2: scale.map(|s| s * len * len),
        }
    }

    /// The weights Rd_c(|xo − xi|)/p(xi) per channel, before the hit count,
    /// for an entry point at `local` = (xi − xo) in the shading frame
    /// (T, B, N, scene units), with `cos` = |V_a·N(xi)| and `probs` = P(a)
    /// per axis (T, B, N). p is the sampled channel's p_c when `single` is
    /// Some(c) (the others then weigh 0), else the balance heuristic
    /// Σ_c p_c / n_active. None when p is 0, not finite, or so small that
    /// 1/p overflows.
    #[inline]
    pub fn weights(
        &self,
        local: [f64; 3],
        cos: [f32; 3],
        probs: [f32; 3],
        single: Option<usize>,
        n_active: usize,
    ) -> Option<[f32; 3]> {
        let [x, y, z] = local.map(|v| v * self.inv_len);
        let (x2, y2, z2) = (x * x, y * y, z * z);
        // Lanes: disk radius ⟂ T, ⟂ B, ⟂ N, then the 3D distance. Rounding
        // can put a hit just outside the sphere; the disk radii are kept on
        // the disk so the sampled axis never scores 0.
        let r2 = [y2 + z2, x2 + z2, x2 + y2, x2 + y2 + z2].map(|v| (v as f32).sqrt());
        let r = Vec4::from_array(r2).min(self.rmax);
        // P(a) |V_a·N| per axis lane
        let w = Vec4::new(probs[0] * cos[0], probs[1] * cos[1], probs[2] * cos[2], 0.0);
        let mut pdf = [0.0f32; 3];
        let mut rd = [0.0f32; 3];
        for c in 0..3 {
            // (e^{−ρ} + e^{−ρ/3}) / (r/L) in each lane: R up to its constant
            let rc = r.max(self.rmin[c]);
            let e = exp4(rc * self.neg_inv3d[c]);
            let v = (e * e * e + e) / rc;
            pdf[c] = match &self.disk[c] {
                Disk::Profile(k) => k * w.dot(v),
                Disk::Constant(k) => k * (w.x + w.y + w.z),
                Disk::Table(dist) | Disk::Tabulated(dist) => w.dot(self.table_lanes(dist, local)),
            };
            rd[c] = match &self.disk[c] {
                Disk::Tabulated(dist) => {
                    let dist3 =
                        (local[0] * local[0] + local[1] * local[1] + local[2] * local[2]).sqrt();
                    (self.scale_l2[c] * dist.profile_at(dist3)) as f32
                }
                _ => self.k_rd[c] * v.w,
            };
        }
        let p = match single {
            Some(ch) => pdf[ch],
            None => pdf[0] + pdf[1] + pdf[2],
        } / n_active as f32;
        if !(p > 0.0 && p.is_finite()) {
            return None;
        }
        // A subnormal p (only in the underflowing tails, module docs) has no
        // finite reciprocal.
        let inv = 1.0 / p;
        if inv == f32::INFINITY {
            return None;
        }
        Some(match single {
            Some(ch) => std::array::from_fn(|c| if c == ch { rd[c] * inv } else { 0.0 }),
            None => rd.map(|v| v * inv),
        })
    }

    /// L²·p_disk(r_a) of a table sampler in the three axis lanes (0 in the
    /// distance lane), from the scene-unit disk radii in f64.
    fn table_lanes(&self, dist: &RadialDist, local: [f64; 3]) -> Vec4 {
        let sq = local.map(|v| v * v);
        let lane = |a: usize| {
            let r_a = (sq[(a + 1) % 3] + sq[(a + 2) % 3])
                .sqrt()
                .min(self.rmax_scene);
            (self.len * self.len * dist.pdf(r_a)) as f32
        };
        Vec4::new(lane(0), lane(1), lane(2), 0.0)
    }
}
