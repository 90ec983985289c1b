//! Random numbers and the warps that turn them into directions and points,
//! plus the multiple-importance-sampling heuristics (Veach 1997, ch. 9).

mod mix;
pub mod rng;
pub mod sampler;
pub mod sobol;

pub use rng::{Draw, Rng, SampleRng};
pub use sampler::SamplerKind;

use crate::geometry::Vec3;
use std::f32::consts::PI;

/// The luminance of linear Rec. 709 RGB: what the light distributions
/// weigh emitters and environment texels by.
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Cosine-weighted direction about +z; pdf = cos θ / π.
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let [x, y] = concentric_disk(u);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    Vec3::new(x, y, z)
}

pub(crate) fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) / PI
}

/// Uniform point on the unit disk, area-preserving (Shirley & Chiu 1997).
pub(crate) fn concentric_disk(u: [f32; 2]) -> [f32; 2] {
    let a = 2.0 * u[0] - 1.0;
    let b = 2.0 * u[1] - 1.0;
    if a == 0.0 && b == 0.0 {
        return [0.0, 0.0];
    }
    // Both wedges need an angle within π/4 of an axis: the second is
    // π/2 − x, whose cosine and sine are sin x and cos x.
    if a.abs() > b.abs() {
        let (s, c) = sin_cos_quarter((PI / 4.0) * (b / a));
        [a * c, a * s]
    } else {
        let (s, c) = sin_cos_quarter((PI / 4.0) * (a / b));
        [b * s, b * c]
    }
}

/// (sin x, cos x) for |x| ≤ π/4 (a little beyond is fine), from the
/// minimax polynomials of Cephes `sinf`/`cosf`: within 2 ulp of the true
/// values there. The samplers only need angles in this range or whole
/// turns ([`sin_cos_turns`]), and libm's general `sincosf` (argument
/// reduction for any float) is a visible share of the time outside ray
/// queries.
#[inline]
pub(crate) fn sin_cos_quarter(x: f32) -> (f32, f32) {
    let z = x * x;
    let s = x + x * z * ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1);
    let c = 1.0 - 0.5 * z + z * z * ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2);
    (s, c)
}

/// (sin 2πu, cos 2πu) for u ∈ [0, 1): the angle is split into a quarter
/// turn k and a remainder within π/4 of it, both exact in f32 (4u is a
/// power-of-two scaling and q − k cancels exactly), so the only rounding
/// before the polynomials is that of the remainder times π/2 — less than
/// that of forming 2πu in f32.
#[inline]
pub(crate) fn sin_cos_turns(u: f32) -> (f32, f32) {
    let q = 4.0 * u;
    // u ≥ 0, so truncating q + ½ rounds to the nearest quarter turn.
    let k = (q + 0.5) as i32;
    let (s, c) = sin_cos_quarter((q - k as f32) * (PI / 2.0));
    match k & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
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
    let (sin, cos) = sin_cos_turns(u[1]);
    Vec3::new(r * cos, r * sin, z)
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
    pub(crate) fn sample_index(&self, u: f32) -> usize {
        let target = u as f64 * self.total;
        // The first entry above target (the cdf never decreases); a scan
        // beats the binary search on the few entries of a typical light set
        // (a quad light has two).
        let i = if self.cdf.len() <= 8 {
            self.cdf
                .iter()
                .position(|&c| c > target)
                .unwrap_or(self.cdf.len())
        } else {
            self.cdf.partition_point(|&c| c <= target)
        };
        i.min(self.cdf.len() - 1)
    }
    pub(crate) fn pmf(&self, i: usize) -> f32 {
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
    fn polynomial_sin_cos_match_f64_to_a_few_ulp() {
        // Every float in [−π/4, π/4] would be 2e9 cases; a dense grid of 4M
        // plus the ends covers the polynomials' error curve.
        let n = 1 << 22;
        let lim = std::f32::consts::FRAC_PI_4;
        let mut worst = [0f64; 2];
        for i in 0..=n {
            let x = -lim + 2.0 * lim * (i as f32 / n as f32);
            let (s, c) = sin_cos_quarter(x);
            let (ts, tc) = (x as f64).sin_cos();
            // in ulps of the true value (f32 ulp of |v| ≥ 2^-24·|v|)
            let ulp = |v: f64| v.abs().max(1e-30) * f32::EPSILON as f64 / 2.0;
            worst[0] = worst[0].max((s as f64 - ts).abs() / ulp(ts));
            worst[1] = worst[1].max((c as f64 - tc).abs() / ulp(tc));
        }
        assert!(
            worst[0] <= 4.0 && worst[1] <= 4.0,
            "worst ulp error {worst:?}"
        );
        assert_eq!(sin_cos_quarter(0.0), (0.0, 1.0));
    }

    #[test]
    fn whole_turn_sin_cos_match_f64() {
        // u on a dense grid and at the quarter-turn boundaries; absolute
        // error against sin/cos of 2πu in f64, and the point stays on the
        // unit circle.
        let n = 1 << 22;
        let mut us: Vec<f32> = (0..n).map(|i| i as f32 / n as f32).collect();
        for q in 0..4 {
            let b = q as f32 * 0.25 + 0.125;
            us.extend([
                b,
                f32::from_bits(b.to_bits() - 1),
                f32::from_bits(b.to_bits() + 1),
            ]);
        }
        us.push(f32::from_bits(1f32.to_bits() - 1)); // the largest u < 1
        let mut worst = 0f64;
        let mut worst_norm = 0f64;
        for u in us {
            let (s, c) = sin_cos_turns(u);
            let (ts, tc) = (2.0 * std::f64::consts::PI * u as f64).sin_cos();
            worst = worst.max((s as f64 - ts).abs()).max((c as f64 - tc).abs());
            worst_norm = worst_norm.max(((s as f64).powi(2) + (c as f64).powi(2) - 1.0).abs());
        }
        assert!(worst < 2e-7, "worst absolute error {worst}");
        assert!(worst_norm < 4e-7, "worst |sin² + cos² − 1| {worst_norm}");
        assert_eq!(sin_cos_turns(0.0), (0.0, 1.0));
    }

    #[test]
    fn concentric_disk_matches_the_polar_form() {
        // the same point as r (cos φ, sin φ) with the angles of Shirley & Chiu
        let mut r = Rng::from_key(5);
        for _ in 0..100_000 {
            let u = r.uniform2();
            let [x, y] = concentric_disk(u);
            let (a, b) = (2.0 * u[0] as f64 - 1.0, 2.0 * u[1] as f64 - 1.0);
            let (rad, phi) = if a.abs() > b.abs() {
                (a, std::f64::consts::FRAC_PI_4 * (b / a))
            } else {
                (
                    b,
                    std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (a / b),
                )
            };
            assert!((x as f64 - rad * phi.cos()).abs() < 3e-7, "{u:?}");
            assert!((y as f64 - rad * phi.sin()).abs() < 3e-7, "{u:?}");
        }
    }

    #[test]
    fn scan_and_binary_search_pick_the_same_index() {
        // sizes on both sides of the scan's limit, with zero weights (flat
        // runs in the cdf) and u at and between the steps
        let mut r = Rng::from_key(9);
        for n in [1, 2, 3, 8, 9, 40] {
            let w: Vec<f64> = (0..n)
                .map(|i| if i % 3 == 1 { 0.0 } else { 1.0 + i as f64 })
                .collect();
            let d = Distribution1D::new(&w);
            let mut us: Vec<f32> = (0..2000).map(|_| r.uniform()).collect();
            us.extend(d.cdf.iter().map(|&c| (c / d.total) as f32));
            us.extend([0.0, f32::from_bits(1f32.to_bits() - 1)]);
            for u in us {
                let target = u as f64 * d.total;
                let reference = d.cdf.partition_point(|&c| c <= target).min(n - 1);
                assert_eq!(d.sample_index(u), reference, "n={n} u={u}");
            }
        }
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
