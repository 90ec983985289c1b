//! Random numbers and the warps that turn them into directions and points,
//! plus the multiple-importance-sampling heuristics (Veach 1997, ch. 9).

pub mod rng;

pub use rng::Rng;

use crate::geometry::Vec3;
use std::f32::consts::PI;

/// Cosine-weighted direction about +z; pdf = cos θ / π.
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let [x, y] = concentric_disk(u);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    Vec3::new(x, y, z)
}

pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) / PI
}

/// Uniform point on the unit disk, area-preserving (Shirley & Chiu 1997).
pub fn concentric_disk(u: [f32; 2]) -> [f32; 2] {
    let a = 2.0 * u[0] - 1.0;
    let b = 2.0 * u[1] - 1.0;
    if a == 0.0 && b == 0.0 {
        return [0.0, 0.0];
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, (PI / 4.0) * (b / a))
    } else {
        (b, PI / 2.0 - (PI / 4.0) * (a / b))
    };
    [r * phi.cos(), r * phi.sin()]
}

/// Uniform barycentrics (b1, b2) on a triangle.
pub fn uniform_triangle(u: [f32; 2]) -> [f32; 2] {
    let su = u[0].sqrt();
    [1.0 - su, u[1] * su]
}

/// Uniform direction on the unit sphere; pdf = 1 / 4π.
pub fn uniform_sphere(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Balance heuristic weight of strategy f against g (one sample each).
pub fn balance(f_pdf: f32, g_pdf: f32) -> f32 {
    if f_pdf + g_pdf > 0.0 {
        f_pdf / (f_pdf + g_pdf)
    } else {
        0.0
    }
}

/// Power heuristic (β = 2) weight of strategy f against g.
pub fn power(f_pdf: f32, g_pdf: f32) -> f32 {
    let (f, g) = (f_pdf * f_pdf, g_pdf * g_pdf);
    if f.is_infinite() {
        return 1.0;
    }
    if f + g > 0.0 {
        f / (f + g)
    } else {
        0.0
    }
}

/// A discrete distribution over weights, sampled by inverse CDF.
#[derive(Clone, Debug, Default)]
pub struct Distribution1D {
    cdf: Vec<f64>,
    total: f64,
}

impl Distribution1D {
    pub fn new(weights: &[f64]) -> Self {
        let mut cdf = Vec::with_capacity(weights.len());
        let mut acc = 0.0;
        for &w in weights {
            acc += w.max(0.0);
            cdf.push(acc);
        }
        Distribution1D { cdf, total: acc }
    }
    pub fn is_empty(&self) -> bool {
        self.total <= 0.0
    }
    pub fn total(&self) -> f64 {
        self.total
    }
    /// Returns (index, probability of that index).
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let i = self.sample_index(u);
        (i, self.pmf(i))
    }
    /// The index alone, for callers that stored its probability.
    #[inline]
    pub fn sample_index(&self, u: f32) -> usize {
        let target = u as f64 * self.total;
        self.cdf
            .partition_point(|&c| c <= target)
            .min(self.cdf.len() - 1)
    }
    pub fn pmf(&self, i: usize) -> f32 {
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        ((self.cdf[i] - lo) / self.total) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_hemisphere_matches_its_pdf() {
        // chi-square over cos θ bins: P(cos θ in [a,b]) = b² − a²
        let mut r = Rng::from_key(1);
        let bins = 20;
        let n = 200_000;
        let mut c = vec![0f64; bins];
        for _ in 0..n {
            let d = cosine_hemisphere(r.uniform2());
            assert!(d.z >= 0.0 && (d.length() - 1.0).abs() < 1e-5);
            c[((d.z * bins as f32) as usize).min(bins - 1)] += 1.0;
        }
        let chi2: f64 = (0..bins)
            .map(|i| {
                let (a, b) = (i as f64 / bins as f64, (i + 1) as f64 / bins as f64);
                let e = n as f64 * (b * b - a * a);
                (c[i] - e).powi(2) / e
            })
            .sum();
        assert!(chi2 < 45.0, "chi2 {chi2}"); // 19 dof, p ≈ 1e-3
    }

    #[test]
    fn distribution_samples_proportionally() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        assert_eq!(d.sample(0.0).0, 0);
        assert_eq!(d.sample(0.3).0, 2);
        assert!((d.pmf(2) - 0.75).abs() < 1e-7);
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(d.sample(0.999_999).0, 2);
    }
}
