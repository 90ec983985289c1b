//! Checks every glossy lobe's tests share: the integral of f cos θ by
//! quadrature against the mean sampled weight (the white furnace, which
//! also catches a pdf that is not the sampling density), reciprocity, and
//! each sample's weight against f cos θ / pdf.

use crate::geometry::Vec3;
use crate::sampling::Rng;

/// The unit direction with cosine `mu` in the xz plane.
pub(crate) fn from_mu(mu: f32) -> Vec3 {
    Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu)
}

fn dir(theta: f64, phi: f64) -> Vec3 {
    Vec3::new(
        (theta.sin() * phi.cos()) as f32,
        (theta.sin() * phi.sin()) as f32,
        theta.cos() as f32,
    )
}

/// ∫ g(ωi) |cos θi| dωi over the sphere (g is 0 where it should be) by the
/// midpoint rule in (θ, φ).
pub(crate) fn albedo_by_quadrature(g: impl Fn(Vec3) -> f32) -> f64 {
    let (nt, np) = (2400, 2400);
    let (dt, dp) = (
        std::f64::consts::PI / nt as f64,
        std::f64::consts::TAU / np as f64,
    );
    let mut s = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) * dt;
        let w = t.sin() * t.cos().abs() * dt * dp;
        for j in 0..np {
            s += g(dir(t, (j as f64 + 0.5) * dp)) as f64 * w;
        }
    }
    s
}

/// The mean sampled weight over a stratified grid of the sampling square
/// (a lost sample weighs 0).
pub(crate) fn albedo_by_sampling(mut sample: impl FnMut([f32; 2]) -> Option<f32>) -> f64 {
    let n = 512;
    let mut s = 0.0;
    for i in 0..n {
        for j in 0..n {
            let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
            s += sample(u).unwrap_or(0.0) as f64;
        }
    }
    s / (n * n) as f64
}

/// Random direction pairs above the surface.
fn pairs(key: u64) -> impl Iterator<Item = (Vec3, Vec3)> {
    let mut rng = Rng::from_key(key);
    (0..500).map(move |_| {
        let mut d = || {
            dir(
                rng.uniform_f64() * 1.5,
                rng.uniform_f64() * std::f64::consts::TAU,
            )
        };
        (d(), d())
    })
}

/// f(ωo, ωi) = f(ωi, ωo).
pub(crate) fn check_reciprocity(f: impl Fn(Vec3, Vec3) -> Vec3) {
    for (wo, wi) in pairs(3) {
        let (a, b) = (f(wo, wi), f(wi, wo));
        let tol = 1e-4 * a.max(b).max_element() + 1e-7;
        assert!((a - b).abs().max_element() <= tol, "{wo} {wi}: {a} vs {b}");
    }
}

/// Every sample's weight is f cos θi / pdf and its pdf is `pdf(ωo, ωi)`.
pub(crate) fn check_sampled_weights(
    sample: impl Fn(Vec3, [f32; 2]) -> Option<(Vec3, Vec3, f32)>,
    f: impl Fn(Vec3, Vec3) -> Vec3,
    pdf: impl Fn(Vec3, Vec3) -> f32,
) {
    let mut rng = Rng::from_key(5);
    let mut checked = 0;
    for (wo, _) in pairs(9) {
        let Some((wi, w, p)) = sample(wo, rng.uniform2()) else {
            continue;
        };
        let p_eval = pdf(wo, wi);
        assert!((p / p_eval - 1.0).abs() < 1e-3, "pdf {p} vs {p_eval}");
        let want = f(wo, wi) * (wi.z.abs() / p_eval);
        let tol = 2e-3 * want.max_element() + 1e-7;
        assert!((w - want).abs().max_element() <= tol, "{w} vs {want}");
        checked += 1;
    }
    assert!(checked > 400, "{checked} of 500 samples kept");
}

/// ∫ pdf dωi equals the fraction of samples the lobe keeps: a pdf off by
/// a factor, or a density that leaks below the horizon, fails.
pub(crate) fn check_pdf_matches_kept(
    pdf: impl Fn(Vec3, Vec3) -> f32,
    kept: impl Fn(Vec3, [f32; 2]) -> bool,
) {
    for mu in [0.2f32, 0.7] {
        let wo = from_mu(mu);
        let integral = albedo_by_quadrature(|wi| {
            if wi.z.abs() > 0.0 {
                pdf(wo, wi) / wi.z.abs()
            } else {
                0.0
            }
        });
        let fraction = albedo_by_sampling(|u| Some(kept(wo, u) as u32 as f32));
        assert!(
            (integral - fraction).abs() < 5e-3,
            "μo {mu}: ∫ pdf = {integral}, kept {fraction}"
        );
    }
}
