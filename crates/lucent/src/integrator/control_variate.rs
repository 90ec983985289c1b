//! The plane control variate of the probe estimator (a control variate in
//! the sense of Owen, "Monte Carlo theory, methods and examples", 2013,
//! §8.9; in rendering, Lafortune & Willems 1994, "The ambient term as a
//! variance reducing technique"): at a subsurface exit point xo the path
//! estimates the light the medium carries there,
//!
//!   L(xo) = ∫_A Rd(|xo − xi|) g(xi) dA(xi),
//!
//! g(xi) the light entering at xi (next-event estimation through the entry
//! lobe), by one probe: L̂ = W·ĝ_nee(xi), W the probe weight
//! ([`crate::bssrdf::probe`]). On a smooth lit body most of that
//! estimate's variance is the probe weight's spread over the disk and the
//! light turning across it, both of which a model surface predicts: the
//! tangent plane at xo, lifted onto the sphere of xo's curvature.
//!
//! **The model.** A probe along the normal N with disk offset d would, on
//! the tangent plane, land at xo + d with weight W_plane = Rd(r)/(P(N)
//! p_disk(r)), r = |d| ([`PlaneModel`]). With g evaluated at the model
//! surface's point over xo + d (the sphere of xo's mean curvature κ,
//! [`model_point`]: sagitta and normal exact on that sphere), using the
//! same light sample as the real entry point's next-event estimation and
//! no shadow ray, let
//!
//!   ĝ(d) = g(0) + ½ (g(d) − g(−d)),
//!   C = 1[V = N] · ( W_plane · ĝ(d) − (A_plane / P(N)) · g(0) ),
//!
//! A_plane the profile's plane integral
//! ([`ProbeSampler::planar_reflectance`](crate::bssrdf::ProbeSampler::planar_reflectance)).
//! The path adds −β·f(κo)·C (β its throughput into the medium, f(κo) the
//! curvature correction the model surface would get everywhere) to what
//! the probe gives.
//!
//! **Why E\[C\] = 0, exactly.** Given the light sample, d is symmetric (φ
//! uniform) and W_plane depends on r only, so by [`PlaneModel`]'s identity
//! E\[1\[V=N\]·W_plane·ĝ(d)\] = ∫_disk Rd(|d|) ĝ(d) dA = A_plane·g(0): the odd
//! part ½(g(d) − g(−d)) integrates to 0 over the disk. And
//! E\[1\[V=N\]\] · A_plane/P(N) · g(0) = A_plane·g(0). The light sample is
//! drawn independently of the probe, so the mean over it is 0 too. The
//! estimator stays unbiased whatever g is; how much variance it removes
//! depends on how well W_plane·ĝ tracks W·g(xi) (measured below).
//!
//! **Why these pieces.** The odd part is what the antithetic pair cancels
//! between φ and φ + π (`super::path`'s module docs): here it is
//! subtracted at the cost of two evaluations of g without a ray, instead
//! of a second probe and shadow ray. The even part is not modelled (g(0)
//! stands for it): its mean is not known in closed form, and the
//! first-order model already takes most of the lit body's noise. Probes
//! along T and B get no term: on a smooth body they rarely hit, and their
//! rare hits are not predicted by the plane.
//!
//! **With the pair** ([`pair`]): the two probes' odd parts already cancel,
//! so only the radial part is modelled, ½Σ_k 1[V=N](W_plane − A_plane/P(N))
//! g_k(0) over the two light samples k, mean 0 by the same identity.
//!
//! **Bound.** For the exact radius samplers Rd_c(r)/p_c(r) ≤ n_active·A_c
//! (the probe module's weight bound with |V·N| = 1), and P(N) ≥ ½, so
//! |C| ≤ (2·|ĝ| + 1)·2·n_active·A·max g ≤ 6·n_active·A·max g per channel,
//! max g over the three model points: the term never exceeds a small
//! multiple of what light at xo itself would give, and cannot create a
//! firefly. It can make a pixel of few samples slightly negative where the
//! model surface is lit and the real surface is in shadow (the term has no
//! shadow ray); the mean is unaffected.
//!
//! **Measured** (docs/accuracy.md, "The plane control variate"): on
//! scenes/smooth-sphere.toml one probe with the term has 0.43× the relMSE
//! per sample of one probe without it, for 14 % more instructions; the
//! antithetic pair, which it replaces as the default, has 0.84× its
//! relMSE for 25 % more, so the two reach a given error in about the same
//! work (the pair 5 % slower). On the marble bunny it gains ~4 %.

use crate::bssrdf::PlaneModel;
use crate::geometry::Vec3;

/// Subsurface hits at depths below this add the plane control variate
/// (module docs). 1: the camera vertex only (the default of
/// [`super::Context::cv_depth`]); deeper vertices carry little of the
/// image and their light is already averaged over many paths.
pub(crate) const CV_DEPTH: u32 = 1;

/// Whether the control variate applies at a subsurface hit at `depth`:
/// below the context's depth, and only where there is an area light to
/// sample (it models next-event estimation).
#[inline]
pub fn applies(cv_depth: u32, area_lights: bool, depth: u32) -> bool {
    depth < cv_depth && area_lights
}

/// The model surface's point over the disk offset `d` (⟂ `n`, the unit
/// normal at `xo`): on the sphere of curvature `kappa` (≥ 0; 0 is the
/// plane) tangent to the surface at xo, the point xo + d − s·n with the
/// sagitta s = κr²/(1 + √(1 − κ²r²)), and its unit normal
/// √(1 − κ²r²)·n + κ·d, both exact on that sphere (r = |d|). Beyond the
/// sphere's silhouette (κr > 1) the silhouette's point.
#[inline]
pub fn model_point(xo: Vec3, n: Vec3, kappa: f32, d: Vec3) -> (Vec3, Vec3) {
    let r2 = d.length_squared();
    let k = kappa.max(0.0);
    let kr2 = k * k * r2;
    if kr2 >= 1.0 {
        // The silhouette: s = 1/κ, normal along d.
        let r = r2.sqrt();
        return (xo + d * (1.0 / (k * r)) - n * (1.0 / k), d / r);
    }
    let c = (1.0 - kr2).sqrt();
    let s = k * r2 / (1.0 + c);
    (xo + d - n * s, n * c + d * k)
}

/// C for one probe (module docs) from g at the model's points over 0, d
/// and −d, per channel; `a_plane` is A_plane. Zero for probes along T or
/// B, which have no [`PlaneModel`].
#[inline]
pub(crate) fn one_probe(
    plane: &PlaneModel,
    a_plane: Vec3,
    g0: Vec3,
    g_d: Vec3,
    g_minus_d: Vec3,
) -> Vec3 {
    let g_hat = g0 + 0.5 * (g_d - g_minus_d);
    plane.weight * g_hat - (a_plane / plane.p_normal) * g0
}

/// C for an antithetic pair (module docs): ½ Σ_k (W_plane − A_plane/P(N))
/// g_k(0), g_k the light sample k's light at xo; the odd parts cancel
/// between the pair's probes and are not modelled.
#[inline]
pub fn pair(plane: &PlaneModel, a_plane: Vec3, g0: [Vec3; 2]) -> Vec3 {
    0.5 * (plane.weight - a_plane / plane.p_normal) * (g0[0] + g0[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::{ProbeOptions, ProbeRandoms, ProbeSampler, SubsurfaceParams};
    use crate::geometry::Frame;
    use crate::sampling::Rng;

    /// A material with channels 3× apart and its default sampler.
    fn sampler() -> ProbeSampler {
        let params = SubsurfaceParams {
            albedo: [0.8, 0.5, 0.3],
            d: [1.0, 0.35, 0.1],
            eta: 1.3,
            medium: None,
        };
        ProbeSampler::new(&params, &ProbeOptions::default()).unwrap()
    }

    /// A light seen from near xo: a smooth function of the point and normal
    /// with linear, quadratic and angular parts (what g is on a lit body),
    /// scaled by a per-sample factor (the light sample's own randomness).
    fn light(p: Vec3, n: Vec3, s: f32) -> Vec3 {
        let to = Vec3::new(2.0, 0.5, 3.0) - p;
        let cos = n.dot(to.normalize()).max(0.0);
        let g = s * cos / to.length_squared() * (1.0 + 0.3 * p.x * p.x);
        Vec3::new(g, 0.8 * g, 0.5 * g)
    }

    /// Mean and standard error of C·scale over `n` probes at xo (frame
    /// tilted, curvature κ) for the term `c`, per channel.
    fn mean_of(
        n: usize,
        c: impl Fn(&ProbeSampler, &PlaneModel, Vec3, f32, f32) -> Vec3,
    ) -> ([f64; 3], [f64; 3]) {
        let s = sampler();
        let frame = Frame::from_normal(Vec3::new(0.1, -0.2, 1.0).normalize());
        // κ·d ≈ 0.3: ε ≈ 0.01, so most probes are along N
        let kappa = 0.3;
        let mut rng = Rng::from_key(11);
        let (mut s1, mut s2) = ([0f64; 3], [0f64; 3]);
        for _ in 0..n {
            let u = ProbeRandoms::from_rng(&mut rng);
            let (ls1, ls2) = (rng.uniform_f64() as f32, rng.uniform_f64() as f32);
            let (_, plane) = s
                .sample_probe_and_plane(Vec3::ZERO, &frame, kappa, &u)
                .unwrap();
            let v = match plane {
                Some(pm) => c(&s, &pm, frame.n, ls1, ls2),
                None => Vec3::ZERO,
            };
            for k in 0..3 {
                s1[k] += v[k] as f64;
                s2[k] += (v[k] as f64).powi(2);
            }
        }
        let nf = n as f64;
        let mean = s1.map(|x| x / nf);
        let se = std::array::from_fn(|k| ((s2[k] / nf - mean[k] * mean[k]) / nf).sqrt());
        (mean, se)
    }

    fn a_plane(s: &ProbeSampler) -> Vec3 {
        Vec3::from_array(s.planar_reflectance().map(|a| a as f32))
    }

    /// g at the model point over d.
    fn g(n: Vec3, d: Vec3, ls: f32) -> Vec3 {
        let (p, m) = model_point(Vec3::ZERO, n, 0.3, d);
        light(p, m, ls)
    }

    /// E[C] = 0 within 5 standard errors per channel, the error not 0 (a
    /// term that is always 0 would pass vacuously).
    fn assert_mean_zero(mean: [f64; 3], se: [f64; 3]) {
        for k in 0..3 {
            assert!(
                mean[k].abs() < 5.0 * se[k] && se[k] > 0.0,
                "ch{k}: E[C] = {} ± {}",
                mean[k],
                se[k]
            );
        }
    }

    #[test]
    fn the_term_has_mean_zero_at_a_lit_exit_point() {
        // E[C] = 0 (module docs) for a light that is linear, quadratic and
        // angular across the disk: the odd part integrates to 0, and
        // W_plane·g(0) to A_plane/P(N)·g(0) over the normal probes. A
        // wrong weight, a wrong A_plane/P(N) or an even part in ĝ breaks
        // it. Seen by hand, red channel: ĝ = g(0) + ½(g(d) + g(−d)) gives
        // E[C] = 0.0147 ± 0.00005; A_plane without the 1/P(N), 0.0039 ±
        // 0.00004 (and the pair's term without it, next test, 0.0039 ±
        // 0.00004).
        let (mean, se) = mean_of(400_000, |s, pm, n, ls, _| {
            let d = pm.offset;
            one_probe(
                pm,
                a_plane(s),
                g(n, Vec3::ZERO, ls),
                g(n, d, ls),
                g(n, -d, ls),
            )
        });
        assert_mean_zero(mean, se);
    }

    #[test]
    fn the_pairs_term_has_mean_zero_at_a_lit_exit_point() {
        let (mean, se) = mean_of(400_000, |s, pm, n, l1, l2| {
            pair(pm, a_plane(s), [g(n, Vec3::ZERO, l1), g(n, Vec3::ZERO, l2)])
        });
        assert_mean_zero(mean, se);
    }

    #[test]
    fn the_term_cancels_a_linear_light_on_a_plane_exactly() {
        // On the plane (κ = 0) with g linear in d, ĝ(d) = g(d): W_plane·g(d)
        // is then what a probe hitting the plane at xo + d weighs, and C is
        // that minus its known mean; a light constant across the disk
        // leaves (W_plane − A_plane/P(N))·g alone.
        let s = sampler();
        let frame = Frame::from_normal(Vec3::Z);
        let mut rng = Rng::from_key(3);
        let a = a_plane(&s);
        let lin = |d: Vec3| Vec3::splat(1.0 + 0.5 * d.x - 0.25 * d.y);
        let mut normal_probes = 0;
        for _ in 0..2000 {
            let u = ProbeRandoms::from_rng(&mut rng);
            let Some((_, Some(pm))) = s.sample_probe_and_plane(Vec3::ZERO, &frame, 0.0, &u) else {
                continue;
            };
            normal_probes += 1;
            let d = pm.offset;
            assert!(d.z.abs() < 1e-6 && d.length() <= s.rmax() as f32 * 1.0001);
            let c = one_probe(&pm, a, lin(Vec3::ZERO), lin(d), lin(-d));
            let want = pm.weight * lin(d) - a / pm.p_normal * lin(Vec3::ZERO);
            assert!((c - want).abs().max_element() < 1e-4 * (1.0 + want.abs().max_element()));
        }
        assert!(normal_probes > 1900, "{normal_probes} of 2000 along N");
    }

    #[test]
    fn the_pairs_term_removes_the_radial_spread_of_its_two_light_samples() {
        // On the plane under a light constant across the disk, the pair's
        // probes both land on the model with weight W_plane and see their
        // own light samples g_1, g_2 at xo: the pair gives ½ W_plane (g_1 +
        // g_2), and less its term that must be (A_plane/P(N))·½(g_1 + g_2),
        // the same for every radius. Each sample's light must enter with
        // its own sign: a term built from g_1 − g_2 keeps the mean (the
        // samples are alike) but no longer cancels the spread, and fails
        // here.
        let s = sampler();
        let frame = Frame::from_normal(Vec3::Z);
        let mut rng = Rng::from_key(5);
        let a = a_plane(&s);
        let mut normal_probes = 0;
        for _ in 0..2000 {
            let u = ProbeRandoms::from_rng(&mut rng);
            let g1 = Vec3::splat(0.2 + rng.uniform_f64() as f32);
            let g2 = Vec3::new(1.5, 0.7, 0.1) * rng.uniform_f64() as f32;
            let Some((_, Some(pm))) = s.sample_probe_and_plane(Vec3::ZERO, &frame, 0.0, &u) else {
                continue;
            };
            normal_probes += 1;
            let estimate = 0.5 * pm.weight * (g1 + g2);
            let left = estimate - pair(&pm, a, [g1, g2]);
            let want = a / pm.p_normal * 0.5 * (g1 + g2);
            let scale = 1.0 + estimate.abs().max_element();
            assert!(
                (left - want).abs().max_element() < 1e-5 * scale,
                "{left:?} against {want:?}"
            );
        }
        assert!(normal_probes > 1900, "{normal_probes} of 2000 along N");
    }

    #[test]
    fn model_points_lie_on_the_sphere_with_its_normals() {
        let (xo, n, k) = (Vec3::new(1.0, 2.0, 3.0), Vec3::Z, 0.5f32);
        let centre = xo - n / k;
        for d in [
            Vec3::new(0.3, 0.0, 0.0),
            Vec3::new(-1.0, 1.2, 0.0),
            Vec3::new(0.0, -1.9, 0.0),
        ] {
            let (p, m) = model_point(xo, n, k, d);
            assert!(((p - centre).length() - 1.0 / k).abs() < 1e-5, "{p:?}");
            assert!((m - (p - centre) * k).length() < 1e-5, "{m:?}");
            // over xo + d: the same tangential coordinates
            assert!(((p - xo).truncate() - d.truncate()).length() < 1e-5);
        }
        // beyond the silhouette (κr > 1): the silhouette's point over d,
        // on the sphere, its normal along d
        for d in [Vec3::new(2.5, 0.0, 0.0), Vec3::new(-3.0, 4.0, 0.0)] {
            let (p, m) = model_point(xo, n, k, d);
            assert!(((p - centre).length() - 1.0 / k).abs() < 1e-5, "{p:?}");
            assert!((m - d.normalize()).length() < 1e-6, "{m:?}");
            assert!((p - (centre + d.normalize() / k)).length() < 1e-5, "{p:?}");
        }
        // the plane: no sagitta, the same normal
        let d = Vec3::new(0.7, -0.2, 0.0);
        assert_eq!(model_point(xo, n, 0.0, d), (xo + d, n));
    }
}
