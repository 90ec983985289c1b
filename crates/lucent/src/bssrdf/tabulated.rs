//! The tabulated diffusion profile of one channel: the half-space's
//! transfer by the random walk ([`super::profile_table`]) in place of the
//! normalized-diffusion fit, in scene units (`docs/bssrdf.md` §10, "Where
//! the light leaves").
//!
//! The radial density 2πr·R(r) is constant within each bin of the table,
//! so R(r) ∝ 1/r inside a bin (the fit's behaviour at r → 0), the CDF is
//! piecewise linear and its inverse exact: a radius sampled from it has
//! the density R itself, and the probe's weight Rd/p stays what it is
//! with the fit. ∫R 2πr dr = 1, so A·R reflects A under uniform light.

use std::f64::consts::PI;

use super::params::{diffuse_mfp, Medium};
use super::profile_table::ProfileTable;

/// One channel's tabulated R(r).
#[derive(Clone, Debug, PartialEq)]
pub struct TabulatedProfile {
    /// Bin edges (scene units), from 0, increasing.
    edges: Vec<f64>,
    /// The mass within each edge: `cum[0] = 0`, the last is 1.
    cum: Vec<f64>,
    /// The radial density dCDF/dr in each bin (1/scene units).
    dens: Vec<f64>,
}

impl TabulatedProfile {
    /// From a table row's shares over bins `edges_u` of u = r/ℓd, for a
    /// diffusion length `ld` (scene units).
    pub fn new(shares: &[f64], edges_u: &[f64], ld: f64) -> Self {
        let edges: Vec<f64> = edges_u.iter().map(|u| u * ld).collect();
        let total: f64 = shares.iter().sum();
        let mut cum = vec![0.0];
        let mut dens = Vec::with_capacity(shares.len());
        for (k, s) in shares.iter().enumerate() {
            let s = s / total;
            dens.push(s / (edges[k + 1] - edges[k]));
            cum.push(cum[k] + s);
        }
        let last = cum.len() - 1;
        cum[last] = 1.0;
        TabulatedProfile { edges, cum, dens }
    }

    /// Channel `c` of `medium` (scene units) behind index `eta`, from the
    /// embedded table; None for a channel that scatters nothing.
    pub fn for_channel(table: &ProfileTable, medium: &Medium, c: usize, eta: f64) -> Option<Self> {
        let ss = medium.sigma_s[c] * (1.0 - medium.g);
        let sa = medium.sigma_a[c];
        if ss.is_nan() || ss <= 0.0 {
            return None;
        }
        let ld = diffuse_mfp(ss, sa);
        // Media that absorb nothing clamp to the table's first x node.
        let x = (sa / (ss + sa)).max(0.0).sqrt();
        ld.is_finite()
            .then(|| TabulatedProfile::new(&table.row(x, eta), &table.edges, ld))
    }

    /// The bin holding r (clamped to the table).
    #[inline]
    fn bin(&self, r: f64) -> usize {
        let n = self.dens.len();
        self.edges.partition_point(|&e| e <= r).clamp(1, n) - 1
    }

    /// The mass within radius r.
    pub fn cdf(&self, r: f64) -> f64 {
        if r.is_nan() || r <= 0.0 {
            return 0.0;
        }
        if r >= self.reach() {
            return 1.0;
        }
        let k = self.bin(r);
        self.cum[k] + self.dens[k] * (r - self.edges[k])
    }

    /// R(r) per unit area, 0 beyond the table; r > 0.
    #[inline]
    pub fn profile(&self, r: f64) -> f64 {
        if r.is_nan() || r >= self.reach() {
            return 0.0;
        }
        self.dens[self.bin(r)] / (2.0 * PI * r)
    }

    /// The radius holding mass ξ ∈ [0, 1]: the exact inverse of
    /// [`cdf`](Self::cdf), never inside a bin of zero mass.
    pub fn inverse_cdf(&self, xi: f64) -> f64 {
        let n = self.dens.len();
        // the first edge whose mass exceeds ξ closes the bin holding it
        let k = self.cum.partition_point(|&c| c <= xi).clamp(1, n) - 1;
        if self.dens[k] <= 0.0 {
            return self.edges[k];
        }
        (self.edges[k] + (xi - self.cum[k]) / self.dens[k]).min(self.edges[k + 1])
    }

    /// The table's last edge: R is 0 beyond it.
    pub fn reach(&self) -> f64 {
        self.edges[self.edges.len() - 1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::radius::RadialDist;
    use std::sync::Arc;

    /// Shares over four bins of u, the second empty.
    fn small() -> TabulatedProfile {
        TabulatedProfile::new(&[0.5, 0.0, 0.3, 0.2], &[0.0, 0.1, 0.5, 2.0, 6.0], 3.0)
    }

    /// The inverse CDF inverts the CDF, and never lands inside the empty
    /// bin: a sampler that did would put entry points where R is 0.
    #[test]
    fn inverse_cdf_inverts_the_cdf_and_skips_empty_bins() {
        let p = small();
        for k in 0..=1000 {
            let xi = k as f64 / 1000.0;
            let r = p.inverse_cdf(xi);
            assert!(
                (p.cdf(r) - xi).abs() < 1e-12,
                "ξ {xi}: r {r}, cdf {}",
                p.cdf(r)
            );
            assert!(!(r > 0.3 && r < 1.5), "ξ {xi}: r {r} in the empty bin");
        }
        assert_eq!(p.cdf(0.0), 0.0);
        assert_eq!(p.cdf(100.0), 1.0);
        assert_eq!(p.reach(), 18.0);
        assert_eq!(p.profile(18.0), 0.0);
    }

    /// ∫R 2πr dr = 1 and R = (share / bin width)/(2πr) inside a bin: the
    /// profile a probe weighs is the density it samples.
    #[test]
    fn profile_integrates_to_one_and_falls_as_one_over_r_in_a_bin() {
        let p = small();
        let n = 400_000;
        let total: f64 = (0..n)
            .map(|i| {
                let r = p.reach() * (i as f64 + 0.5) / n as f64;
                p.profile(r) * 2.0 * PI * r * p.reach() / n as f64
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-4, "{total}");
        let (a, b) = (2.0, 5.0); // both in the third bin, [1.5, 6) scene units
        assert!((p.profile(a) * a - p.profile(b) * b).abs() < 1e-15);
        assert!((p.profile(a) * 2.0 * PI * a - 0.3 / 4.5).abs() < 1e-12);
    }

    /// As a radius distribution truncated at Rmax: the disk pdf integrates
    /// to 1 within Rmax, the mass kept is the CDF there, and every sample
    /// lies within Rmax.
    #[test]
    fn a_truncated_tabulated_distribution_is_normalized() {
        let p = Arc::new(small());
        let rmax = 4.0;
        let dist = RadialDist::tabulated(p.clone(), 0.1, rmax).unwrap();
        assert!((dist.profile_mass() - p.cdf(rmax)).abs() < 1e-15);
        let n = 400_000;
        let m: f64 = (0..n)
            .map(|i| {
                let r = rmax * (i as f64 + 0.5) / n as f64;
                dist.pdf(r) * 2.0 * PI * r * rmax / n as f64
            })
            .sum();
        assert!((m - 1.0).abs() < 1e-4, "{m}");
        for k in 0..1000 {
            let r = dist.sample_radius(k as f64 / 1000.0);
            assert!(r <= rmax && r > 0.0, "{r}");
        }
    }

    /// Marble's red channel (η = 1.5, x ≈ 0.03): the walk's profile holds
    /// the same total but sends far more light beyond one diffusion length
    /// than the normalized-diffusion fit with d = ℓd/s(A) — the tail a key
    /// light's far side lives on (`docs/bssrdf.md` §10).
    #[test]
    fn marble_reaches_farther_than_the_fit() {
        let p = crate::bssrdf::SubsurfaceParams::from_preset(
            "marble",
            1.0,
            crate::bssrdf::Fit::Searchlight,
        )
        .unwrap();
        let m = p.medium.unwrap();
        let table = ProfileTable::get().unwrap();
        let t = TabulatedProfile::for_channel(table, &m, 0, p.eta as f64).unwrap();
        let ld = diffuse_mfp(m.sigma_s[0] * (1.0 - m.g), m.sigma_a[0]);
        for k in [1.0, 2.0] {
            let walk = 1.0 - t.cdf(k * ld);
            let fit = 1.0 - crate::bssrdf::profile::cdf(k * ld, p.d[0]);
            assert!(walk > 2.0 * fit, "beyond {k} ld: walk {walk}, fit {fit}");
        }
    }
}
