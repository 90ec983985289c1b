//! The rough coat of a subsurface material: reflection off a dielectric
//! interface of relative index η whose microfacet normals follow the GGX
//! (Trowbridge–Reitz) distribution, α = roughness² (Walter et al. 2007;
//! Heitz 2014, 2018; pbrt-v4 §9.6). Directions are local to the shading
//! frame, z = the macro-surface normal on the outside, where light arrives.
//!
//! D, Smith's height-correlated G2, the Torrance–Sparrow BRDF with the
//! coat's Fresnel ([`crate::fresnel::dielectric`]), visible-normal sampling
//! and the tabulated directional albedo E(μo) ([`RoughCoat`]) with its
//! accuracy: `docs/bssrdf.md` §12.7. Below [`SMOOTH_ALPHA`] the interface
//! is a mirror and the material uses its smooth coat instead.
//!
//! This file depends only on geometry, sampling and Fresnel: no ray queries.

use super::albedo_table::{shared, AlbedoTable, TableKey};
use crate::fresnel;
use crate::geometry::Vec3;
use crate::sampling::concentric_disk;
use std::f32::consts::PI;
use std::sync::Arc;

/// Below this α the interface is treated as smooth (pbrt-v4's threshold).
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// Midpoint-rule points per side of the sampling square for each node of
/// the albedo table.
const QUADRATURE_SIDE: usize = 64;

/// α from the scene's roughness ∈ [0, 1]: α = roughness².
pub(crate) fn alpha_from_roughness(roughness: f32) -> f32 {
    roughness * roughness
}

/// The isotropic GGX distribution of microfacet normals, width α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    pub alpha: f32,
}

impl Ggx {
    /// D(m) per steradian of m (0 below the surface).
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        // (α² − 1) cos²θ + 1 = α² cos²θ + sin²θ, with sin²θ = x² + y²
        // exact where 1 − cos²θ would cancel (narrow lobes, m near z).
        let a2 = self.alpha * self.alpha;
        let t = a2 * m.z * m.z + (m.x * m.x + m.y * m.y);
        a2 / (PI * t * t)
    }

    /// Smith's Λ(ω); infinite at the horizon.
    pub(crate) fn lambda(&self, w: Vec3) -> f32 {
        let c2 = w.z * w.z;
        if c2 <= 0.0 {
            return f32::INFINITY;
        }
        let x = self.alpha * self.alpha * (w.x * w.x + w.y * w.y) / c2;
        0.5 * x / ((1.0 + x).sqrt() + 1.0)
    }

    /// G1(ω) = 1 / (1 + Λ(ω)).
    pub(crate) fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// G2(ωo, ωi) = 1 / (1 + Λ(ωo) + Λ(ωi)), height-correlated.
    pub(crate) fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// A microfacet normal m visible from `wo` (wo.z > 0), drawn from
    /// D_ωo(m) (Heitz 2018, listing 1, with the concentric disk map).
    #[inline(always)]
    pub(crate) fn sample_visible(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        self.visible_from_disk(wo, concentric_disk(u))
    }

    /// The visible normal of [`Ggx::sample_visible`] for the point `p` of
    /// the unit disk (uniform points give D_ωo).
    #[inline(always)]
    pub(crate) fn visible_from_disk(&self, wo: Vec3, p: [f32; 2]) -> Vec3 {
        let a = self.alpha;
        // The view direction in the hemisphere configuration (α = 1).
        let wh = Vec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        let t1 = if wh.z < 0.99999 {
            Vec3::Z.cross(wh).normalize()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        // A uniform disk point, warped onto the projected visible half.
        let [px, py] = p;
        let h = (1.0 - px * px).max(0.0).sqrt();
        let s = 0.5 * (1.0 + wh.z);
        let py = (1.0 - s) * h + s * py;
        let pz = (1.0 - px * px - py * py).max(0.0).sqrt();
        let nh = t1 * px + t2 * py + wh * pz;
        // Back to the ellipsoid configuration.
        Vec3::new(a * nh.x, a * nh.y, nh.z.max(1e-6)).normalize()
    }
}

/// The mirror direction of `wo` about the unit normal `m`.
pub(crate) fn reflect(wo: Vec3, m: Vec3) -> Vec3 {
    2.0 * wo.dot(m) * m - wo
}

/// A dielectric GGX coat: the BRDF of its reflection and its directional
/// albedo table.
#[derive(Clone, Debug)]
pub struct RoughCoat {
    pub ggx: Ggx,
    pub eta: f32,
    /// E(μ) and its cosine-weighted mean Ē, the coat's albedo under
    /// uniform light: the shared table of this α and η, or a blend of the
    /// tables at the roughness steps around it ([`RoughCoat::with_table`]).
    albedo: AlbedoTable,
}

impl PartialEq for RoughCoat {
    fn eq(&self, o: &Self) -> bool {
        self.ggx == o.ggx && self.eta == o.eta
    }
}

impl RoughCoat {
    /// The coat of width `alpha` (≥ [`SMOOTH_ALPHA`]) and index `eta`, with
    /// its albedo table.
    pub fn new(alpha: f32, eta: f32) -> Self {
        Self::with_table(alpha, eta, *Self::table(alpha, eta))
    }

    /// The coat of width `alpha` and index `eta` whose albedo is `albedo`
    /// (a blend of the tables of nearby roughnesses).
    pub fn with_table(alpha: f32, eta: f32, albedo: AlbedoTable) -> Self {
        RoughCoat {
            ggx: Ggx { alpha },
            eta,
            albedo,
        }
    }

    /// The albedo table of the coat of width `alpha` and index `eta`,
    /// built once per process.
    pub fn table(alpha: f32, eta: f32) -> Arc<AlbedoTable> {
        let key = TableKey::Coat {
            alpha: alpha.to_bits(),
            eta: eta.to_bits(),
        };
        // Sampling the coat, which the quadrature does, never reads the
        // table: an empty one stands in while it is built.
        let bare = Self::with_table(alpha, eta, AlbedoTable::default());
        shared(key, || {
            AlbedoTable::new(|mu| bare.albedo_quadrature(mu, QUADRATURE_SIDE))
        })
    }

    /// E(μo) by an n × n midpoint rule over the sampling square.
    pub(crate) fn albedo_quadrature(&self, mu: f32, n: usize) -> f64 {
        let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
                if let Some((_, w, _)) = self.sample(wo, u) {
                    sum += w as f64;
                }
            }
        }
        sum / (n * n) as f64
    }

    /// E(μ), linearly interpolated in μ between the table's nodes (μ
    /// clamped to [0, 1]).
    pub fn albedo(&self, mu: f32) -> f32 {
        self.albedo.at(mu)
    }

    /// 2 ∫₀¹ E(μ) μ dμ: the fraction of uniform incident light reflected.
    pub(crate) fn mean_albedo(&self) -> f32 {
        self.albedo.mean()
    }

    /// f(ωo, ωi) per steradian; 0 unless both are above the surface.
    pub(crate) fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(h) = half_vector(wo, wi) else {
            return 0.0;
        };
        let fr = fresnel::dielectric(wo.dot(h), self.eta);
        self.ggx.d(h) * self.ggx.g2(wo, wi) * fr / (4.0 * wo.z * wi.z)
    }

    /// The solid-angle density with which [`RoughCoat::sample`] returns ωi.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(h) = half_vector(wo, wi) else {
            return 0.0;
        };
        self.ggx.g1(wo) * self.ggx.d(h) / (4.0 * wo.z)
    }

    /// Samples ωi by visible normals; returns (ωi, f cos θi / pdf, pdf), or
    /// None when the mirrored direction is below the surface.
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<(Vec3, f32, f32)> {
        if wo.z <= 0.0 {
            return None;
        }
        let m = self.ggx.sample_visible(wo, u);
        let wi = reflect(wo, m);
        let cos_om = wo.dot(m);
        if wi.z <= 0.0 || cos_om <= 0.0 {
            return None;
        }
        let g1 = self.ggx.g1(wo);
        let pdf = g1 * self.ggx.d(m) / (4.0 * wo.z);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let w = fresnel::dielectric(cos_om, self.eta) * self.ggx.g2(wo, wi) / g1;
        Some((wi, w, pdf))
    }
}

/// The unit half vector of a reflection, ωh = (ωo + ωi)/|ωo + ωi|; None
/// unless both directions are above the surface (and their sum nonzero),
/// where the coat reflects nothing.
fn half_vector(wo: Vec3, wi: Vec3) -> Option<Vec3> {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return None;
    }
    let h = wo + wi;
    (h.length_squared() != 0.0).then(|| h.normalize())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn dir(theta: f64, phi: f64) -> Vec3 {
        Vec3::new(
            (theta.sin() * phi.cos()) as f32,
            (theta.sin() * phi.sin()) as f32,
            theta.cos() as f32,
        )
    }

    /// ∫ g(ω) dω over the upper hemisphere by the midpoint rule in (θ, φ).
    fn hemisphere(nt: usize, np: usize, g: impl Fn(Vec3) -> f64) -> f64 {
        let (dt, dp) = (
            std::f64::consts::FRAC_PI_2 / nt as f64,
            std::f64::consts::TAU / np as f64,
        );
        let mut s = 0.0;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * dt;
            for j in 0..np {
                let p = (j as f64 + 0.5) * dp;
                s += g(dir(t, p)) * t.sin() * dt * dp;
            }
        }
        s
    }

    #[test]
    fn d_is_normalized_projected_on_the_normal() {
        for alpha in [0.001f32, 0.01, 0.1, 0.5, 1.0] {
            let g = Ggx { alpha };
            // isotropic: a 1-D integral in θ, fine enough for the narrowest lobe
            let n = 400_000;
            let dt = std::f64::consts::FRAC_PI_2 / n as f64;
            let s: f64 = (0..n)
                .map(|i| {
                    let t = (i as f64 + 0.5) * dt;
                    let m = dir(t, 0.0);
                    g.d(m) as f64 * t.cos() * t.sin() * std::f64::consts::TAU * dt
                })
                .sum();
            assert!((s - 1.0).abs() < 2e-3, "α = {alpha}: ∫ D cos = {s}");
        }
    }

    /// Smith's G1 is the projected-area ratio: ∫ G1(ωo) max(0, ωo·m) D(m) dm = cos θo
    /// (Heitz 2014, eq. 2), which is what makes D_ωo a density.
    #[test]
    fn visible_normals_are_normalized() {
        for alpha in [0.2f32, 0.6] {
            let g = Ggx { alpha };
            for theta in [0.2f64, 1.0, 1.4] {
                let wo = dir(theta, 0.3);
                let s = g.g1(wo) as f64
                    * hemisphere(1500, 600, |m| g.d(m) as f64 * (wo.dot(m).max(0.0)) as f64)
                    / wo.z as f64;
                assert!((s - 1.0).abs() < 3e-3, "α {alpha} θo {theta}: {s}");
            }
        }
    }

    #[test]
    fn brdf_is_reciprocal_and_sampled_weight_equals_evaluated() {
        let coat = RoughCoat::new(0.3, 1.5);
        let mut rng = Rng::from_key(7);
        let mut checked = 0;
        for _ in 0..2000 {
            let wo = dir(
                rng.uniform_f64() * 1.55,
                rng.uniform_f64() * std::f64::consts::TAU,
            );
            let wi = dir(
                rng.uniform_f64() * 1.55,
                rng.uniform_f64() * std::f64::consts::TAU,
            );
            let (a, b) = (coat.eval(wo, wi), coat.eval(wi, wo));
            assert!((a - b).abs() <= 1e-4 * a.max(b), "{a} vs {b}");
            if let Some((wi, w, pdf)) = coat.sample(wo, rng.uniform2()) {
                let (f, p) = (coat.eval(wo, wi), coat.pdf(wo, wi));
                assert!((p / pdf - 1.0).abs() < 1e-3, "pdf {p} vs {pdf}");
                let w_eval = f * wi.z / p;
                assert!((w / w_eval - 1.0).abs() < 2e-3, "weight {w} vs {w_eval}");
                assert!(w <= 1.0 + 1e-6);
                checked += 1;
            }
        }
        assert!(checked > 1500);
    }

    /// χ² of sampled directions against the pdf, on a (cos θ, φ) grid, plus
    /// one bin for the samples lost below the horizon.
    #[test]
    fn vndf_samples_follow_their_pdf_chi_square() {
        for (alpha, theta_o) in [(0.1f32, 0.5f64), (0.3, 1.2), (0.8, 0.2), (0.8, 1.45)] {
            let coat = RoughCoat::new(alpha, 1.5);
            let wo = dir(theta_o, 0.0);
            let (nt, np) = (24, 24);
            let mut counts = vec![0f64; nt * np + 1];
            let mut rng = Rng::from_key(11 + (alpha * 100.0) as u64);
            let n = 400_000;
            for _ in 0..n {
                match coat.sample(wo, rng.uniform2()) {
                    Some((wi, _, _)) => {
                        let i = ((wi.z as f64 * nt as f64) as usize).min(nt - 1);
                        let phi = (wi.y as f64)
                            .atan2(wi.x as f64)
                            .rem_euclid(std::f64::consts::TAU);
                        let j = ((phi / std::f64::consts::TAU * np as f64) as usize).min(np - 1);
                        counts[i * np + j] += 1.0;
                    }
                    None => counts[nt * np] += 1.0,
                }
            }
            // expected: the pdf integrated over each bin (16 × 16 points)
            let sub = 16;
            let mut expected = vec![0f64; nt * np + 1];
            for i in 0..nt {
                for j in 0..np {
                    let mut s = 0.0;
                    for a in 0..sub {
                        for b in 0..sub {
                            let z = (i as f64 + (a as f64 + 0.5) / sub as f64) / nt as f64;
                            let p = (j as f64 + (b as f64 + 0.5) / sub as f64) / np as f64
                                * std::f64::consts::TAU;
                            let r = (1.0 - z * z).sqrt();
                            let wi =
                                Vec3::new((r * p.cos()) as f32, (r * p.sin()) as f32, z as f32);
                            s += coat.pdf(wo, wi) as f64;
                        }
                    }
                    // dω = dz dφ
                    expected[i * np + j] = n as f64 * s / (sub * sub) as f64
                        * (1.0 / nt as f64)
                        * (std::f64::consts::TAU / np as f64);
                }
            }
            let upper: f64 = expected[..nt * np].iter().sum();
            expected[nt * np] = (n as f64 - upper).max(0.0);
            let (mut chi2, mut dof) = (0.0, 0usize);
            let (mut o, mut e) = (0.0, 0.0);
            for b in 0..expected.len() {
                o += counts[b];
                e += expected[b];
                if e >= 20.0 || b == expected.len() - 1 {
                    if e > 0.0 {
                        chi2 += (o - e) * (o - e) / e;
                        dof += 1;
                    }
                    o = 0.0;
                    e = 0.0;
                }
            }
            let dof = dof - 1;
            let limit = dof as f64 + 5.0 * (2.0 * dof as f64).sqrt();
            assert!(chi2 < limit, "α {alpha} θo {theta_o}: χ² {chi2}, dof {dof}");
        }
    }

    /// White furnace of the coat alone: ∫ f cos θi dωi, integrated over
    /// directions (independently of the sampler), is E(μo) ≤ 1, and the
    /// table holds it; for η = 1 nothing is reflected.
    #[test]
    fn directional_albedo_is_the_integral_of_f_cos_and_the_table_holds_it() {
        // The quadrature the table is built from, at a finer side, is the
        // same integral to 6·10⁻⁴ (measured ≤ 2.6·10⁻⁴ at these μ; a view
        // direction off by a wrong sin θ, 1 − 2μ for 1 − μ², moved it by
        // up to 3.7·10⁻³, inside the table's own tolerance).
        for alpha in [0.1f32, 0.3, 1.0] {
            let coat = RoughCoat::new(alpha, 1.5);
            for mu in [0.15f32, 0.3, 0.5, 0.8, 0.95] {
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let direct = hemisphere(1200, 600, |wi| (coat.eval(wo, wi) * wi.z) as f64);
                assert!(direct <= 1.0);
                let table = coat.albedo(mu) as f64;
                assert!(
                    (direct - table).abs() < 4e-3,
                    "α {alpha} μ {mu}: ∫ f cos = {direct}, E = {table}"
                );
                let quadrature = coat.albedo_quadrature(mu, 256);
                assert!(
                    (direct - quadrature).abs() < 6e-4,
                    "α {alpha} μ {mu}: ∫ f cos = {direct}, quadrature {quadrature}"
                );
            }
        }
        let clear = RoughCoat::new(0.5, 1.0);
        assert!(clear.albedo(0.5) < 1e-6 && clear.mean_albedo() < 1e-6);
    }

    /// The scene's roughness is α = roughness², and the coat is smooth
    /// below α = 10⁻³, i.e. roughness < 0.032 (docs/scene-format.md).
    #[test]
    fn roughness_maps_to_alpha_squared() {
        for r in [0.1f32, 0.3, 0.5, 0.7, 1.0] {
            assert!(
                (alpha_from_roughness(r) - r * r).abs() <= 1e-7,
                "roughness {r}"
            );
        }
        assert_eq!(alpha_from_roughness(0.0), 0.0);
        assert!(alpha_from_roughness(0.031) < SMOOTH_ALPHA);
        assert!(alpha_from_roughness(0.032) >= SMOOTH_ALPHA);
    }

    /// The coat only reflects: f and its pdf are 0 when either direction
    /// is below the surface (a light behind it must get nothing).
    #[test]
    fn nothing_is_reflected_to_or_from_below_the_surface() {
        let coat = RoughCoat::new(0.5, 1.5);
        for (a, b) in [(0.3f64, 2.0f64), (1.2, 1.7), (0.0, 2.9), (1.5, 1.6)] {
            let (up, down) = (dir(a, 0.4), dir(b, 2.5));
            assert!(up.z > 0.0 && down.z < 0.0);
            for (wo, wi) in [(up, down), (down, up), (down, down)] {
                assert_eq!(coat.eval(wo, wi), 0.0, "{wo} {wi}");
                assert_eq!(coat.pdf(wo, wi), 0.0, "{wo} {wi}");
            }
        }
    }

    /// Two coats are the same material exactly when α and η agree (the
    /// table is a function of them).
    #[test]
    fn coats_are_equal_when_alpha_and_eta_are() {
        let c = RoughCoat::new(0.3, 1.5);
        assert_eq!(c, RoughCoat::new(0.3, 1.5));
        assert_ne!(c, RoughCoat::new(0.4, 1.5));
        assert_ne!(c, RoughCoat::new(0.3, 1.4));
        assert_ne!(c, RoughCoat::new(0.4, 1.4));
    }

    /// The table's stated error: within 5·10⁻³ of a 512² quadrature between
    /// and at nodes, for narrow to wide lobes.
    #[test]
    fn albedo_table_error_is_within_its_bound() {
        for alpha in [SMOOTH_ALPHA, 0.01, 0.09, 0.3, 1.0] {
            let coat = RoughCoat::new(alpha, 1.5);
            for mu in [0.003f32, 0.02, 0.11, 0.37, 0.5, 0.83, 1.0] {
                let fine = coat.albedo_quadrature(mu.max(1e-4), 512);
                let table = coat.albedo(mu) as f64;
                assert!(
                    (fine - table).abs() < 5e-3,
                    "α {alpha} μ {mu}: table {table}, fine {fine}"
                );
            }
            // a narrow lobe reflects about what a mirror does (Fr) away
            // from grazing
            if alpha <= 0.01 {
                let fr = fresnel::dielectric(0.5, 1.5) as f64;
                assert!((coat.albedo(0.5) as f64 - fr).abs() < 2e-3);
            }
        }
    }

    #[test]
    fn coats_share_a_table_only_when_alpha_and_eta_agree() {
        // a table keyed by α alone would give the η = 1.5 coat the η = 1.3
        // coat's albedo
        let a = RoughCoat::new(0.09, 1.3);
        let b = RoughCoat::new(0.09, 1.3);
        let c = RoughCoat::new(0.09, 1.5);
        let d = RoughCoat::new(0.16, 1.3);
        let table = |c: &RoughCoat| Arc::as_ptr(&RoughCoat::table(c.ggx.alpha, c.eta));
        assert_eq!(table(&a), table(&b));
        assert!(table(&a) != table(&c) && table(&a) != table(&d));
        assert_ne!(a.albedo, c.albedo);
        assert!(
            c.mean_albedo() > a.mean_albedo(),
            "a higher index reflects more"
        );
        assert_eq!(c.albedo(0.5), RoughCoat::new(0.09, 1.5).albedo(0.5));
    }
}
