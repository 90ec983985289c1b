//! The plane model of the probe estimator, used as a positivised control
//! variate (in the sense of Owen, "Monte Carlo theory, methods and
//! examples", 2013, §8.9 for control variates and Owen & Zhou 2000, "Safe
//! and effective importance sampling", for positivisation; in rendering,
//! Lafortune & Willems 1994): at a subsurface exit point xo the path
//! estimates the light the medium carries there,
//!
//!   L(xo) = ∫_A Rd(|xo − xi|) g(xi) dA(xi),
//!
//! g(xi) the light entering at xi (next-event estimation through the entry
//! lobe), by one probe: L̂ = W·ĝ_nee(xi), W the probe weight
//! ([`crate::bssrdf::probe`]). On a smooth lit body much of that
//! estimate's variance is the light turning across the disk, which a
//! model surface predicts: the tangent plane at xo, lifted onto the sphere
//! of xo's curvature (`docs/bssrdf.md` §5).
//!
//! **The model.** A probe along the normal N with disk offset d has a
//! mirror, the probe at φ + π with offset −d (the antithetic pair's twin,
//! [`PlaneModel`](crate::bssrdf::PlaneModel); the same radius, axis and channel, so the same plane
//! weight). With g evaluated at the model surface's point over xo ± d (the
//! sphere of xo's mean curvature κ, [`model_point`]), using the light
//! sample the real entry point's next-event estimation will use and no
//! shadow ray, the model predicts
//!
//!   ĝ(±d) = g(0) ± ½ (g(d) − g(−d)),
//!
//! the light at the two probes' entry points to first order (the even part
//! is left as g(0)).
//!
//! **The estimator: a choice, not a subtraction.** An additive control
//! variate (L̂ − W_plane·ĝ(d) + its known mean) keeps the mean but crosses
//! zero wherever the model is lit and the real surface is not (a cast
//! shadow, a probe that misses): no additive term without a ray can be
//! bounded by what the real probe finds. Instead the path follows one of
//! the two mirrored probes, d with probability p₊ and −d with p₋ = 1 − p₊,
//!
//!   p± = y± / (y₊ + y₋),  y± = max(Σ_c ĝ_c(±d), 0),
//!
//! clamped to [ε, 1 − ε] ([`EPSILON`]; ½ when both are 0), and multiplies
//! the chosen probe's weight by 1/(2 p_s) ([`MirrorChoice`]). Every factor
//! is positive, so every estimate keeps the sign of the plain probe's: no
//! pass can go below zero.
//!
//! **Why it is unbiased, exactly.** Given d, the estimate's mean over the
//! choice is p₊·X(d)/(2p₊) + p₋·X(−d)/(2p₋) = ½(X(d) + X(−d)), for any p₊ in
//! (0, 1) — whatever the model says, right or wrong. And −d has the same
//! distribution as d (φ is uniform), so E[½(X(d) + X(−d))] = E[X(d)]: the
//! one probe's mean. Probes along T and B have no plane model and follow d
//! with probability 1 (the plain probe).
//!
//! **Why it removes the odd part.** Where the real light is what the model
//! predicts up to a factor k (X(±d) = k·W_plane·ĝ(±d)), the estimate is
//! k·W_plane·ĝ(±d)/(2p±) = k·W_plane·g(0) for either choice: the light's
//! turn across the disk, the part the antithetic pair cancels with a
//! second probe and shadow ray, is gone with one of each. The radial part
//! (W_plane's spread over r) is left: it is a per-channel factor that one
//! scalar choice cannot follow, and its additive correction is the one
//! that crossed zero.
//!
//! **Bound.** 1/(2p_s) ≤ 1/(2ε): the chosen probe's weight grows at most
//! that much over the plain probe's bound, where the model is badly wrong
//! (the mirror the model favours in shadow).
//!
//! **Measured** in docs/accuracy.md, "The plane model at the camera
//! vertex".

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

/// The clamp of the mirror choice's probabilities (module docs): the
/// chosen probe's weight grows by at most 1/(2ε) = 4. Chosen by the
/// relMSE×spp it gives on the smooth sphere and the marble bunny
/// (docs/accuracy.md, "The plane control variate").
pub const EPSILON: f32 = 1.0 / 8.0;

/// Which of a probe and its mirror the path follows, and the factor on
/// the followed probe's weight (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MirrorChoice {
    /// Follow the mirror (offset −d) rather than the probe (d).
    pub mirror: bool,
    /// 1/(2 p_s), p_s the probability of the followed one.
    pub factor: f32,
}

impl MirrorChoice {
    /// The probe itself, with its own weight: where there is no model.
    pub const PROBE: MirrorChoice = MirrorChoice {
        mirror: false,
        factor: 1.0,
    };
}

/// The probability p₊ of following the probe at d rather than its mirror,
/// from g at the model's points over 0, d and −d, per channel (module
/// docs): proportional to the model's light at each, clamped to
/// [ε, 1 − ε], ½ where the model sees no light at either.
#[inline]
pub fn probability_of_probe(g0: Vec3, g_d: Vec3, g_minus_d: Vec3) -> f32 {
    let odd = 0.5 * (g_d - g_minus_d).element_sum();
    let g0 = g0.element_sum();
    let (plus, minus) = ((g0 + odd).max(0.0), (g0 - odd).max(0.0));
    let p = plus / (plus + minus);
    if p.is_finite() {
        p.clamp(EPSILON, 1.0 - EPSILON)
    } else {
        0.5
    }
}

/// The choice for the probability `p_plus` of the probe (from
/// [`probability_of_probe`]) and a uniform `u` in [0, 1).
#[inline]
pub fn choose(p_plus: f32, u: f32) -> MirrorChoice {
    if u < p_plus {
        MirrorChoice {
            mirror: false,
            factor: 0.5 / p_plus,
        }
    } else {
        MirrorChoice {
            mirror: true,
            factor: 0.5 / (1.0 - p_plus),
        }
    }
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

    /// g at the model point over d.
    fn g(n: Vec3, d: Vec3, ls: f32) -> Vec3 {
        let (p, m) = model_point(Vec3::ZERO, n, 0.3, d);
        light(p, m, ls)
    }

    /// What the followed probe finds at offset `d`: the model's light, but
    /// in shadow where d leans towards +T (a cast shadow the model, with
    /// no shadow ray, does not see).
    fn shadowed(n: Vec3, t: Vec3, d: Vec3, ls: f32) -> Vec3 {
        if d.dot(t) > 0.1 {
            Vec3::ZERO
        } else {
            g(n, d, ls)
        }
    }

    /// Per channel, the mean and standard error of the plain probe's
    /// estimate W_plane·X(d) and of the mirror choice's, over `n` probes
    /// along N at a tilted exit point of curvature 0.3, X the light the
    /// probes find (`real`), the choice made from the model's g.
    #[allow(clippy::type_complexity)]
    fn plain_and_chosen(
        n: usize,
        real: impl Fn(Vec3, Vec3, Vec3, f32) -> Vec3,
    ) -> ([[f64; 2]; 3], [[f64; 2]; 3]) {
        let s = sampler();
        let frame = Frame::from_normal(Vec3::new(0.1, -0.2, 1.0).normalize());
        let mut rng = Rng::from_key(11);
        let (mut s1, mut s2) = ([[0f64; 2]; 3], [[0f64; 2]; 3]);
        for _ in 0..n {
            let u = ProbeRandoms::from_rng(&mut rng);
            let ls = rng.uniform_f64() as f32;
            let Some((_, Some(pm))) = s.sample_probe_and_plane(Vec3::ZERO, &frame, 0.3, &u) else {
                continue;
            };
            let d = pm.offset;
            let (n, t) = (frame.n, frame.t);
            let p = probability_of_probe(g(n, Vec3::ZERO, ls), g(n, d, ls), g(n, -d, ls));
            let c = choose(p, rng.uniform());
            let followed = if c.mirror { -d } else { d };
            let plain = pm.weight * real(n, t, d, ls);
            let chosen = pm.weight * real(n, t, followed, ls) * c.factor;
            for k in 0..3 {
                for (j, v) in [plain[k], chosen[k]].into_iter().enumerate() {
                    s1[k][j] += v as f64;
                    s2[k][j] += (v as f64).powi(2);
                }
            }
        }
        let nf = n as f64;
        let mean: [[f64; 2]; 3] = s1.map(|c| c.map(|x| x / nf));
        let se = std::array::from_fn(|k| {
            std::array::from_fn(|j| ((s2[k][j] / nf - mean[k][j].powi(2)) / nf).sqrt())
        });
        (mean, se)
    }

    /// The two estimates' means agree within 5 combined standard errors
    /// per channel (the errors not 0: a vacuous pass is not one).
    fn assert_same_mean(mean: [[f64; 2]; 3], se: [[f64; 2]; 3]) {
        for k in 0..3 {
            let (diff, err) = (
                mean[k][1] - mean[k][0],
                (se[k][0].powi(2) + se[k][1].powi(2)).sqrt(),
            );
            assert!(
                diff.abs() < 5.0 * err && err > 0.0,
                "ch{k}: chosen {} against plain {} (± {err})",
                mean[k][1],
                mean[k][0]
            );
        }
    }

    #[test]
    fn the_choice_keeps_the_plain_probes_mean_where_the_model_is_right() {
        // Light that is linear, quadratic and angular across the disk,
        // found as modelled. A factor 1/p instead of 1/(2p), or the choice
        // without its factor (the probe the model favours, weighed as if
        // it had not been chosen), fails here.
        let (mean, se) = plain_and_chosen(200_000, |n, _, d, ls| g(n, d, ls));
        assert_same_mean(mean, se);
    }

    #[test]
    fn the_choice_keeps_the_plain_probes_mean_where_the_model_is_wrong() {
        // The model lit, the real surface in shadow on one side: the mean
        // must not move, whatever the model predicts (the property an
        // additive term without a shadow ray keeps only by going below 0).
        let (mean, se) = plain_and_chosen(200_000, shadowed);
        assert_same_mean(mean, se);
    }

    #[test]
    fn where_the_model_is_exact_either_choice_gives_the_light_at_xo() {
        // On the plane under a light linear across the disk (the same in
        // every channel up to a factor), the followed probe finds ĝ(±d):
        // its weight × 1/(2p) is W_plane·g(0) for either choice, the
        // light's turn across the disk gone.
        let s = sampler();
        let frame = Frame::from_normal(Vec3::Z);
        let mut rng = Rng::from_key(3);
        let colour = Vec3::new(1.0, 0.6, 0.2);
        // |odd part| ≤ 0.56 g(0) over the disk: p inside (ε, 1 − ε)
        let k = 0.5 / s.rmax() as f32;
        let lin = |d: Vec3| colour * (1.0 + k * (d.x - 0.5 * d.y));
        let mut normal_probes = 0;
        for _ in 0..2000 {
            let u = ProbeRandoms::from_rng(&mut rng);
            let Some((_, Some(pm))) = s.sample_probe_and_plane(Vec3::ZERO, &frame, 0.0, &u) else {
                continue;
            };
            normal_probes += 1;
            let d = pm.offset;
            let p = probability_of_probe(lin(Vec3::ZERO), lin(d), lin(-d));
            assert!(p > EPSILON && p < 1.0 - EPSILON, "{p} clamped at {d:?}");
            for u in [0.0, 0.999_999] {
                let c = choose(p, u);
                let followed = if c.mirror { -d } else { d };
                let got = pm.weight * lin(followed) * c.factor;
                let want = pm.weight * lin(Vec3::ZERO);
                assert!(
                    (got - want).abs().max_element() < 1e-4 * want.max_element(),
                    "{got:?} against {want:?}"
                );
            }
        }
        assert!(normal_probes > 1900, "{normal_probes} of 2000 along N");
    }

    #[test]
    fn choices_are_positive_and_bounded() {
        // Every factor positive and at most 1/(2ε), for lights the model
        // sees on one side only, on neither, or everywhere alike.
        let z = Vec3::ZERO;
        let one = Vec3::ONE;
        for (g0, gd, gm) in [
            (one, 2.0 * one, z),
            (one, z, 2.0 * one),
            (z, z, z),
            (one, one, one),
            (0.1 * one, 5.0 * one, z),
        ] {
            let p = probability_of_probe(g0, gd, gm);
            assert!((EPSILON..=1.0 - EPSILON).contains(&p), "{p}");
            for u in [0.0, 0.5, 0.999_999] {
                let c = choose(p, u);
                assert!(c.factor > 0.0 && c.factor <= 0.5 / EPSILON, "{c:?}");
            }
        }
        assert_eq!(probability_of_probe(z, z, z), 0.5);
        assert_eq!(probability_of_probe(one, one, one), 0.5);
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
