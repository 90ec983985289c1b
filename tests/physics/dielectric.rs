//! Light transport through a smooth dielectric: closed-form facts that a
//! wrong refraction direction, Fresnel split or path weight breaks.
//!
//! - Furnace: a non-absorbing glass object in a constant environment L
//!   neither creates nor destroys light, so a camera outside sees exactly L
//!   everywhere, and radiance inside a medium of index η is η²L (L/η² is
//!   invariant along a path, pbrt-v4 §9.5.2), so a camera inside sees η²L.
//! - Snell's law sin θo = η sin θi, reciprocity (refracting back returns the
//!   original direction), total internal reflection beyond the critical
//!   angle sin θc = 1/η.
//! - Fresnel reflectance against the textbook form (Born & Wolf §1.5.2)
//!   rs = −sin(θi − θt)/sin(θi + θt), rp = tan(θi − θt)/tan(θi + θt),
//!   F = (rs² + rp²)/2 — written differently from the code under test —
//!   with its closed-form values at normal incidence, ((η − 1)/(η + 1))²,
//!   and at Brewster's angle (rp = 0); F is the same seen from either side
//!   of the interface (Stokes reciprocity).
//! - The sampled split: reflected with frequency F and transmitted with
//!   frequency 1 − F, so R + T = 1.

use crate::common;

use std::path::Path;

use lucent::accel;
use lucent::fresnel;
use lucent::geometry::Vec3;
use lucent::materials::dielectric;
use lucent::render::{render, RenderOptions};
use lucent::scene::load_str;

/// Fresnel reflectance in f64 from the angles (see the module docs).
fn fresnel_angles(cos_i: f64, eta: f64) -> f64 {
    let ti = cos_i.acos();
    let st = ti.sin() / eta;
    if st >= 1.0 {
        return 1.0;
    }
    let tt = st.asin();
    if ti == 0.0 {
        return ((eta - 1.0) / (eta + 1.0)).powi(2);
    }
    let rs = -(ti - tt).sin() / (ti + tt).sin();
    let rp = (ti - tt).tan() / (ti + tt).tan();
    0.5 * (rs * rs + rp * rp)
}

#[test]
fn fresnel_reflectance_matches_the_textbook_form() {
    for eta in [1.33f32, 1.5, 2.4, 0.7] {
        let e = eta as f64;
        assert!(
            (fresnel::dielectric(1.0, eta) as f64 - ((e - 1.0) / (e + 1.0)).powi(2)).abs() < 1e-6
        );
        for i in 0..=100 {
            let c = 0.001 + 0.999 * i as f64 / 100.0;
            let want = fresnel_angles(c, e);
            let got = fresnel::dielectric(c as f32, eta) as f64;
            assert!(
                (got - want).abs() < 2e-5,
                "η {eta} cos {c}: {got} vs {want}"
            );
            // from inside: the same formula with 1/η
            let want = fresnel_angles(c, 1.0 / e);
            let got = fresnel::dielectric(-c as f32, eta) as f64;
            assert!(
                (got - want).abs() < 2e-5,
                "η {eta} cos −{c}: {got} vs {want}"
            );
        }
        // Brewster's angle tan θB = η: rp = 0, so only the s-polarized
        // half reflects, F = rs²/2 with rs = (cos θi − η cos θt)/(cos θi +
        // η cos θt), and θi + θt = 90° gives cos θt = sin θB.
        let tb = e.atan();
        let rs = (tb.cos() - e * tb.sin()) / (tb.cos() + e * tb.sin());
        let got = fresnel::dielectric(tb.cos() as f32, eta) as f64;
        assert!(
            (got - 0.5 * rs * rs).abs() < 1e-5,
            "Brewster η {eta}: {got}"
        );
    }
}

#[test]
fn fresnel_is_the_same_from_both_sides() {
    // Light crossing at (θi outside, θt inside) reflects the same fraction
    // whichever way it travels.
    for eta in [1.33f32, 1.5, 2.4] {
        for i in 1..100 {
            let wo = Vec3::new(
                (i as f32 / 100.0 * 1.5).sin(),
                0.0,
                (i as f32 / 100.0 * 1.5).cos(),
            );
            let (wt, _) = dielectric::refract(wo, eta).expect("entering never reflects totally");
            let outside = fresnel::dielectric(wo.z, eta);
            let inside = fresnel::dielectric(wt.z, eta);
            // (f32 rounding of the refracted direction near grazing)
            assert!(
                (outside - inside).abs() < 1e-4,
                "η {eta} {wo}: {outside} vs {inside}"
            );
        }
    }
}

#[test]
fn refraction_obeys_snell_reciprocity_and_total_internal_reflection() {
    for eta in [1.33f32, 1.5, 2.4, 0.75] {
        for i in 0..200 {
            let th = i as f32 / 200.0 * 1.55;
            let phi = i as f32 * 0.7;
            for side in [1.0f32, -1.0] {
                let wo = Vec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), side * th.cos());
                // η' is the index ratio (far side / near side)
                let etap = if side > 0.0 { eta } else { 1.0 / eta };
                let sin_o = th.sin();
                match dielectric::refract(wo, eta) {
                    None => {
                        assert!(
                            sin_o >= etap * 0.9999,
                            "TIR below the critical angle: {wo} η {eta}"
                        );
                        // and the sampler reflects it with weight 1
                        let s = dielectric::sample(eta, wo, 0.999_999);
                        assert!(!s.transmitted && s.weight == 1.0);
                        assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                    }
                    Some((wi, e)) => {
                        assert!(
                            sin_o < etap * 1.0001,
                            "no TIR past the critical angle: {wo}"
                        );
                        assert_eq!(e, etap);
                        assert!((wi.length() - 1.0).abs() < 1e-5);
                        assert!(wi.z * wo.z < 0.0, "{wo} → {wi}: not through the surface");
                        // Snell: sin θo = η' sin θi
                        let sin_i = (wi.x * wi.x + wi.y * wi.y).sqrt();
                        assert!((sin_o - etap * sin_i).abs() < 2e-5, "{wo} → {wi} η {eta}");
                        // in the plane of incidence, on the other side of the normal
                        if sin_o > 1e-3 {
                            let dot = (wo.x * wi.x + wo.y * wi.y) / (sin_o * sin_i);
                            assert!((dot + 1.0).abs() < 1e-4, "{wo} → {wi}");
                        }
                        // reciprocity
                        let (back, eb) = dielectric::refract(wi, eta).unwrap();
                        assert!((back - wo).length() < 1e-4, "{wo} → {wi} → {back}");
                        assert!((eb * e - 1.0).abs() < 1e-6);
                    }
                }
            }
        }
    }
}

/// Sampling with stratified u: the reflected fraction is F, the rest is
/// transmitted, and the transmitted weight is 1/η'² (radiance compressed
/// into the narrower cone), so E[weight · η'²·transmitted + reflected] = 1.
#[test]
fn sampled_split_reflects_f_and_transmits_one_minus_f() {
    let n = 4096;
    for eta in [1.5f32, 2.4, 0.8] {
        for cos in [1.0f32, 0.8, 0.5, 0.2, 0.05, -0.3, -0.9] {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let f = fresnel::dielectric(cos, eta);
            let (mut r, mut t) = (0usize, 0usize);
            for k in 0..n {
                let s = dielectric::sample(eta, wo, (k as f32 + 0.5) / n as f32);
                if s.transmitted {
                    t += 1;
                    let (wi, etap) = dielectric::refract(wo, eta).unwrap();
                    assert!((s.wi - wi).length() < 1e-6);
                    assert!(
                        (s.weight * etap * etap - 1.0).abs() < 1e-5,
                        "weight {}",
                        s.weight
                    );
                } else {
                    r += 1;
                    assert_eq!(s.weight, 1.0);
                    assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                }
            }
            assert_eq!(r + t, n);
            let fr = r as f32 / n as f32;
            assert!(
                (fr - f).abs() <= 1.0 / n as f32,
                "η {eta} cos {cos}: R {fr} vs F {f}"
            );
        }
    }
}

/// A glass sphere in a constant environment, camera at `eye`.
fn glass_furnace(eta: f32, eye: [f32; 3], env: [f32; 3]) -> String {
    format!(
        r#"
[camera]
look_from = {eye:?}
look_at = [0.05, 0.1, -3.0]
fov_y = 60
resolution = [32, 32]

[render]
spp = 16
max_depth = 200
seed = 3

[environment]
radiance = {env:?}

[materials.glass]
type = "dielectric"
eta = {eta}

[[shapes]]
type = "sphere"
subdivisions = 3
material = "glass"
scale = 2.0
"#
    )
}

/// Renders `text` on each backend and checks the mean of every channel
/// against `want` (4 standard errors plus 1e-4 relative for rounding).
fn check_mean(text: &str, want: Vec3, what: &str) {
    let scene = load_str(text, Path::new("furnace.toml")).unwrap();
    for backend in common::backends() {
        let a = accel::build(&scene.meshes, backend).unwrap();
        let film = render(&scene, a.as_ref(), &RenderOptions::default())
            .unwrap()
            .0;
        let (mean, se) = common::mean_se(&film);
        for c in 0..3 {
            let w = want[c] as f64;
            assert!(
                (mean[c] - w).abs() < 4.0 * se[c] + 1e-4 * w,
                "{what} {backend:?} ch{c}: mean {} want {w} (se {})",
                mean[c],
                se[c]
            );
            assert!(
                se[c] < 0.01 * w,
                "{what}: too noisy to mean anything (se {})",
                se[c]
            );
        }
    }
}

#[test]
fn glass_sphere_in_a_furnace_returns_the_environment() {
    let env = [0.5f32, 0.8, 1.25];
    for eta in [1.5f32, 1.33, 0.8] {
        // from outside: the sphere vanishes
        check_mean(
            &glass_furnace(eta, [0.0, 0.0, 5.0], env),
            Vec3::from(env),
            "outside",
        );
        // from its centre: η²L (radiance in the denser medium)
        check_mean(
            &glass_furnace(eta, [0.0, 0.0, 0.0], env),
            Vec3::from(env) * eta * eta,
            "inside",
        );
    }
}
