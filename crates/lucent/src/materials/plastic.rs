//! A coated diffuse surface ("plastic"): a dielectric coat of index η
//! (smooth, or GGX of roughness r, α = r², [`super::microfacet`]) over a
//! Lambertian base of albedo ρ, coupled so that energy is conserved
//! (Kelemen & Szirmay-Kalos 2001):
//!
//!   f = f_coat + ρ (1 − E(μo)) (1 − E(μi)) / (π (1 − Ē)),
//!
//! E the coat's directional albedo (the rough coat's table, or Fresnel
//! for a smooth coat) and Ē its cosine-weighted mean. The albedo is then
//! E(μo) + ρ (1 − E(μo)): exactly 1 for ρ = 1 (a white furnace), for any
//! roughness. f is symmetric in ωo, ωi. A smooth coat is a mirror: the
//! bounce loop picks it or the base ([`Plastic::mirror_probability`]).
//! Directions are local, z = the shading normal on wo's side (two-sided).

use super::albedo_table::AlbedoTable;
use super::conductor::{weighted, GlossySample};
use super::microfacet::{alpha_from_roughness, RoughCoat, SMOOTH_ALPHA};
use super::roughness_steps::RoughnessSteps;
use crate::fresnel;
use crate::geometry::Vec3;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug, PartialEq)]
pub struct Plastic {
    pub albedo: Vec3,
    pub eta: f32,
    pub roughness: f32,
    /// None: a smooth coat.
    coat: Option<RoughCoat>,
    /// Ē of the coat.
    mean: f32,
    /// F̄ of the smooth coat of index η.
    smooth_mean: f32,
}

impl Plastic {
    /// The plastic of base `albedo`, coat index `eta` (> 0, ≠ 1 for a
    /// visible coat) and `roughness` ∈ [0, 1].
    pub fn new(albedo: Vec3, eta: f32, roughness: f32) -> Self {
        let alpha = alpha_from_roughness(roughness);
        let coat = (alpha >= SMOOTH_ALPHA).then(|| RoughCoat::new(alpha, eta));
        Self::with_coat(albedo, eta, roughness, coat, mean_fresnel(eta))
    }

    /// The same plastic at `roughness` ∈ [0, 1], its coat's albedo blended
    /// from the tables of `steps` (a point of a roughness texture).
    pub fn at_roughness(&self, roughness: f32, steps: &RoughnessSteps) -> Self {
        let alpha = alpha_from_roughness(roughness);
        let coat = (alpha >= SMOOTH_ALPHA)
            .then(|| RoughCoat::with_table(alpha, self.eta, steps.at(roughness)));
        Self::with_coat(self.albedo, self.eta, roughness, coat, self.smooth_mean)
    }

    /// The albedo table of the coat of `roughness` (≥ the smooth
    /// threshold) and index `eta`, built once per process.
    pub fn table(roughness: f32, eta: f32) -> std::sync::Arc<AlbedoTable> {
        RoughCoat::table(alpha_from_roughness(roughness), eta)
    }

    /// The plastic with the coat `coat` (None: smooth, whose F̄ is
    /// `smooth_mean`).
    fn with_coat(
        albedo: Vec3,
        eta: f32,
        roughness: f32,
        coat: Option<RoughCoat>,
        smooth_mean: f32,
    ) -> Self {
        let mean = match &coat {
            Some(c) => c.mean_albedo(),
            None => smooth_mean,
        };
        Plastic {
            albedo,
            eta,
            roughness,
            coat,
            mean,
            smooth_mean,
        }
    }

    /// Whether the coat is a mirror.
    pub fn is_smooth(&self) -> bool {
        self.coat.is_none()
    }

    /// The coat's albedo E(μ).
    fn coat_albedo(&self, mu: f32) -> f32 {
        match &self.coat {
            Some(c) => c.albedo(mu),
            None => fresnel::dielectric(mu, self.eta),
        }
    }

    /// The base's share ρ (1 − E(μo)) (1 − E(μi)) / (π (1 − Ē)).
    fn base(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 || self.mean >= 1.0 {
            return Vec3::ZERO;
        }
        let t = (1.0 - self.coat_albedo(wo.z)).max(0.0) * (1.0 - self.coat_albedo(wi.z)).max(0.0);
        self.albedo * (t * FRAC_1_PI / (1.0 - self.mean))
    }

    /// f(ωo, ωi) per steradian, the smooth coat's mirror excluded.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let coat = match &self.coat {
            Some(c) => c.eval(wo, wi),
            None => 0.0,
        };
        self.base(wo, wi) + Vec3::splat(coat)
    }

    /// The probability of sampling the coat: its share of the albedo at
    /// μo, E / (E + ρ̄ (1 − E)), ρ̄ the mean of ρ's channels.
    pub fn mirror_probability(&self, mu: f32) -> f32 {
        let e = self.coat_albedo(mu);
        let rho = (self.albedo.x + self.albedo.y + self.albedo.z) / 3.0;
        let total = e + rho * (1.0 - e);
        if total > 0.0 {
            (e / total).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }

    /// The solid-angle density of [`Plastic::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let diffuse = cosine_hemisphere_pdf(wi.z);
        match &self.coat {
            Some(c) => {
                let p = self.mirror_probability(wo.z);
                p * c.pdf(wo, wi) + (1.0 - p) * diffuse
            }
            None => diffuse,
        }
    }

    /// Samples ωi: the rough coat's visible normals with probability
    /// [`Plastic::mirror_probability`], else cosine-weighted; a smooth
    /// coat's base by cosine only.
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<GlossySample> {
        if wo.z <= 0.0 {
            return None;
        }
        let p = match &self.coat {
            Some(_) => self.mirror_probability(wo.z),
            None => 0.0,
        };
        let wi = match &self.coat {
            Some(c) if u[0] < p => c.sample(wo, [u[0] / p, u[1]])?.0,
            _ => cosine_hemisphere([(u[0] - p) / (1.0 - p), u[1]]),
        };
        weighted(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }
}

/// F̄ = 2 ∫₀¹ F(μ) μ dμ of a smooth interface (midpoint rule).
fn mean_fresnel(eta: f32) -> f32 {
    let n = 1024;
    let s: f64 = (0..n)
        .map(|i| {
            let mu = (i as f32 + 0.5) / n as f32;
            (fresnel::dielectric(mu, eta) * mu) as f64
        })
        .sum();
    (2.0 * s / n as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::super::lobe_checks::*;
    use super::*;

    /// ρ = 1 under uniform light: the coat plus the base reflect all of
    /// it, at every roughness and angle. A smooth coat: its mirror
    /// reflects F(μo), the base the rest.
    #[test]
    fn white_furnace_at_several_roughnesses() {
        for r in [0.2f32, 0.5, 1.0] {
            let p = Plastic::new(Vec3::ONE, 1.5, r);
            for mu in [0.1f32, 0.5, 0.95] {
                let wo = from_mu(mu);
                let quad = albedo_by_quadrature(|wi| p.eval(wo, wi).x);
                let sampled = albedo_by_sampling(|u| p.sample(wo, u).map(|s| s.weight.x));
                assert!((quad - 1.0).abs() < 6e-3, "r {r} μ {mu}: ∫ f cos = {quad}");
                assert!(
                    (sampled - 1.0).abs() < 6e-3,
                    "r {r} μ {mu}: E[w] = {sampled}"
                );
            }
        }
        let p = Plastic::new(Vec3::ONE, 1.5, 0.0);
        for mu in [0.1f32, 0.5, 0.95] {
            let wo = from_mu(mu);
            let base = albedo_by_quadrature(|wi| p.eval(wo, wi).x);
            let total = base + fresnel::dielectric(mu, 1.5) as f64;
            assert!((total - 1.0).abs() < 3e-3, "smooth μ {mu}: {total}");
        }
    }

    /// A darker base reflects E(μo) + ρ (1 − E(μo)), per channel.
    #[test]
    fn coloured_base_reflects_its_share() {
        let rho = Vec3::new(0.8, 0.4, 0.1);
        let p = Plastic::new(rho, 1.5, 0.5);
        let wo = from_mu(0.6);
        let e = p.coat_albedo(0.6) as f64;
        for c in 0..3 {
            let quad = albedo_by_quadrature(|wi| p.eval(wo, wi)[c]);
            let want = e + rho[c] as f64 * (1.0 - e);
            assert!((quad - want).abs() < 5e-3, "channel {c}: {quad} vs {want}");
        }
    }

    #[test]
    fn reciprocal_weights_and_pdf() {
        for r in [0.0f32, 0.3, 0.8] {
            let p = Plastic::new(Vec3::new(0.7, 0.5, 0.2), 1.5, r);
            check_reciprocity(|wo, wi| p.eval(wo, wi));
            check_pdf_matches_kept(|wo, wi| p.pdf(wo, wi), |wo, u| p.sample(wo, u).is_some());
            check_sampled_weights(
                |wo, u| p.sample(wo, u).map(|s| (s.wi, s.weight, s.pdf)),
                |wo, wi| p.eval(wo, wi),
                |wo, wi| p.pdf(wo, wi),
            );
        }
    }
}
