//! The Christensen–Burley normalized diffusion profile (Christensen & Burley
//! 2015, "Approximate Reflectance Profiles for Efficient Subsurface
//! Scattering", Pixar TR 15-04, eqs. 2–3), its radial CDF, the closed-form
//! inverse of that CDF, and the fits s(A) that turn a mean free path into the
//! profile's shape parameter d.
//!
//! Everything here is in f64: the inverse CDF is used by the samplers at both
//! tails (ξ → 0 near the exit point, ξ → 1 at the truncation radius), where f32
//! loses most of its digits (see `docs/bssrdf.md` §4c).
//!
//! Conventions: `rho = r / d` is the radius in units of d. `profile(r, d)` is
//! R(r) per unit area, so that ∫_0^∞ R(r) 2πr dr = 1 and a flat, uniformly lit
//! slab reflects exactly A when Rd = A·R.

use std::f64::consts::PI;

use crate::error::{Constraint, Param, ParamError};

/// Smallest radius, in units of d, at which the profile is evaluated.
///
/// R(r) ~ 1/(4πd r) is integrable but infinite at r = 0, and a sampler fed
/// ξ = 0 returns r = 0. Clamping r to `RHO_MIN·d` keeps every pdf finite; the
/// profile mass moved by the clamp is CDF(RHO_MIN·d) ≈ RHO_MIN/2 = 5e-10, far below
/// any Monte Carlo noise.
pub const RHO_MIN: f64 = 1e-9;

/// R(r) = (e^{−r/d} + e^{−r/(3d)}) / (8π d r), per unit area; r is clamped to
/// at least `RHO_MIN·d`. Returns 0 for d ≤ 0 (an inactive channel).
#[inline]
pub fn profile(r: f64, d: f64) -> f64 {
    if d <= 0.0 || !d.is_finite() {
        return 0.0;
    }
    let rho = (r / d).max(RHO_MIN);
    // one exp instead of two: e^{−ρ} = (e^{−ρ/3})³ (relative error ≤ 3ε)
    let e3 = (-rho / 3.0).exp();
    (e3 * e3 * e3 + e3) / (8.0 * PI * d * d * rho)
}

/// The radial density of r/d at d = 1: 2πρ R(ρ) = (e^{−ρ} + e^{−ρ/3}) / 4.
#[inline]
pub fn radial_density_unit(rho: f64) -> f64 {
    ((-rho).exp() + (-rho / 3.0).exp()) / 4.0
}

/// CDF(ρ) = 1 − e^{−ρ}/4 − 3e^{−ρ/3}/4, the profile mass within radius ρ·d.
///
/// Written with `expm1` so it keeps full relative precision as ρ → 0, where
/// the direct form cancels (CDF ≈ ρ/2).
#[inline]
pub(crate) fn cdf_unit(rho: f64) -> f64 {
    if rho <= 0.0 {
        return 0.0;
    }
    -((-rho).exp_m1() + 3.0 * (-rho / 3.0).exp_m1()) / 4.0
}

/// 1 − CDF(ρ) = e^{−ρ}/4 + 3e^{−ρ/3}/4, with full relative precision in the
/// tail (where 1 − cdf_unit would cancel).
#[inline]
pub(crate) fn ccdf_unit(rho: f64) -> f64 {
    if rho <= 0.0 {
        return 1.0;
    }
    ((-rho).exp() + 3.0 * (-rho / 3.0).exp()) / 4.0
}

/// CDF at radius r for parameter d (scene units).
#[inline]
pub fn cdf(r: f64, d: f64) -> f64 {
    cdf_unit(r / d)
}

/// Closed-form inverse of the CDF at d = 1, given both ξ and 1 − ξ.
///
/// With u = 1 − ξ and x = e^{−ρ/3}, CDF = ξ is the depressed cubic
/// x³ + 3x − 4u = 0, whose one real root by Cardano is x = a − 1/a with
/// a = ∛(2u + √(1 + 4u²)). Both ends cancel catastrophically if evaluated
/// directly, so each branch rewrites the root without subtraction:
///
/// - ξ < ½: y = 1 − x = (φ − a)(a + φ − 1)/a, where φ = ∛(2 + √5) is the
///   golden ratio (the value of a at ξ = 0) and
///   φ³ − a³ = 2ξ(1 + 2(2 − ξ)/(√5 + s)), so φ − a is a product of positive
///   terms; then ρ = −3 ln1p(−y).
/// - ξ ≥ ½: x = (a³ − 1)(a + 1)/((a² + a + 1) a) with a³ − 1 = 2u + 4u²/(s + 1);
///   then ρ = −3 ln x.
///
/// Passing 1 − ξ separately lets callers that know it exactly (a truncated
/// sampler computes it as (1 − u)·c + (1 − c)) keep the tail precise.
/// Returns +∞ for ξ = 1 (u = 0).
#[inline]
pub(crate) fn inverse_cdf_unit_pair(xi: f64, one_minus_xi: f64) -> f64 {
    if xi <= 0.0 {
        return 0.0;
    }
    if one_minus_xi <= 0.0 {
        return f64::INFINITY;
    }
    if xi < 0.5 {
        let u = one_minus_xi;
        let s = (1.0 + 4.0 * u * u).sqrt();
        let a = cbrt_cardano(2.0 * u + s);
        let phi = 0.5 * (1.0 + 5f64.sqrt());
        let phi3_minus_a3 = 2.0 * xi * (1.0 + 2.0 * (2.0 - xi) / (5f64.sqrt() + s));
        let phi_minus_a = phi3_minus_a3 / (phi * phi + phi * a + a * a);
        let y = phi_minus_a * (a + phi - 1.0) / a;
        -3.0 * (-y).ln_1p()
    } else {
        let u = one_minus_xi;
        let s = (1.0 + 4.0 * u * u).sqrt();
        let a = cbrt_cardano(2.0 * u + s);
        let a3_minus_1 = 2.0 * u + 4.0 * u * u / (s + 1.0);
        let x = a3_minus_1 * (a + 1.0) / ((a * a + a + 1.0) * a);
        -3.0 * x.ln()
    }
}

/// ∛x for the Cardano term of [`inverse_cdf_unit_pair`], x = 2u + √(1 + 4u²)
/// ∈ [1, φ³] (φ³ = 2 + √5) for u ∈ [0, 1], within one ulp there. The
/// general `cbrt` (any exponent, correctly rounded) cost ~150 instructions
/// per sampled radius; on this short interval a cubic (Chebyshev
/// interpolant in t ∈ [−1, 1], relative error 2.6e-3) and two Halley steps
/// (each cubes the relative error) reach full precision.
#[inline]
fn cbrt_cardano(x: f64) -> f64 {
    // [1, φ³] → [−1, 1]: t = (2x − 1 − φ³) / (φ³ − 1) = x/φ − φ.
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    const PHI: f64 = 1.618_033_988_749_895;
    let t = x * INV_PHI - PHI;
    let mut a = 1.379_567_861_396_700_8
        + t * (0.283_315_861_620_448_4
            + t * (-0.068_807_421_426_335_45 + t * 0.024_868_790_238_352_978));
    let a3 = a * a * a;
    a *= (a3 + 2.0 * x) / (2.0 * a3 + x);
    // The second step as a correction to a (now within ~1e-8): the result
    // then carries the rounding of one addition, not of a product chain.
    let a3 = a * a * a;
    a - a * (a3 - x) / (2.0 * a3 + x)
}

/// Inverse CDF at d = 1: the radius ρ = r/d holding a fraction `xi` of the
/// profile's energy (1 − ξ is computed exactly for ξ ≥ ½ by Sterbenz).
#[inline]
pub(crate) fn inverse_cdf_unit(xi: f64) -> f64 {
    inverse_cdf_unit_pair(xi, 1.0 - xi)
}

/// The radius r (scene units) at which CDF(r) = ξ for parameter d.
#[inline]
pub fn sample_radius(xi: f64, d: f64) -> f64 {
    d * inverse_cdf_unit(xi)
}

/// Quantile helper: r/d holding fraction `p` of the energy
/// (0.99 → 12.95, 0.999 → 19.86).
#[inline]
pub fn quantile(p: f64) -> f64 {
    inverse_cdf_unit(p)
}

/// Published fits of the scale s(A) with d = ℓ / s(A) (Christensen & Burley
/// 2015, §5). They differ in what ℓ is and in the lighting used to fit them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Fit {
    /// Searchlight configuration, ℓ = diffuse mean free path:
    /// s = 3.5 + 100 (A − 0.33)⁴ (their eq. 8). The course report's choice.
    #[default]
    Searchlight,
    /// Diffuse surface transmission, ℓ = diffuse mean free path:
    /// s = 1.9 − A + 3.5 (A − 0.8)² (their eq. 6).
    DiffuseTransmission,
    /// Diffuse surface transmission, ℓ = volume mean free path 1/σt':
    /// s = 1.85 − A + 7 |A − 0.8|³ (their eq. 5).
    VolumeMfp,
}

impl Fit {
    /// The scale s(A) for albedo A ∈ [0, 1]; positive on that range for
    /// every fit (minima ≈ 3.5, 0.9, 0.85).
    pub fn s(self, a: f64) -> f64 {
        match self {
            Fit::Searchlight => 3.5 + 100.0 * (a - 0.33).powi(4),
            Fit::DiffuseTransmission => 1.9 - a + 3.5 * (a - 0.8).powi(2),
            Fit::VolumeMfp => 1.85 - a + 7.0 * (a - 0.8).abs().powi(3),
        }
    }

    /// Whether the length this fit expects is the volume mean free path
    /// 1/σt' (true) or the diffuse mean free path 1/σtr (false).
    pub(crate) fn uses_volume_mfp(self) -> bool {
        matches!(self, Fit::VolumeMfp)
    }

    /// Parses "searchlight", "diffuse-transmission", "volume-mfp"
    /// (case-insensitive; '_' accepted for '-').
    pub fn parse(name: &str) -> Result<Fit, ParamError> {
        match name.to_ascii_lowercase().replace('_', "-").as_str() {
            "searchlight" => Ok(Fit::Searchlight),
            "diffuse-transmission" | "dmfp" => Ok(Fit::DiffuseTransmission),
            "volume-mfp" | "mfp" => Ok(Fit::VolumeMfp),
            other => Err(ParamError::new(
                Param::Fit,
                format!("\"{other}\""),
                Constraint::Named {
                    what: "fit",
                    names: "expected searchlight, diffuse-transmission or volume-mfp".into(),
                },
            )),
        }
    }
}

#[cfg(test)]
// Tests index parallel per-channel arrays by channel number.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    /// Composite Simpson on [a, b] with n (even) intervals.
    fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
        let h = (b - a) / n as f64;
        let mut s = f(a) + f(b);
        for i in 1..n {
            let x = a + i as f64 * h;
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(x);
        }
        s * h / 3.0
    }

    /// 2πr R(r), continued to its limit 1/(2d) at r = 0.
    fn radial(r: f64, d: f64) -> f64 {
        if r == 0.0 {
            radial_density_unit(0.0) / d
        } else {
            2.0 * PI * r * profile(r, d)
        }
    }

    #[test]
    fn profile_integrates_to_one() {
        for &d in &[1e-3, 0.37, 1.0, 42.0] {
            // 2πr R(r) is smooth and bounded; the tail beyond 150 d is < 1e-21.
            let total = simpson(|r| radial(r, d), 0.0, 150.0 * d, 200_000);
            assert!((total - 1.0).abs() < 1e-9, "d={d}: ∫R 2πr dr = {total}");
        }
    }

    /// An inactive channel (d = 0) and d no medium can have (negative,
    /// infinite, NaN) reflect nothing: R = 0 at every r, never the NaN
    /// that r/d with d = 0 would give.
    #[test]
    fn a_channel_without_a_length_has_no_profile() {
        for d in [0.0, -0.0, -1.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            for r in [0.0, 1e-12, 0.5, 3.0] {
                assert_eq!(profile(r, d), 0.0, "R({r}) with d = {d}");
            }
        }
    }

    #[test]
    fn cdf_matches_numerical_integral() {
        let d = 2.5;
        for &r in &[1e-3, 0.1, 1.0, 5.0, 20.0, 60.0] {
            let num = simpson(|t| radial(t, d), 0.0, r, 20_000);
            let c = cdf(r, d);
            assert!((num - c).abs() < 1e-10 * c.max(1e-3), "r={r}: {num} vs {c}");
            assert!((cdf_unit(r / d) + ccdf_unit(r / d) - 1.0).abs() < 1e-15);
        }
        // small-ρ precision: CDF = ρ/2 − ρ²/6 + O(ρ³)
        let rho = 1e-12;
        assert!((cdf_unit(rho) / (rho / 2.0) - 1.0).abs() < 1e-11);
    }

    #[test]
    fn cardano_cube_root_is_within_one_ulp() {
        // a dense grid over [1, φ³] plus both ends and a little beyond
        // (rounding of 2u + s at u = 0 and u = 1)
        let top = 2.0 + 5f64.sqrt();
        let n = 1 << 20;
        let xs = (0..=n)
            .map(|i| 1.0 + (top - 1.0) * i as f64 / n as f64)
            .chain([1.0 - f64::EPSILON, top * (1.0 + f64::EPSILON)]);
        let mut worst = 0f64;
        for x in xs {
            let (a, t) = (cbrt_cardano(x), x.cbrt());
            // ∛x ∈ [1, 2): one ulp is f64::EPSILON
            worst = worst.max((a - t).abs() / f64::EPSILON);
        }
        assert!(worst <= 1.0, "worst error {worst} ulp");
    }

    #[test]
    fn closed_form_inverse_is_exact_at_both_tails() {
        // Log-spaced in ξ toward 0 and in 1 − ξ toward 1: relative error of
        // CDF near 0 and of 1 − CDF near 1.
        let mut worst = 0.0f64;
        for k in 0..=1200 {
            let e = -12.0 + 12.0 * k as f64 / 1200.0; // 1e-12 ..= 1
            let t = 10f64.powf(e) * 0.5; // 5e-13 ..= 0.5
                                         // lower tail
            let rho = inverse_cdf_unit(t);
            let rel = (cdf_unit(rho) - t).abs() / t;
            worst = worst.max(rel);
            assert!(rel < 1e-12, "ξ={t}: ρ={rho}, CDF={}", cdf_unit(rho));
            // upper tail: ξ = 1 − t, passing 1 − ξ exactly.
            let rho = inverse_cdf_unit_pair(1.0 - t, t);
            let rel = (ccdf_unit(rho) - t).abs() / t;
            worst = worst.max(rel);
            assert!(rel < 1e-12, "1−ξ={t}: ρ={rho}, 1−CDF={}", ccdf_unit(rho));
            // and with 1 − ξ rounded by the caller: absolute error ≤ 1e-15
            let xi = 1.0 - t;
            let rho = inverse_cdf_unit(xi);
            assert!((cdf_unit(rho) - xi).abs() < 1e-15);
        }
        assert!(worst < 1e-13, "worst relative error {worst}");
        assert_eq!(inverse_cdf_unit(0.0), 0.0);
        assert_eq!(inverse_cdf_unit(1.0), f64::INFINITY);
        let top = inverse_cdf_unit(1.0 - f64::EPSILON / 2.0);
        assert!(top.is_finite() && top > 100.0 && top < 120.0, "{top}");
    }

    #[test]
    fn quantiles_match_the_doc() {
        for &(p, q) in &[
            (0.99, 12.95),
            (0.997, 16.56),
            (0.999, 19.86),
            (0.9999, 26.77),
        ] {
            assert!((quantile(p) - q).abs() < 0.005, "q({p}) = {}", quantile(p));
        }
        assert!((sample_radius(0.999, 3.0) - 3.0 * 19.86).abs() < 0.02);
        // median: a direct bisection agrees
        let (mut lo, mut hi) = (0.0f64, 50.0f64);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if cdf_unit(m) < 0.5 {
                lo = m
            } else {
                hi = m
            }
        }
        assert!((quantile(0.5) - lo).abs() < 1e-12);
    }

    #[test]
    fn fits_match_published_values() {
        // s at the points the paper plots; A = 0.33 is the searchlight minimum.
        assert_eq!(Fit::Searchlight.s(0.33), 3.5);
        assert!((Fit::Searchlight.s(1.0) - (3.5 + 100.0 * 0.67f64.powi(4))).abs() < 1e-12);
        assert!((Fit::DiffuseTransmission.s(0.8) - 1.1).abs() < 1e-12);
        assert!((Fit::VolumeMfp.s(0.8) - 1.05).abs() < 1e-12);
        for fit in [Fit::Searchlight, Fit::DiffuseTransmission, Fit::VolumeMfp] {
            for i in 0..=100 {
                let s = fit.s(i as f64 / 100.0);
                assert!(s > 0.8 && s.is_finite(), "{fit:?} s = {s}");
            }
        }
        assert_eq!(Fit::parse("Volume_MFP"), Ok(Fit::VolumeMfp));
        let e = Fit::parse("nope").unwrap_err();
        assert_eq!((e.param, e.found.as_str()), (Param::Fit, "\"nope\""));
        assert!(
            e.to_string().starts_with("fit: unknown fit \"nope\""),
            "{e}"
        );
    }
}
