//! The f64 oracle of the probe density and weights (test builds only).

use glam::DVec3;

use super::ProbeSampler;
use crate::geometry::Frame;

/// The f64 transcription of the density and weights, term by term from the
/// module docs with libm's `exp`: the oracle of [`ProbeDensity`]'s f32
/// lanes.
impl ProbeSampler {
    /// Per channel, the surface-area density with which a probe sampled for
    /// that channel lands on xi (normal `n_hit`), summed over axes with
    /// their probabilities (pbrt-v3 `Pdf_Sp` without the channel sum).
    /// Inactive channels give 0.
    pub(super) fn pdf_area_d(&self, d: DVec3, frame: &Frame, kappa: f32, n_hit: DVec3) -> [f64; 3] {
        let per_axis = self.pdf_area_axes(d, frame, kappa, n_hit);
        std::array::from_fn(|c| per_axis.iter().map(|p| p[c]).sum())
    }

    /// [`pdf_area_d`](Self::pdf_area_d)'s terms, axis by axis (T, B, N):
    /// P(a) p_c(r_a) |V_a·N| per channel c.
    pub(super) fn pdf_area_axes(
        &self,
        d: DVec3,
        frame: &Frame,
        kappa: f32,
        n_hit: DVec3,
    ) -> [[f64; 3]; 3] {
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
    pub(super) fn weights_f64(
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
        let w = |c: usize| {
            (self.scale[c] * self.dists[c].as_ref().map_or(0.0, |d| d.profile_at(dist3)) / p) as f32
        };
        Some(match self.single(ch) {
            Some(ch) => std::array::from_fn(|c| if c == ch { w(c) } else { 0.0 }),
            None => std::array::from_fn(w),
        })
    }
}
