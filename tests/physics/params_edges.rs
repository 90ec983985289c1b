//! Edge paths of the subsurface parameters that rendering the shipped
//! scenes never takes.
//!
//! - The diffuse Fresnel reflectance Fdr(η) behind the dipole's boundary
//!   condition, for η < 1 (a medium optically thinner than its
//!   surroundings) as well as η ≥ 1. Fdr is the cosine-weighted hemispherical
//!   average of the exact Fresnel reflectance seen from inside,
//!   Fdr(η) = 2∫₀¹ F(μ; 1/η) μ dμ, computed here by quadrature from the
//!   Fresnel equations and compared with the Egan & Hilgeman polynomial
//!   fits the code uses (accurate to ~1e-3; the fit for η < 1 is not the
//!   fit for η ≥ 1 with 1/η). Fdr is private; it is read back from the
//!   public total dipole reflectance Rd(α', η) = α'/2 (1 + e^{−4/3 A s})
//!   e^{−s}, s = √(3(1 − α')), A = (1 + Fdr)/(1 − Fdr), solved for Fdr.
//! - The Henyey–Greenstein g must lie in (−1, 1): g = −1 (pure
//!   back-scattering) is rejected like g = 1.
//! - Rescaling lengths by k rescales the random-walk medium by 1/k.
//! - Material equality and empty overrides.

use std::path::Path;
use std::sync::Arc;

use lucent::bssrdf::params::{dipole_reflectance, Medium};
use lucent::bssrdf::{Fit, Measured, ProbeAxes, ProbeOptions, SubsurfaceParams};
use lucent::error::{Constraint, Param};
use lucent::geometry::Vec3;
use lucent::materials::estimator_options::Assignments as Overrides;
use lucent::materials::{Material, Subsurface};

/// Exact Fresnel reflectance for light arriving with cosine `c` at an
/// interface of relative index `eta` (far side over near side).
fn fresnel(c: f64, eta: f64) -> f64 {
    let st2 = (1.0 - c * c) / (eta * eta);
    if st2 >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - st2).sqrt();
    let rs = (c - eta * ct) / (c + eta * ct);
    let rp = (eta * c - ct) / (eta * c + ct);
    0.5 * (rs * rs + rp * rp)
}

/// Fdr(η) = 2∫₀¹ F(μ; 1/η) μ dμ by the midpoint rule (the integrand has a
/// kink at the critical angle; 2·10⁵ points put the error far below 1e-5).
fn fdr_exact(eta: f64) -> f64 {
    let n = 200_000;
    let h = 1.0 / n as f64;
    (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) * h;
            fresnel(mu, 1.0 / eta) * mu
        })
        .sum::<f64>()
        * 2.0
        * h
}

/// The Fdr the code uses, recovered from the dipole reflectance.
fn fdr_code(eta: f64) -> f64 {
    let alpha = 0.5f64;
    let s = (3.0 * (1.0 - alpha)).sqrt();
    let rd = dipole_reflectance(alpha, eta);
    let x = 2.0 * rd * s.exp() / alpha - 1.0;
    let a = -3.0 * x.ln() / (4.0 * s);
    (a - 1.0) / (a + 1.0)
}

#[test]
fn diffuse_fresnel_reflectance_matches_the_hemispherical_integral() {
    // sanity of the reference: no reflection at η = 1; F(μ; η) from outside
    // integrates to the known external value for glass (≈ 0.092)
    assert!(fdr_exact(1.0) < 1e-12);
    assert!((fdr_exact(1.0 / 1.5) - 0.0918).abs() < 5e-4);
    for eta in [
        0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 1.01, 1.05, 1.3, 1.5, 2.0,
    ] {
        let (got, want) = (fdr_code(eta), fdr_exact(eta));
        assert!(
            (got - want).abs() < 1.5e-3,
            "Fdr({eta}): fit {got}, hemispherical integral {want}"
        );
    }
    // Both branches meet at η = 1, where there is no interface (Fdr = 0).
    let below = fdr_code(1.0 - 1e-9);
    let at = fdr_code(1.0);
    assert!(below.abs() < 3e-3 && at.abs() < 3e-3, "{below} {at}");
    assert!(
        (below - at).abs() < 1e-3,
        "branches disagree at η = 1: {below} vs {at}"
    );
}

fn measured(g: f64) -> Measured {
    Measured {
        sigma_s: [1.0, 2.0, 3.0],
        sigma_a: [0.1, 0.2, 0.3],
        g,
        albedo: [0.5; 3],
        eta: 1.3,
    }
}

#[test]
fn g_must_be_strictly_between_minus_one_and_one() {
    for g in [-1.0, 1.0, -1.5, 2.0, f64::NAN, f64::INFINITY] {
        let e = SubsurfaceParams::from_measured(&measured(g), 1.0, Fit::Searchlight).unwrap_err();
        assert_eq!(e.param, Param::G, "g = {g}: {e}");
        assert_eq!(e.constraint, Constraint::Open(-1.0, 1.0), "g = {g}: {e}");
        assert!(e.to_string().contains("(-1, 1)"), "g = {g}: {e}");
    }
    for g in [-0.999, -0.5, 0.0, 0.9] {
        let p = SubsurfaceParams::from_measured(&measured(g), 1.0, Fit::Searchlight).unwrap();
        assert_eq!(p.medium.unwrap().g, g);
    }
    // the same in a scene file, with the file, line and field
    for g in ["-1.0", "1.0", "-1"] {
        let text = format!(
            "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\n\n\
             [materials.m]\ntype = \"subsurface\"\nsigma_s_prime = [1, 1, 1]\n\
             sigma_a = [0.1, 0.1, 0.1]\nalbedo = [0.5, 0.5, 0.5]\ng = {g}\n\n\
             [[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\n"
        );
        let e = lucent::scene::load_str(&text, Path::new("g.toml")).unwrap_err();
        assert_eq!(e.line, Some(11), "{e}");
        assert!(e.message.contains("(-1, 1)"), "{e}");
        assert!(e.field.as_deref().unwrap_or("").ends_with('g'), "{e}");
    }
}

#[test]
fn scaling_lengths_scales_the_medium_inversely() {
    for p in [
        SubsurfaceParams::from_preset("skin1", 1.0, Fit::Searchlight).unwrap(),
        SubsurfaceParams::from_measured(&measured(0.7), 0.1, Fit::VolumeMfp).unwrap(),
        SubsurfaceParams::from_artist([0.8, 0.5, 0.2], [1.0, 0.5, 0.0], 1.4, Fit::Searchlight)
            .unwrap(),
    ] {
        let m = p.medium.unwrap();
        for k in [0.25, 3.0, 1e3] {
            let q = p.scaled(k);
            let qm: Medium = q.medium.unwrap();
            for c in 0..3 {
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
                assert!(close(q.d[c], p.d[c] * k));
                assert!(close(qm.sigma_s[c], m.sigma_s[c] / k), "σs ×{k}");
                assert!(close(qm.sigma_a[c], m.sigma_a[c] / k), "σa ×{k}");
                // optical depth over a scaled length is unchanged
                assert!(close(qm.sigma_t()[c] * q.d[c], m.sigma_t()[c] * p.d[c]));
            }
            assert_eq!(qm.g, m.g);
            assert_eq!((q.albedo, q.eta), (p.albedo, p.eta));
        }
    }
    let bare = SubsurfaceParams {
        medium: None,
        ..SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap()
    };
    assert_eq!(bare.scaled(2.0).medium, None);
}

#[test]
fn materials_are_equal_exactly_when_their_settings_are() {
    let p = SubsurfaceParams::from_preset("marble", 1.0, Fit::Searchlight).unwrap();
    let opts = ProbeOptions::default();
    let ss = |p: SubsurfaceParams, o: &ProbeOptions, sw: bool, spec: bool| {
        Material::Subsurface(Arc::new(Subsurface::new(p, o, sw, spec).unwrap()))
    };
    let base = ss(p, &opts, true, true);
    assert_eq!(base, ss(p, &opts, true, true));
    assert_eq!(base, base.clone());
    let other = SubsurfaceParams::from_preset("skin1", 1.0, Fit::Searchlight).unwrap();
    let axes = ProbeOptions {
        axes: ProbeAxes::Normal,
        ..opts
    };
    for (what, m) in [
        ("params", ss(other, &opts, true, true)),
        ("options", ss(p, &axes, true, true)),
        ("exit_sw", ss(p, &opts, false, true)),
        ("specular", ss(p, &opts, true, false)),
        ("kind", Material::Dielectric { eta: 1.5 }),
    ] {
        assert_ne!(base, m, "{what} differs");
    }
    assert_eq!(
        Material::Diffuse { albedo: Vec3::ONE },
        Material::Diffuse { albedo: Vec3::ONE }
    );
    assert_ne!(
        Material::Diffuse { albedo: Vec3::ONE },
        Material::Diffuse { albedo: Vec3::ZERO }
    );
}

#[test]
fn overrides_are_empty_only_when_they_override_nothing() {
    assert!(Overrides::default().is_empty());
    let one_each = [
        ("radius", "uniform"),
        ("rmax_quantile", "0.99"),
        ("axes", "normal"),
        ("channel", "single"),
        ("renormalize", "false"),
        ("exit_sw", "true"),
        ("specular", "true"),
    ];
    for (name, value) in one_each {
        let o = Overrides::default().with(name, value);
        assert!(!o.is_empty(), "{o:?}");
        assert_eq!(o.value(name), Some(value));
    }
}
