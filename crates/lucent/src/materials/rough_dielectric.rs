//! A rough dielectric interface ("frosted glass"): reflection and
//! refraction through a GGX microsurface of roughness r (α = r²,
//! [`super::microfacet`]), relative index η = inside / outside (Walter et
//! al. 2007; pbrt-v4 §9.7, `DielectricBxDF`). Directions are local, z =
//! the outward normal; ωo may be inside (z < 0). Radiance transport: a
//! refracted sample's weight carries 1/η'² like the smooth dielectric's.
//!
//! Single scattering only: light that would scatter more than once
//! between microfacets is lost (measured in `docs/journal.md`,
//! 2026-12-07, "Rough dielectric").

use super::microfacet::{alpha_from_roughness, reflect, Ggx};
use crate::fresnel;
use crate::geometry::Vec3;

/// A direction sampled from the interface, f |cos θi| / pdf, the
/// solid-angle pdf, and whether it crossed the interface.
#[derive(Clone, Copy, Debug)]
pub struct InterfaceSample {
    pub wi: Vec3,
    pub weight: f32,
    pub pdf: f32,
    pub transmitted: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    pub eta: f32,
    pub roughness: f32,
    ggx: Ggx,
}

/// Refracts `wo` about the unit normal `m` (either side) for the relative
/// index `eta` across it; the refracted direction and η' (the index
/// ratio it crossed, transmitted side over incident side), None on total
/// internal reflection.
fn refract_about(wo: Vec3, m: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = wo.dot(m);
    let (mut etap, mut n) = (eta, m);
    if cos_i < 0.0 {
        etap = 1.0 / eta;
        cos_i = -cos_i;
        n = -m;
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (etap * etap);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / etap + (cos_i / etap - cos_t) * n, etap))
}

impl RoughDielectric {
    /// The interface of index `eta` and `roughness` ∈ (0, 1].
    pub fn new(eta: f32, roughness: f32) -> Self {
        RoughDielectric {
            eta,
            roughness,
            ggx: Ggx {
                alpha: alpha_from_roughness(roughness),
            },
        }
    }

    /// The same interface at `roughness` (a point of a roughness
    /// texture); None below the smooth threshold, where it is the smooth
    /// interface.
    pub fn at_roughness(&self, roughness: f32) -> Option<Self> {
        (alpha_from_roughness(roughness) >= super::microfacet::SMOOTH_ALPHA)
            .then(|| Self::new(self.eta, roughness))
    }

    /// D_ωo(m): the density of visible normals, for either side of ωo.
    fn visible_density(&self, wo: Vec3, m: Vec3) -> f32 {
        self.ggx.g1(wo) / wo.z.abs() * self.ggx.d(m) * wo.dot(m).abs()
    }

    /// The microfacet normal (z > 0) of the pair, η' and whether it is a
    /// reflection; None where no facet facing both scatters ωo into ωi.
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, bool)> {
        let (co, ci) = (wo.z, wi.z);
        if co == 0.0 || ci == 0.0 {
            return None;
        }
        let reflected = co * ci > 0.0;
        let etap = match (reflected, co > 0.0) {
            (true, _) => 1.0,
            (false, true) => self.eta,
            (false, false) => 1.0 / self.eta,
        };
        let m = wi * etap + wo;
        if m.length_squared() == 0.0 {
            return None;
        }
        let m = m.normalize();
        let m = if m.z < 0.0 { -m } else { m };
        // facets seen from behind by either direction scatter nothing
        if m.dot(wi) * ci < 0.0 || m.dot(wo) * co < 0.0 {
            return None;
        }
        Some((m, etap, reflected))
    }

    /// f(ωo, ωi) per steradian (radiance).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some((m, etap, reflected)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let f = fresnel::dielectric(wo.dot(m), self.eta);
        let dg = self.ggx.d(m) * self.ggx.g2(wo, wi);
        if reflected {
            return dg * f / (4.0 * wo.z * wi.z).abs();
        }
        let denom = (wi.dot(m) + wo.dot(m) / etap).powi(2) * wi.z * wo.z;
        dg * (1.0 - f) * (wi.dot(m) * wo.dot(m) / denom).abs() / (etap * etap)
    }

    /// The solid-angle density of [`RoughDielectric::sample`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some((m, etap, reflected)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let f = fresnel::dielectric(wo.dot(m), self.eta);
        let dm = self.visible_density(wo, m);
        if reflected {
            return dm / (4.0 * wo.dot(m).abs()) * f;
        }
        let denom = (wi.dot(m) + wo.dot(m) / etap).powi(2);
        dm * wi.dot(m).abs() / denom * (1.0 - f)
    }

    /// Samples a visible normal (for ωo on either side), then reflection
    /// with probability F, else refraction; the weight is G2/G1, over η'²
    /// when refracted.
    pub fn sample(&self, wo: Vec3, u: [f32; 3]) -> Option<InterfaceSample> {
        if wo.z == 0.0 {
            return None;
        }
        let up = if wo.z > 0.0 { wo } else { -wo };
        let m = self.ggx.sample_visible(up, [u[0], u[1]]);
        let f = fresnel::dielectric(wo.dot(m), self.eta);
        let (wi, etap, transmitted) = if u[2] < f {
            (reflect(wo, m), 1.0, false)
        } else {
            let (wi, etap) = refract_about(wo, m, self.eta)?;
            (wi, etap, true)
        };
        // the same side as ωo exactly when reflected
        if (wi.z * wo.z > 0.0) == transmitted || wi.z == 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let weight = self.ggx.g2(wo, wi) / self.ggx.g1(wo) / (etap * etap);
        Some(InterfaceSample {
            wi,
            weight,
            pdf,
            transmitted,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::lobe_checks::*;
    use super::*;
    use crate::sampling::Rng;

    fn dir(rng: &mut Rng, sphere: bool) -> Vec3 {
        let z = if sphere {
            2.0 * rng.uniform() - 1.0
        } else {
            rng.uniform()
        };
        let phi = std::f32::consts::TAU * rng.uniform();
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }

    /// Every sample's weight is f |cos θi| / pdf, its pdf is `pdf`, for
    /// reflection and refraction from both sides.
    #[test]
    fn sampled_weight_is_f_cos_over_pdf() {
        let d = RoughDielectric::new(1.5, 0.5);
        let mut rng = Rng::from_key(21);
        let (mut refl, mut trans) = (0, 0);
        for _ in 0..4000 {
            let wo = dir(&mut rng, true);
            let Some(s) = d.sample(wo, rng.uniform3()) else {
                continue;
            };
            let (f, p) = (d.eval(wo, s.wi), d.pdf(wo, s.wi));
            assert!((s.pdf / p - 1.0).abs() < 2e-3, "pdf {} vs {p}", s.pdf);
            let want = f * s.wi.z.abs() / p;
            assert!(
                (s.weight / want - 1.0).abs() < 3e-3,
                "{} vs {want}",
                s.weight
            );
            if s.transmitted {
                trans += 1
            } else {
                refl += 1
            }
        }
        assert!(
            refl > 100 && trans > 2000,
            "{refl} reflected, {trans} refracted"
        );
    }

    /// Radiance BSDFs of refraction obey f(ωo, ωi) η'² = f(ωi, ωo), η' the
    /// index ratio across the interface from ωo's side (Veach 1997, §5.2);
    /// reflection is plainly symmetric. A missing or doubled 1/η'² fails.
    #[test]
    fn generalized_reciprocity() {
        let d = RoughDielectric::new(1.5, 0.4);
        let mut rng = Rng::from_key(4);
        for _ in 0..2000 {
            let (wo, wi) = (dir(&mut rng, true), dir(&mut rng, true));
            let scale = |w: Vec3, v: Vec3| {
                if w.z * v.z > 0.0 {
                    1.0
                } else if w.z > 0.0 {
                    1.5f32 * 1.5
                } else {
                    1.0 / (1.5 * 1.5)
                }
            };
            let a = d.eval(wo, wi) * scale(wo, wi);
            let b = d.eval(wi, wo);
            assert!(
                (a - b).abs() <= 3e-3 * a.max(b) + 1e-7,
                "{wo} {wi}: {a} vs {b}"
            );
        }
    }

    /// The albedo in importance units (weights × η'², so that a lossless
    /// interface gives 1), by quadrature of f |cos| and by sampling, from
    /// outside and inside: equal, at most 1, near 1 for a smooth-ish
    /// surface, the loss growing with roughness (single scattering).
    #[test]
    fn energy_by_quadrature_and_sampling_agree_and_loss_grows() {
        let mut last_loss = 0.0;
        for r in [0.2f32, 0.5, 1.0] {
            let d = RoughDielectric::new(1.5, r);
            let mut loss_out = 0.0;
            for mu in [0.5f32, -0.5] {
                let wo = from_mu(mu);
                let quad = albedo_by_quadrature(|wi| {
                    let crossed = wi.z * wo.z < 0.0;
                    let back = if !crossed {
                        1.0
                    } else if wo.z > 0.0 {
                        1.5f32 * 1.5
                    } else {
                        1.0 / (1.5 * 1.5)
                    };
                    d.eval(wo, wi) * back
                });
                let mut rng = Rng::from_key(8);
                let sampled = albedo_by_sampling(|u| {
                    let s = d.sample(wo, [u[0], u[1], rng.uniform()])?;
                    let etap = if wo.z > 0.0 { 1.5f32 } else { 1.0 / 1.5 };
                    let back = if s.transmitted { etap * etap } else { 1.0 };
                    Some(s.weight * back)
                });
                assert!(
                    (quad - sampled).abs() < 6e-3,
                    "r {r} μ {mu}: {quad} vs {sampled}"
                );
                assert!(quad <= 1.0 + 3e-3, "r {r} μ {mu}: {quad}");
                if mu > 0.0 {
                    loss_out = 1.0 - quad;
                }
            }
            assert!(loss_out >= last_loss - 2e-3, "r {r}: loss {loss_out}");
            last_loss = loss_out;
        }
    }
}
