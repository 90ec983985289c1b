//! What a homogeneous sphere behind a smooth dielectric boundary reflects
//! under uniform light, against what the half-space of the same medium
//! reflects, by the random walk's own physics: the generator of the
//! curvature table (`bssrdf::curvature_table`, `docs/bssrdf.md` §10).
//!
//! Tabulated is h(ρ, x, η) = (1 − A_sphere) / (1 − A_slab), x = √(1 − α'),
//! the ratio of what a sphere of radius ρ ℓd and the half-space absorb.
//! The walk is `integrator::randomwalk`'s with the mesh replaced by the
//! analytic sphere or plane ([`free_flight`], [`sample_hg`],
//! [`dielectric::sample`]), absorption analog, so each walk scores 0 or 1.
//! The quantity, why one entry point suffices, and the walk's units:
//! `docs/bssrdf.md` §12.9.

use crate::halfspace::{enter, Entry};
use glam::DVec3;
use lucent::geometry::Frame;
use lucent::integrator::randomwalk::{free_flight, sample_hg};
use lucent::materials::dielectric;
use lucent::sampling::{Draw, Rng};

/// The body a walk runs in (lengths in reduced mean free paths).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Body {
    /// The ball of this radius centred at the origin; light enters at its
    /// north pole (0, 0, radius).
    Sphere(f64),
    /// The half-space z < 0; light enters at the origin.
    HalfSpace,
}

/// Distance along unit `d` from `p` (inside) to the boundary of `body`.
fn to_boundary(body: Body, p: DVec3, d: DVec3) -> f64 {
    match body {
        Body::HalfSpace => {
            if d.z > 0.0 {
                -p.z / d.z
            } else {
                f64::INFINITY
            }
        }
        Body::Sphere(r) => {
            // |p + t d|² = r², the positive root (p inside: c ≤ 0).
            let b = p.dot(d);
            let c = (p.length_squared() - r * r).min(0.0);
            let disc = (b * b - c).max(0.0).sqrt();
            // −b + √(b² − c), written without cancellation when b > 0.
            if b > 0.0 {
                -c / (b + disc)
            } else {
                disc - b
            }
        }
    }
}

/// Outward unit normal of `body` at boundary point `p`.
fn outward(body: Body, p: DVec3) -> DVec3 {
    match body {
        Body::HalfSpace => DVec3::Z,
        Body::Sphere(_) => p.normalize(),
    }
}

/// One walk of light entering `body` from uniform radiance outside, in a
/// medium of reduced albedo `alpha` and relative index `eta`: whether it
/// leaves again, and how many scattering events it had.
pub fn walk(body: Body, alpha: f64, eta: f32, rng: &mut impl Draw) -> (bool, u64) {
    let (exit, events) = walk_to_exit(body, Entry::Diffuse, alpha, eta, rng);
    (exit.is_some(), events)
}

/// [`walk`] with the point where the light leaves (None if absorbed) and
/// the light entering as `entry` says (the same random numbers as [`walk`]
/// for [`Entry::Diffuse`]): what `crate::sphere_transfer` bins by
/// distance.
pub fn walk_to_exit(
    body: Body,
    entry: Entry,
    alpha: f64,
    eta: f32,
    rng: &mut impl Draw,
) -> (Option<DVec3>, u64) {
    let mut d = enter(eta, entry, rng).as_dvec3().normalize();
    let mut p = match body {
        Body::Sphere(r) => DVec3::new(0.0, 0.0, r),
        Body::HalfSpace => DVec3::ZERO,
    };
    let mut events = 0u64;
    loop {
        let t = free_flight(1.0, rng.uniform_f64());
        let s = to_boundary(body, p, d);
        if t >= s {
            // The boundary, seen from inside: wo points back into the medium.
            let n = outward(body, p + s * d);
            p = match body {
                // Back onto the sphere, so rounding never leaves p outside.
                Body::Sphere(r) => n * r,
                Body::HalfSpace => {
                    let q = p + s * d;
                    DVec3::new(q.x, q.y, 0.0)
                }
            };
            let frame = Frame::from_normal(n.as_vec3());
            let wo = frame.to_local(-d.as_vec3());
            let b = dielectric::sample(eta, wo, rng.uniform());
            if b.transmitted {
                return (Some(p), events);
            }
            d = frame.to_world(b.wi).as_dvec3().normalize();
            continue;
        }
        p += t * d;
        events += 1;
        if rng.uniform_f64() >= alpha {
            return (None, events);
        }
        d = sample_hg(d.as_vec3(), 0.0, rng.uniform2())
            .as_dvec3()
            .normalize();
    }
}

/// The escape fraction of `walks` walks, its standard error and the events
/// simulated. Chunk k of `chunk` walks draws from the stream (seed, stream,
/// k), so the result does not depend on the thread count.
pub fn escape(
    body: Body,
    alpha: f64,
    eta: f32,
    walks: u64,
    seed: u64,
    stream: u64,
) -> (f64, f64, u64) {
    use rayon::prelude::*;
    const CHUNK: u64 = 2_000;
    let chunks = walks.div_ceil(CHUNK);
    let (out, events) = (0..chunks)
        .into_par_iter()
        .map(|k| {
            let mut rng = Rng::new(seed, stream, k);
            let (mut out, mut ev) = (0u64, 0u64);
            for _ in 0..CHUNK.min(walks - k * CHUNK) {
                let (o, e) = walk(body, alpha, eta, &mut rng);
                out += o as u64;
                ev += e;
            }
            (out, ev)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    let a = out as f64 / walks as f64;
    (a, (a * (1.0 - a) / walks as f64).sqrt(), events)
}

/// What the generator runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub etas: Vec<f64>,
    /// x = √(1 − α') nodes, increasing, all in (0, 1].
    pub xs: Vec<f64>,
    /// Sphere radii in diffusion lengths, increasing.
    pub rhos: Vec<f64>,
    pub walks_sphere: u64,
    pub walks_slab: u64,
    pub seed: u64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            etas: vec![1.0, 1.3, 1.5, 2.0],
            xs: vec![0.01, 0.03, 0.06, 0.1, 0.15, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0],
            rhos: (0..=14)
                .map(|k| 0.125 * 2f64.powf(k as f64 / 2.0))
                .collect(),
            walks_sphere: 60_000,
            walks_slab: 200_000,
            seed: 2026,
        }
    }
}

/// One node of the table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    pub eta: f64,
    pub x: f64,
    pub rho: f64,
    pub a_sphere: f64,
    pub se_sphere: f64,
    pub a_slab: f64,
    pub se_slab: f64,
    /// (1 − A_sphere) / (1 − A_slab).
    pub h: f64,
    /// Its standard error (the two estimates are independent).
    pub se_h: f64,
}

/// The table and its cost.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    pub nodes: Vec<Node>,
    pub events: u64,
}

/// Runs every (η, x, ρ) node of `s`.
pub fn generate(s: &Settings, mut progress: impl FnMut(&str)) -> Table {
    let mut t = Table {
        nodes: Vec::new(),
        events: 0,
    };
    for (ie, &eta) in s.etas.iter().enumerate() {
        for (ix, &x) in s.xs.iter().enumerate() {
            let alpha = 1.0 - x * x;
            let stream = ((ie * 64 + ix) * 64) as u64;
            let (a_slab, se_slab, ev) = escape(
                Body::HalfSpace,
                alpha,
                eta as f32,
                s.walks_slab,
                s.seed,
                stream,
            );
            t.events += ev;
            for (ir, &rho) in s.rhos.iter().enumerate() {
                let radius = rho / (3f64.sqrt() * x);
                let (a, se, ev) = escape(
                    Body::Sphere(radius),
                    alpha,
                    eta as f32,
                    s.walks_sphere,
                    s.seed,
                    stream + 1 + ir as u64,
                );
                t.events += ev;
                let (u, v) = (1.0 - a, 1.0 - a_slab);
                let h = u / v;
                let se_h = (se * se / (v * v) + se_slab * se_slab * u * u / (v * v * v * v)).sqrt();
                t.nodes.push(Node {
                    eta,
                    x,
                    rho,
                    a_sphere: a,
                    se_sphere: se,
                    a_slab,
                    se_slab,
                    h,
                    se_h,
                });
            }
            progress(&format!(
                "eta {eta:.2} x {x:.3}: A_slab {a_slab:.4}, {:.3e} events so far",
                t.events as f64
            ));
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The half-space walker here against the albedo table's generator
    /// (α^n counting, a different estimator of the same physics) at one
    /// node: the same R within the two standard errors.
    #[test]
    fn half_space_escape_matches_the_albedo_table_walker() {
        let (alpha, eta) = (0.9, 1.3);
        let (a, se, _) = escape(Body::HalfSpace, alpha, eta, 100_000, 7, 0);
        let b = crate::halfspace::Batch {
            walks: 100_000,
            cap: 10_000,
            seed: 8,
            chunk: 5_000,
        };
        let t = crate::halfspace::run(eta as f64, 0.0, Entry::Diffuse, &[alpha], &b);
        let (r, se_r) = t.estimate(0);
        assert!(
            (a - r).abs() < 4.0 * (se * se + se_r * se_r).sqrt(),
            "{a} ± {se} vs {r} ± {se_r}"
        );
    }

    /// A sphere that absorbs nothing returns everything that enters, and a
    /// huge sphere reflects what the half-space does.
    #[test]
    fn sphere_limits() {
        let (a, _, _) = escape(Body::Sphere(3.0), 1.0, 1.4, 2_000, 1, 0);
        assert_eq!(a, 1.0);
        let (big, se_b, _) = escape(Body::Sphere(1e4), 0.8, 1.3, 100_000, 2, 0);
        let (flat, se_f, _) = escape(Body::HalfSpace, 0.8, 1.3, 100_000, 3, 0);
        assert!(
            (big - flat).abs() < 4.0 * (se_b * se_b + se_f * se_f).sqrt(),
            "{big} vs {flat}"
        );
    }
}
