//! Sampling the Henyey–Greenstein phase function for the random walk
//! (`docs/bssrdf.md` §7, "The walk's cost"): one event's new direction in
//! f32, from the inverted CDF written without the division by g (so it is
//! exact as g → 0 and needs no isotropic special case for the cosine).
//! An isotropic medium's direction does not depend on the incoming one,
//! so it is the uniform sphere's; any other is turned about the
//! propagation direction by the branchless orthonormal basis of
//! [`Frame::from_normal`].

use crate::geometry::{Frame, Vec3};
use crate::sampling::sin_cos_turns;

/// The cosine between the incoming propagation direction and the sampled
/// one for mean cosine `g` ∈ (−1, 1) and a uniform `u` ∈ [0, 1): the
/// inverse of the Henyey–Greenstein CDF (pbrt-v4 §11.3.1),
/// (1 + g² − s²)/(2g) with s = (1 − g²)/(1 − g + 2gu), multiplied out as
/// (2u (1 + g²)(1 − g + gu) − (1 − g)²) / (1 − g + 2gu)², which is 2u − 1
/// at g = 0 and rounds no worse near it. For g < 0 it is the mirror image
/// of |g| (p_g(μ) = p_{−g}(−μ)), taken at 1 − u (exact in f32), so every
/// term is positive and nothing cancels but the numerator's difference,
/// whose terms are no larger than the denominator.
#[inline]
pub fn hg_cos(g: f32, u: f32) -> f32 {
    let (g_abs, u) = if g < 0.0 { (-g, 1.0 - u) } else { (g, u) };
    let a = 1.0 - g_abs;
    let den = a + 2.0 * g_abs * u;
    let num = 2.0 * u * (1.0 + g_abs * g_abs) * (a + g_abs * u) - a * a;
    let cos = (num / (den * den)).clamp(-1.0, 1.0);
    if g < 0.0 {
        -cos
    } else {
        cos
    }
}

/// A direction from the Henyey–Greenstein phase function with mean cosine
/// `g` about the propagation direction `d` (unit), g > 0 forward, from two
/// uniforms `u` (the cosine's and the azimuth's).
#[inline]
pub fn sample_hg(d: Vec3, g: f64, u: [f32; 2]) -> Vec3 {
    let g = g as f32;
    let cos = hg_cos(g, u[0]);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let (s, c) = sin_cos_turns(u[1]);
    let local = Vec3::new(sin * c, sin * s, cos);
    if g == 0.0 {
        // Uniform on the sphere whatever `d` is: no frame to turn into.
        return local;
    }
    Frame::from_normal(d).to_world(local).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::walk_nee::henyey_greenstein;
    use crate::sampling::Rng;
    use std::f64::consts::TAU;

    /// χ² of sampled directions against the phase function, on a grid of
    /// (cos θ, φ) about the incoming direction, for isotropic, backward,
    /// weakly and strongly forward media. The mistakes it catches: the
    /// multiplied-out CDF's sign or a factor wrong (g's sign swapped, a
    /// missing 1 + g²), the azimuth not uniform, and an isotropic
    /// direction that depends on the incoming one in any way but none.
    #[test]
    fn henyey_greenstein_directions_follow_the_phase_function_chi_square() {
        let d = Vec3::new(0.3, -0.5, 0.8).normalize();
        let frame = Frame::from_normal(d);
        for g in [0.0, -0.7, 0.0005, 0.3, 0.9] {
            let (nt, np) = (32, 8);
            let mut counts = vec![0f64; nt * np];
            let mut rng = Rng::from_key(23);
            let n = 200_000;
            for _ in 0..n {
                let w = sample_hg(d, g, rng.uniform2());
                assert!(
                    (w.length() - 1.0).abs() < 1e-5,
                    "g = {g}: |w| = {}",
                    w.length()
                );
                let l = frame.to_local(w);
                let z = (l.z as f64).clamp(-1.0, 1.0);
                let i = (((z + 1.0) / 2.0 * nt as f64) as usize).min(nt - 1);
                let phi = (l.y as f64).atan2(l.x as f64).rem_euclid(TAU);
                let j = ((phi / TAU * np as f64) as usize).min(np - 1);
                counts[i * np + j] += 1.0;
            }
            // expected: the pdf over each cosine bin (64 midpoints), dω = dz dφ
            let sub = 64;
            let (mut chi2, mut dof) = (0.0, 0usize);
            let (mut o, mut e) = (0.0, 0.0);
            for i in 0..nt {
                let p: f64 = (0..sub)
                    .map(|a| {
                        let z = -1.0 + 2.0 * (i as f64 + (a as f64 + 0.5) / sub as f64) / nt as f64;
                        henyey_greenstein(g, z)
                    })
                    .sum::<f64>()
                    / sub as f64
                    * (2.0 / nt as f64)
                    * (TAU / np as f64);
                for j in 0..np {
                    o += counts[i * np + j];
                    e += n as f64 * p;
                    if e >= 20.0 || (i, j) == (nt - 1, np - 1) {
                        chi2 += (o - e) * (o - e) / e.max(1e-9);
                        dof += 1;
                        (o, e) = (0.0, 0.0);
                    }
                }
            }
            let dof = dof - 1;
            let limit = dof as f64 + 5.0 * (2.0 * dof as f64).sqrt();
            assert!(chi2 < limit, "g = {g}: χ² {chi2}, dof {dof}");
        }
    }

    /// The multiplied-out inverse CDF is the textbook one, (1 + g² − s²)/(2g)
    /// in f64 at the same f32 uniform, within a few f32 roundings (a
    /// backward medium's taken without its mirror image cancels to 3·10⁻⁵
    /// at g = −0.95), and starts at −1 for u = 0 for every g.
    #[test]
    fn the_inverse_cdf_is_pbrts_multiplied_out() {
        for g in [-0.95f32, -0.3, 0.01, 0.5, 0.99] {
            let g = g as f64; // the reference at the g the sampler sees
            for k in 0..100 {
                let u = k as f32 / 100.0;
                let uf = u as f64;
                let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * uf);
                let want = ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0);
                let got = hg_cos(g as f32, u) as f64;
                assert!((got - want).abs() < 2e-6, "g {g} u {u}: {got} vs {want}");
            }
            assert!((hg_cos(g as f32, 0.0) + 1.0).abs() < 1e-6, "g {g}");
        }
        assert_eq!(hg_cos(0.0, 0.25), -0.5);
    }

    #[test]
    fn henyey_greenstein_directions_have_its_legendre_moments() {
        // The Henyey–Greenstein phase function's Legendre moments are g^l:
        // E[cos θ] = g and E[P2(cos θ)] = g², θ the angle to the incoming
        // direction. A wrong inverted CDF (e.g. the s term's division made
        // a product) moves both far beyond 5 standard errors.
        let d = Vec3::new(0.3, -0.5, 0.8).normalize();
        let mut rng = Rng::from_key(17);
        for g in [-0.7, 0.0005, 0.3, 0.9] {
            let n = 200_000;
            let (mut s1, mut s2, mut q1, mut q2) = (0.0, 0.0, 0.0, 0.0);
            for _ in 0..n {
                let u = [rng.uniform_f64() as f32, rng.uniform_f64() as f32];
                let w = sample_hg(d, g, u);
                assert!((w.length() - 1.0).abs() < 1e-5);
                let c = w.dot(d) as f64;
                let p2 = 1.5 * c * c - 0.5;
                s1 += c;
                q1 += c * c;
                s2 += p2;
                q2 += p2 * p2;
            }
            let nf = n as f64;
            let (m1, m2) = (s1 / nf, s2 / nf);
            let se1 = ((q1 / nf - m1 * m1) / nf).sqrt();
            let se2 = ((q2 / nf - m2 * m2) / nf).sqrt();
            assert!(
                (m1 - g).abs() < 5.0 * se1 + 1e-4,
                "g = {g}: E[cos] = {m1} ± {se1}"
            );
            assert!(
                (m2 - g * g).abs() < 5.0 * se2 + 1e-4,
                "g = {g}: E[P2] = {m2} ± {se2}"
            );
        }
    }
}
