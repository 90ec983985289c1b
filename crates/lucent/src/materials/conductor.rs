//! A conductor (metal): reflection off a GGX microsurface (roughness
//! r, α = r², [`super::microfacet`]) with the Fresnel reflectance of a
//! complex index of refraction η + ik per RGB channel (pbrt-v4 §9.4,
//! `FrComplex`), and the energy single scattering loses returned by the
//! multiple-scattering lobe of Kulla & Conty (2017):
//!
//!   f_ms = F_ms (1 − E(μo)) (1 − E(μi)) / (π (1 − Ē)),
//!   F_ms = F̄² Ē / (1 − F̄ (1 − Ē)),
//!
//! E the directional albedo of the lobe with F = 1 ([`AlbedoTable`]), F̄
//! the cosine-weighted mean of F. With F = 1 the albedo is exactly
//! E + (1 − E) = 1 (a white furnace); below α = [`SMOOTH_ALPHA`] the
//! surface is a mirror. Directions are local, z = the shading normal on
//! wo's side (the material is two-sided).

use super::albedo_table::{shared, AlbedoTable, TableKey};
use super::microfacet::{alpha_from_roughness, reflect, Ggx, SMOOTH_ALPHA};
use super::roughness_steps::RoughnessSteps;
use crate::geometry::Vec3;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::FRAC_1_PI;
use std::sync::Arc;

/// Points of the albedo quadrature: in x = −ln(1 − r²) over [0,
/// `TAIL_X`] (r the radius on the unit disk of visible-normal sampling),
/// and in the disk's angle. GGX's long tail (a fraction α²/(1 + α²) of
/// normals tilted past 45°, whose reflections leave below the horizon)
/// lies at 1 − r² of order α², which a grid in x resolves at every α; a
/// square grid of the sampling square puts it in one ring of cells.
const RADIAL_POINTS: usize = 192;
const ANGULAR_POINTS: usize = 96;
const TAIL_X: f64 = 25.0;

/// A direction sampled from a glossy lobe (local frame): f cos θi / pdf
/// and the solid-angle pdf.
#[derive(Clone, Copy, Debug)]
pub struct GlossySample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Conductor {
    pub eta: Vec3,
    pub k: Vec3,
    pub roughness: f32,
    /// F̄, the cosine-weighted mean of F per channel.
    mean_f: Vec3,
    rough: Option<RoughLobe>,
}

/// What a rough conductor adds: its distribution, the F = 1 albedo
/// table and F_ms / (π (1 − Ē)) per channel.
#[derive(Clone, Debug, PartialEq)]
struct RoughLobe {
    ggx: Ggx,
    albedo: AlbedoTable,
    ms: Vec3,
}

impl RoughLobe {
    /// The lobe of width `alpha` whose F = 1 albedo is `albedo`, for a
    /// metal of mean Fresnel `f`.
    fn new(alpha: f32, albedo: AlbedoTable, f: Vec3) -> Self {
        let e = albedo.mean();
        let ms = if 1.0 - e > 1e-6 {
            f * f * e / (Vec3::ONE - f * (1.0 - e)) * (FRAC_1_PI / (1.0 - e))
        } else {
            Vec3::ZERO
        };
        RoughLobe {
            ggx: Ggx { alpha },
            albedo,
            ms,
        }
    }
}

impl Conductor {
    /// The conductor of index η + ik and `roughness` ∈ [0, 1].
    pub fn new(eta: Vec3, k: Vec3, roughness: f32) -> Self {
        let alpha = alpha_from_roughness(roughness);
        let mean_f = mean_fresnel(eta, k);
        let rough =
            (alpha >= SMOOTH_ALPHA).then(|| RoughLobe::new(alpha, *Self::table(roughness), mean_f));
        Conductor {
            eta,
            k,
            roughness,
            mean_f,
            rough,
        }
    }

    /// The same metal at `roughness` ∈ [0, 1], its albedo blended from the
    /// tables of `steps` (a point of a roughness texture).
    pub fn at_roughness(&self, roughness: f32, steps: &RoughnessSteps) -> Self {
        let alpha = alpha_from_roughness(roughness);
        let rough = (alpha >= SMOOTH_ALPHA)
            .then(|| RoughLobe::new(alpha, steps.at(roughness), self.mean_f));
        Conductor {
            roughness,
            rough,
            ..*self
        }
    }

    /// The F = 1 albedo table of the lobe of `roughness` (≥ the smooth
    /// threshold), built once per process.
    pub fn table(roughness: f32) -> Arc<AlbedoTable> {
        let ggx = Ggx {
            alpha: alpha_from_roughness(roughness),
        };
        let key = TableKey::Conductor {
            alpha: ggx.alpha.to_bits(),
        };
        shared(key, || {
            AlbedoTable::new(|mu| single_scattering_albedo(ggx, mu))
        })
    }

    /// A mirror: sampled by [`Conductor::mirror`], not by a lobe.
    pub fn is_smooth(&self) -> bool {
        self.rough.is_none()
    }

    /// Fresnel reflectance per channel for the cosine `cos_i` ≥ 0.
    pub fn fresnel(&self, cos_i: f32) -> Vec3 {
        Vec3::new(
            fresnel_complex(cos_i, self.eta.x, self.k.x),
            fresnel_complex(cos_i, self.eta.y, self.k.y),
            fresnel_complex(cos_i, self.eta.z, self.k.z),
        )
    }

    /// The mirror direction of `wo` and its weight F(cos θo).
    pub fn mirror(&self, wo: Vec3) -> (Vec3, Vec3) {
        (Vec3::new(-wo.x, -wo.y, wo.z), self.fresnel(wo.z.abs()))
    }

    /// f(ωo, ωi) per steradian: single plus multiple scattering; 0 for a
    /// mirror or unless both directions are above the surface.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(r) = &self.rough else {
            return Vec3::ZERO;
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (wo + wi).normalize();
        let single =
            self.fresnel(wo.dot(h).max(0.0)) * r.ggx.d(h) * r.ggx.g2(wo, wi) / (4.0 * wo.z * wi.z);
        let lost = (1.0 - r.albedo.at(wo.z)).max(0.0) * (1.0 - r.albedo.at(wi.z)).max(0.0);
        single + r.ms * lost
    }

    /// The probability of sampling the single-scattering lobe: its share of
    /// the F = 1 albedo, E(μo).
    fn single_probability(r: &RoughLobe, mu: f32) -> f32 {
        r.albedo.at(mu).clamp(0.0, 1.0)
    }

    /// The solid-angle density of [`Conductor::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(r) = &self.rough else {
            return 0.0;
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        let p = Self::single_probability(r, wo.z);
        p * r.ggx.g1(wo) * r.ggx.d(h) / (4.0 * wo.z) + (1.0 - p) * cosine_hemisphere_pdf(wi.z)
    }

    /// Samples ωi: visible normals with probability E(μo), else the
    /// cosine-weighted hemisphere (the multiple-scattering lobe's shape).
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<GlossySample> {
        let r = self.rough.as_ref()?;
        if wo.z <= 0.0 {
            return None;
        }
        let p = Self::single_probability(r, wo.z);
        let wi = if u[0] < p {
            reflect(wo, r.ggx.sample_visible(wo, [u[0] / p, u[1]]))
        } else {
            cosine_hemisphere([(u[0] - p) / (1.0 - p), u[1]])
        };
        weighted(wi, self.eval(wo, wi), self.pdf(wo, wi))
    }
}

/// The sample `wi` with f and pdf, None where it carries nothing.
pub(crate) fn weighted(wi: Vec3, f: Vec3, pdf: f32) -> Option<GlossySample> {
    if wi.z <= 0.0 || !(pdf > 0.0 && pdf.is_finite()) || f == Vec3::ZERO {
        return None;
    }
    Some(GlossySample {
        wi,
        weight: f * (wi.z / pdf),
        pdf,
    })
}

/// E(μ) of the GGX lobe with F = 1: the mean of G2/G1 over visible
/// normals. Uniform disk points have 1 − r² uniform on [0, 1]; with
/// 1 − r² = e^(−x) the mean is ∫ e^(−x) ⟨G2/G1⟩_angle dx, by the midpoint
/// rule (the part beyond `TAIL_X`, e^(−25), is left out).
fn single_scattering_albedo(ggx: Ggx, mu: f32) -> f64 {
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let g1 = ggx.g1(wo);
    let dx = TAIL_X / RADIAL_POINTS as f64;
    let mut sum = 0.0f64;
    for i in 0..RADIAL_POINTS {
        let x = (i as f64 + 0.5) * dx;
        let w = (-x).exp();
        let r = (1.0 - w).max(0.0).sqrt() as f32;
        let mut ring = 0.0f64;
        for j in 0..ANGULAR_POINTS {
            let phi = std::f32::consts::TAU * (j as f32 + 0.5) / ANGULAR_POINTS as f32;
            let m = ggx.visible_from_disk(wo, [r * phi.cos(), r * phi.sin()]);
            let wi = reflect(wo, m);
            if wi.z > 0.0 && wo.dot(m) > 0.0 {
                ring += (ggx.g2(wo, wi) / g1) as f64;
            }
        }
        sum += w * dx * ring / ANGULAR_POINTS as f64;
    }
    sum
}

/// F̄ = 2 ∫₀¹ F(μ) μ dμ per channel (midpoint rule).
fn mean_fresnel(eta: Vec3, k: Vec3) -> Vec3 {
    let n = 256;
    let mut s = [0.0f64; 3];
    for i in 0..n {
        let mu = (i as f32 + 0.5) / n as f32;
        for (c, s) in s.iter_mut().enumerate() {
            *s += (fresnel_complex(mu, eta[c], k[c]) * mu) as f64;
        }
    }
    Vec3::from_array(s.map(|x| (2.0 * x / n as f64) as f32))
}

/// Unpolarized Fresnel reflectance of a conductor of index η + ik for
/// light arriving with cosine `cos_i` from a medium of index 1 (pbrt-v4
/// §9.4.2), in f64 complex arithmetic.
pub fn fresnel_complex(cos_i: f32, eta: f32, k: f32) -> f32 {
    let c = cos_i.clamp(0.0, 1.0) as f64;
    let n = Complex::new(eta as f64, k as f64);
    let sin2_t = Complex::new(1.0 - c * c, 0.0).div(n.mul(n));
    let cos_t = Complex::new(1.0, 0.0).sub(sin2_t).sqrt();
    let ci = Complex::new(c, 0.0);
    let r_parl = n.mul(ci).sub(cos_t).div(n.mul(ci).add(cos_t));
    let r_perp = ci.sub(n.mul(cos_t)).div(ci.add(n.mul(cos_t)));
    (0.5 * (r_parl.norm2() + r_perp.norm2())) as f32
}

/// The few complex operations the Fresnel equations need.
#[derive(Clone, Copy, Debug)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn new(re: f64, im: f64) -> Self {
        Complex { re, im }
    }
    fn add(self, o: Self) -> Self {
        Complex::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Self) -> Self {
        Complex::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Self) -> Self {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: Self) -> Self {
        let d = o.norm2();
        Complex::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// The principal square root.
    fn sqrt(self) -> Self {
        let r = self.norm2().sqrt();
        let re = (0.5 * (r + self.re)).max(0.0).sqrt();
        let im = (0.5 * (r - self.re)).max(0.0).sqrt();
        Complex::new(re, if self.im < 0.0 { -im } else { im })
    }
}

#[cfg(test)]
mod tests {
    use super::super::lobe_checks::*;
    use super::*;
    use crate::fresnel;

    /// At normal incidence R = ((n − 1)² + k²) / ((n + 1)² + k²); with
    /// k = 0 it is the dielectric's Fresnel at every angle.
    #[test]
    fn complex_fresnel_matches_closed_forms() {
        for (n, k) in [(0.2f32, 3.9f32), (1.66, 9.2), (2.9, 3.1)] {
            let want = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
            assert!((fresnel_complex(1.0, n, k) - want).abs() < 1e-6);
            assert!((fresnel_complex(1e-4, n, k) - 1.0).abs() < 1e-3);
        }
        for mu in [0.05f32, 0.3, 0.7, 1.0] {
            let (a, b) = (fresnel_complex(mu, 1.5, 0.0), fresnel::dielectric(mu, 1.5));
            assert!((a - b).abs() < 1e-6, "μ {mu}: {a} vs {b}");
        }
    }

    /// A conductor with F ≈ 1 (k = 10⁴) in a white furnace reflects all
    /// light at every roughness and angle: single scattering's loss is
    /// returned by the multiple-scattering lobe. The albedo is estimated
    /// twice, by quadrature of f cos and by the mean sampled weight, so a
    /// pdf that is not the sampling density fails too. Without the
    /// multiple-scattering lobe it fails by up to 68% (r = 1, μ = 0.95).
    #[test]
    fn white_furnace_at_several_roughnesses() {
        for r in [0.1f32, 0.3, 0.6, 1.0] {
            let c = Conductor::new(Vec3::ONE, Vec3::splat(1e4), r);
            for mu in [0.1f32, 0.5, 0.95] {
                let wo = from_mu(mu);
                let quad = albedo_by_quadrature(|wi| c.eval(wo, wi).x);
                let sampled = albedo_by_sampling(|u| c.sample(wo, u).map(|s| s.weight.x));
                // the (θ, φ) grid resolves lobes from r = 0.3 on
                assert!(
                    r < 0.3 || (quad - 1.0).abs() < 3e-3,
                    "r {r} μ {mu}: ∫ f cos = {quad}"
                );
                assert!(
                    (sampled - 1.0).abs() < 3e-3,
                    "r {r} μ {mu}: E[w] = {sampled}"
                );
            }
        }
    }

    /// Without the multiple-scattering lobe a rough conductor loses light:
    /// the single-scattering albedo at μ = 0.5 falls with roughness, to
    /// 0.45 at r = 1 (the loss the compensation returns).
    #[test]
    fn single_scattering_loses_energy_that_grows_with_roughness() {
        let mut last = 1.0;
        for r in [0.1f32, 0.3, 0.6, 1.0] {
            let e = single_scattering_albedo(Ggx { alpha: r * r }, 0.5);
            assert!(e < last && e <= 1.0, "r {r}: E = {e}");
            last = e;
        }
        assert!((last - 0.45).abs() < 0.01, "r = 1: E(0.5) = {last}");
    }

    #[test]
    fn reciprocal_and_pdf_normalized() {
        for m in super::super::metals::METALS {
            let c = Conductor::new(m.eta(), m.k(), 0.4);
            check_reciprocity(|wo, wi| c.eval(wo, wi));
            check_pdf_matches_kept(|wo, wi| c.pdf(wo, wi), |wo, u| c.sample(wo, u).is_some());
            // every sample's weight is what f cos / pdf says
            check_sampled_weights(
                |wo, u| c.sample(wo, u).map(|s| (s.wi, s.weight, s.pdf)),
                |wo, wi| c.eval(wo, wi),
                |wo, wi| c.pdf(wo, wi),
            );
        }
    }

    /// Gold reflects more red than blue; a smooth conductor is a mirror
    /// with weight F(cos θo).
    #[test]
    fn gold_is_yellow_and_smooth_is_a_mirror() {
        let g = super::super::metals::metal("gold").unwrap();
        let c = Conductor::new(g.eta(), g.k(), 0.0);
        assert!(c.is_smooth());
        let f = c.fresnel(1.0);
        assert!(f.x > f.y && f.y > f.z, "{f}");
        let wo = from_mu(0.6);
        let (wi, w) = c.mirror(wo);
        assert!((wi.z - wo.z).abs() < 1e-7 && (wi.x + wo.x).abs() < 1e-7);
        assert_eq!(w, c.fresnel(0.6));
        assert!(c.sample(wo, [0.3, 0.3]).is_none());
    }
}
