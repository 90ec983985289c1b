//! The random walk's diffuse Fresnel boundary (`boundary = "diffuse"`,
//! `docs/bssrdf.md` §7): a smooth interface of index η whose reflection is
//! exactly the dielectric's, but whose transmission forgets the direction,
//! so the point where a walk leaves the medium is a vertex with a lobe, and
//! the shared bounce loop can sample the lights there (next-event
//! estimation with MIS). It is a **different model** from the exact smooth
//! dielectric boundary (`boundary = "dielectric"`, where light refracts
//! along Snell's direction): it converges to a different image.
//!
//! Notation: n the outward normal, μ = |cos θ| on the side a direction
//! lies, Fr(μ, η) the Fresnel reflectance for light arriving from outside
//! and Fr_in(μ', η) = Fr(μ', 1/η) for light arriving from inside (1 past
//! the critical angle), T = 1 − Fr, T_in = 1 − Fr_in, and the cosine-
//! weighted hemispherical averages
//!
//!   F̄ = 2 ∫₀¹ Fr(μ, η) μ dμ,   F̄_in = 2 ∫₀¹ Fr_in(μ', η) μ' dμ' = 1 − (1 − F̄)/η²
//!
//! (the second equality is Stokes' relation for a dielectric;
//! [`mean_reflectance`] computes F̄ and the test checks the relation).
//!
//! **The model, per crossing:**
//!
//! 1. *Arriving from outside* at xo from ω (cosine μ): mirror reflection
//!    with probability Fr(μ, η), as the smooth dielectric; otherwise the
//!    light enters, in a direction ω' drawn from
//!    p_in(ω') = T_in(μ') μ' / (π (1 − F̄_in)) over the inner hemisphere —
//!    the directions refraction fills under diffuse light — independent of ω.
//! 2. *Arriving from inside* (cosine μ' to n): mirror reflection with
//!    probability Fr_in(μ', η) (total internal reflection included), as the
//!    smooth dielectric; otherwise the light leaves at that point xi, in a
//!    direction ω drawn from the exit lobe
//!    f_exit(ω) = T(μ, η) / (π (1 − F̄)), ∫ f_exit μ dω = 1 ([`ExitLobe`]),
//!    independent of ω'.
//!
//! As a BSDF the transmission is f_t(ω → ω') = T(μ) T_in(μ') / (π (1 − F̄_in))
//! inwards and f_t(ω' → ω) = T_in(μ') T(μ) / (π (1 − F̄)) outwards; their
//! ratio is (1 − F̄)/(1 − F̄_in) = η², which is the generalized reciprocity
//! f(ω → ω')/η'² = f(ω' → ω)/η² of a refractive interface (Veach 1997,
//! §5.2) — the same relation the smooth dielectric obeys. Each crossing
//! either reflects or transmits with probabilities summing to 1, and both
//! direction laws are normalized, so the boundary neither creates nor
//! destroys energy: with σa = 0 a closed object in a uniform environment
//! returns the environment exactly (tests/physics/randomwalk.rs).
//!
//! **Estimator.** Tracing from the camera, step 1 is sampled exactly (the
//! inner direction by rejection from the cosine lobe: accept with
//! probability T_in, mean acceptance 1 − F̄_in, 0.40 at η = 1.5; after
//! [`MAX_REJECTIONS`] misses a cosine sample weighted T_in/(1 − F̄_in), so
//! the estimator stays unbiased for any η), and step 2 chooses exit vs
//! internal reflection with the Fresnel weight Fr_in(μ') (weight 1). The
//! exit point becomes a path vertex with the lobe f_exit, cosine-sampled
//! (weight T/(1 − F̄) ≤ 1/(1 − F̄), 1.10 at η = 1.5), so light sampling and
//! lobe sampling are combined there with the power heuristic.
//!
//! **Precision.** F̄ is integrated by Gauss–Legendre quadrature after the
//! substitution μ = s² (which smooths the square root in cos θt near
//! grazing when η → 1): 4 panels × 8 nodes, error below 10⁻⁷ for
//! η ∈ [1.001, 10] (test), i.e. below the f32 rounding of the lobe itself.
//! For η < 1, F̄(η) = 1 − η² (1 − F̄(1/η)) (Stokes) avoids integrating
//! across the external critical angle.

use crate::fresnel;
use crate::geometry::Vec3;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf, Draw, SampleRng};

/// Rejection attempts for the inner direction before falling back to a
/// weighted cosine sample (the acceptance rate is 1 − F̄_in ≥ 0.1 for
/// η ≤ 3, so the fallback is practically never taken).
pub const MAX_REJECTIONS: u32 = 64;

/// The cosine-weighted hemispherical average Fresnel reflectance F̄(η) for
/// light arriving from outside: 2 ∫₀¹ Fr(μ, η) μ dμ.
pub fn mean_reflectance(eta: f32) -> f64 {
    if eta == 1.0 {
        return 0.0;
    }
    if eta < 1.0 {
        let e2 = (eta as f64) * (eta as f64);
        return 1.0 - e2 * (1.0 - mean_reflectance(1.0 / eta));
    }
    // 2 ∫₀¹ Fr(s²) s² · 2s ds, Gauss–Legendre 8 nodes on 4 panels of s.
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    const PANELS: usize = 4;
    let h = 1.0 / PANELS as f64;
    let mut sum = 0.0;
    for k in 0..PANELS {
        let mid = (k as f64 + 0.5) * h;
        for (x, w) in X.iter().zip(W) {
            for s in [mid - 0.5 * h * x, mid + 0.5 * h * x] {
                let mu = s * s;
                let fr = fresnel::dielectric(mu as f32, eta) as f64;
                sum += w * 0.5 * h * fr * 4.0 * s * s * s;
            }
        }
    }
    sum
}

/// The diffuse Fresnel boundary of one material: η and its averages.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseBoundary {
    pub eta: f32,
    /// 1 − F̄: the exit lobe's normalization.
    pub t_mean: f32,
    /// 1 − F̄_in = (1 − F̄)/η²: the mean acceptance of the inner direction.
    pub t_mean_in: f32,
}

impl DiffuseBoundary {
    pub fn new(eta: f32) -> Self {
        let t = 1.0 - mean_reflectance(eta);
        let e2 = (eta as f64) * (eta as f64);
        DiffuseBoundary {
            eta,
            t_mean: t as f32,
            t_mean_in: (t / e2) as f32,
        }
    }

    /// Fr_in(μ'): the probability that a walk arriving at the boundary from
    /// inside with cosine `mu_in` (> 0) to the outward normal reflects back.
    pub(crate) fn reflect_in(&self, mu_in: f32) -> f32 {
        fresnel::dielectric(-mu_in, self.eta)
    }

    /// Step 1 for a ray arriving from outside with cosine `mu` (> 0): None
    /// for mirror reflection (probability Fr), else the inner direction in
    /// the local frame whose +z is the **inward** normal and its weight
    /// (1, or T_in/(1 − F̄_in) after [`MAX_REJECTIONS`] misses).
    pub fn enter(&self, mu: f32, rng: &mut SampleRng) -> Option<(Vec3, f32)> {
        if rng.uniform() < fresnel::dielectric(mu, self.eta) {
            return None;
        }
        for _ in 0..MAX_REJECTIONS {
            let w = cosine_hemisphere(rng.uniform2_packed());
            if rng.uniform() < 1.0 - self.reflect_in(w.z) {
                return Some((w, 1.0));
            }
        }
        let w = cosine_hemisphere(rng.uniform2_packed());
        Some((w, (1.0 - self.reflect_in(w.z)) / self.t_mean_in))
    }

    pub fn exit_lobe(&self) -> ExitLobe {
        ExitLobe {
            eta: self.eta,
            inv_norm: 1.0 / (std::f32::consts::PI * self.t_mean),
        }
    }
}

/// f_exit(ω) = T(μ, η) / (π (1 − F̄)) on the outer hemisphere (local +z =
/// outward normal): where a walk leaving the medium goes.
#[derive(Clone, Copy, Debug)]
pub struct ExitLobe {
    eta: f32,
    /// 1 / (π (1 − F̄)).
    inv_norm: f32,
}

impl ExitLobe {
    pub(crate) fn eval(&self, wi: Vec3) -> f32 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        (1.0 - fresnel::dielectric(wi.z, self.eta)) * self.inv_norm
    }

    pub fn pdf(&self, wi: Vec3) -> f32 {
        cosine_hemisphere_pdf(wi.z)
    }

    /// A cosine-distributed ωi: (ωi, f |cos| / pdf, pdf).
    pub fn sample(&self, u: [f32; 2]) -> Option<(Vec3, f32, f32)> {
        let wi = cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi.z);
        (pdf > 0.0).then(|| (wi, self.eval(wi) * wi.z / pdf, pdf))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// F̄ by a fine midpoint rule in μ (f64 sum of the f32 Fresnel).
    fn brute(eta: f32) -> f64 {
        let n = 400_000;
        (0..n)
            .map(|i| {
                let mu = (i as f64 + 0.5) / n as f64;
                2.0 * fresnel::dielectric(mu as f32, eta) as f64 * mu / n as f64
            })
            .sum()
    }

    #[test]
    fn mean_reflectance_matches_brute_force_and_stokes() {
        for eta in [1.001f32, 1.01, 1.1, 1.3, 1.33, 1.5, 2.0, 3.0, 10.0] {
            let (q, b) = (mean_reflectance(eta), brute(eta));
            assert!((q - b).abs() < 1e-6, "η {eta}: quadrature {q} brute {b}");
            // From inside: F̄_in(η) = F̄(1/η) integrated directly across the
            // critical angle, against Stokes' 1 − (1 − F̄)/η².
            let inside = brute(1.0 / eta);
            let stokes = 1.0 - (1.0 - q) / (eta as f64 * eta as f64);
            assert!((inside - stokes).abs() < 2e-5, "η {eta}: {inside} {stokes}");
            assert!((mean_reflectance(1.0 / eta) - stokes).abs() < 1e-6);
        }
        assert_eq!(mean_reflectance(1.0), 0.0);
        // glass: F̄ ≈ 0.092 (the classic hemispherical value)
        assert!((mean_reflectance(1.5) - 0.0918).abs() < 1e-3);
    }

    #[test]
    fn exit_lobe_is_normalized() {
        for eta in [1.0f32, 1.3, 1.5, 2.5, 0.7] {
            let lobe = DiffuseBoundary::new(eta).exit_lobe();
            let n = 200_000;
            let integral: f64 = (0..n)
                .map(|i| {
                    let mu = (i as f64 + 0.5) / n as f64;
                    let w = Vec3::new((1.0 - mu * mu).sqrt() as f32, 0.0, mu as f32);
                    2.0 * std::f64::consts::PI * lobe.eval(w) as f64 * mu / n as f64
                })
                .sum();
            assert!((integral - 1.0).abs() < 1e-5, "η {eta}: {integral}");
        }
    }

    /// Sampling the exit lobe returns the density it draws with and the
    /// weight f cos θ / pdf; over the square those weights integrate to
    /// ∫ f cos dω = 1 (every walk that leaves goes somewhere).
    #[test]
    fn exit_lobe_sample_weights_are_f_cos_over_pdf_and_sum_to_one() {
        for eta in [1.3f32, 1.5, 2.5] {
            let lobe = DiffuseBoundary::new(eta).exit_lobe();
            let n = 400;
            let mut sum = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
                    let (wi, w, pdf) = lobe.sample(u).unwrap();
                    assert!((pdf - lobe.pdf(wi)).abs() <= 1e-6 * pdf, "{pdf}");
                    let want = lobe.eval(wi) * wi.z / pdf;
                    assert!((w - want).abs() <= 1e-5 * want.max(1e-3), "{w} vs {want}");
                    sum += w as f64;
                }
            }
            let mean = sum / (n * n) as f64;
            assert!((mean - 1.0).abs() < 1e-3, "η {eta}: {mean}");
        }
    }

    /// At normal incidence a fraction Fr(1, η) reflects; the inner
    /// direction is distributed ∝ T_in(μ') μ': none lies in the total-
    /// internal-reflection cone, and its mean cosine is that law's.
    #[test]
    fn entry_samples_the_refracted_diffuse_law() {
        let eta = 1.5f32;
        let b = DiffuseBoundary::new(eta);
        let mut rng = SampleRng::new(3, 5, 7);
        let (mut n, mut sum_mu, mut reflected) = (0u32, 0.0f64, 0u32);
        let mu_c = (1.0 - 1.0 / (eta * eta)).sqrt();
        for _ in 0..200_000 {
            match b.enter(1.0, &mut rng) {
                None => reflected += 1,
                Some((w, weight)) => {
                    assert_eq!(weight, 1.0);
                    assert!(w.z >= mu_c - 1e-4, "{w}");
                    n += 1;
                    sum_mu += w.z as f64;
                }
            }
        }
        let f0 = fresnel::dielectric(1.0, eta) as f64;
        let fr = reflected as f64 / 200_000.0;
        assert!(
            (fr - f0).abs() < 4.0 * (f0 * (1.0 - f0) / 2e5).sqrt(),
            "{fr}"
        );
        // E[μ'] = ∫ T_in μ'² dμ' / ∫ T_in μ' dμ'
        let m = 100_000;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..m {
            let mu = (i as f64 + 0.5) / m as f64;
            let t = 1.0 - fresnel::dielectric(-(mu as f32), eta) as f64;
            num += t * mu * mu;
            den += t * mu;
        }
        let mean = sum_mu / n as f64;
        assert!((mean - num / den).abs() < 2e-3, "{mean} vs {}", num / den);
    }
    /// At a high index the inner direction's acceptance 1 − F̄_in =
    /// (1 − F̄)/η² is small and many entries take the fallback (η = 6:
    /// acceptance 1.4 %, fallback for (1 − 0.014)⁶⁴ ≈ 40 % of entries): its weight
    /// T_in/(1 − F̄_in) must keep the weighted inner directions on the same
    /// law, ∝ T_in(μ') μ', with mean weight 1 (energy transmitted, not made
    /// or lost).
    #[test]
    fn entry_fallback_keeps_the_refracted_law_at_high_index() {
        let eta = 6.0f32;
        let b = DiffuseBoundary::new(eta);
        let mut rng = SampleRng::new(5, 9, 2);
        let (mut n, mut fallbacks) = (0u32, 0u32);
        let (mut sum_w, mut sum_w2) = (0.0f64, 0.0f64);
        let (mut sum_wmu, mut sum_wmu2) = (0.0f64, 0.0f64);
        for _ in 0..200_000 {
            if let Some((w, weight)) = b.enter(1.0, &mut rng) {
                n += 1;
                if weight != 1.0 {
                    fallbacks += 1;
                }
                let weight = weight as f64;
                sum_w += weight;
                sum_w2 += weight * weight;
                sum_wmu += weight * w.z as f64;
                sum_wmu2 += (weight * w.z as f64).powi(2);
            }
        }
        assert!(fallbacks as f64 > 0.2 * n as f64, "{fallbacks} of {n}");
        let nf = n as f64;
        let mean_w = sum_w / nf;
        let sigma = ((sum_w2 / nf - mean_w * mean_w) / nf).sqrt();
        assert!(
            (mean_w - 1.0).abs() < 4.0 * sigma + 1e-4,
            "mean weight {mean_w} ± {sigma}"
        );
        // E[w μ'] = ∫ T_in μ'² dμ' / ∫ T_in μ' dμ' (the fallback's weights
        // are 0 outside the narrow cone μ' > μ_c and up to 1/(1 − F̄_in)
        // inside it: a wide spread, so the bound is statistical)
        let m = 100_000;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..m {
            let mu = (i as f64 + 0.5) / m as f64;
            let t = 1.0 - fresnel::dielectric(-(mu as f32), eta) as f64;
            num += t * mu * mu;
            den += t * mu;
        }
        let mean_mu = sum_wmu / nf;
        let sigma_mu = ((sum_wmu2 / nf - mean_mu * mean_mu) / nf).sqrt();
        assert!(
            (mean_mu - num / den).abs() < 4.0 * sigma_mu + 1e-4,
            "{mean_mu} ± {sigma_mu} vs {}",
            num / den
        );
    }
}
