//! Where light that enters a sphere (or the half-space) at one point
//! leaves it, by the random walk's own physics: the point-to-point
//! transfer T(r) per unit exit area as a function of the chord distance r
//! from the entry point, for diffuse incidence — what the diffusion
//! estimator models as A·Rd(r)·√(f(κo)f(κi)) (`docs/bssrdf.md` §10,
//! "Where the light leaves").
//!
//! The walk is [`crate::sphere_albedo::walk_to_exit`]'s (lengths in reduced mean
//! free paths). On a sphere of radius R the area within chord distance r
//! of a surface point is πr² for r ≤ 2R (Archimedes), as on the plane, so
//! a bin [r_a, r_b) has area π(r_b² − r_a²) on both bodies.

use crate::sphere_albedo::{walk_to_exit, Body};
use lucent::sampling::Rng;

/// Exits of `walks` walks binned by chord distance from the entry point.
#[derive(Clone, Debug, PartialEq)]
pub struct Transfer {
    /// Bin edges (reduced mean free paths), increasing, from 0.
    pub edges: Vec<f64>,
    /// Exits per bin; exits beyond the last edge are not counted.
    pub counts: Vec<u64>,
    pub walks: u64,
}

impl Transfer {
    /// T(r) in bin `i`: exits per entering walk per unit area.
    pub fn density(&self, i: usize) -> f64 {
        let (a, b) = (self.edges[i], self.edges[i + 1]);
        self.counts[i] as f64 / (self.walks as f64 * std::f64::consts::PI * (b * b - a * a))
    }

    /// The fraction of entering light that leaves in bins `range`.
    pub fn fraction(&self, range: std::ops::Range<usize>) -> f64 {
        self.counts[range].iter().sum::<u64>() as f64 / self.walks as f64
    }
}

/// Runs `walks` walks into `body` (reduced albedo `alpha`, index `eta`)
/// and bins their exits by `edges`. Chunk k draws from the stream (seed,
/// stream, k): the result does not depend on the thread count.
pub fn transfer(
    body: Body,
    alpha: f64,
    eta: f32,
    edges: &[f64],
    walks: u64,
    seed: u64,
    stream: u64,
) -> Transfer {
    use rayon::prelude::*;
    const CHUNK: u64 = 2_000;
    let entry = match body {
        Body::Sphere(r) => glam::DVec3::new(0.0, 0.0, r),
        Body::HalfSpace => glam::DVec3::ZERO,
    };
    let bins = edges.len() - 1;
    let counts = (0..walks.div_ceil(CHUNK))
        .into_par_iter()
        .map(|k| {
            let mut rng = Rng::new(seed, stream, k);
            let mut counts = vec![0u64; bins];
            for _ in 0..CHUNK.min(walks - k * CHUNK) {
                let Some(p) = walk_to_exit(body, alpha, eta, &mut rng).0 else {
                    continue;
                };
                let r = (p - entry).length();
                let i = edges.partition_point(|&e| e <= r);
                if (1..=bins).contains(&i) {
                    counts[i - 1] += 1;
                }
            }
            counts
        })
        .reduce(
            || vec![0u64; bins],
            |a, b| a.iter().zip(&b).map(|(x, y)| x + y).collect(),
        );
    Transfer {
        edges: edges.to_vec(),
        counts,
        walks,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere_albedo::escape;

    /// Binned over every chord a sphere has (0 … 2R), the exits are the
    /// escape fraction [`escape`] counts with the same random numbers:
    /// a binning that dropped or double-counted exits would differ.
    #[test]
    fn all_bins_together_are_the_escape_fraction() {
        let radius = 5.0;
        let edges: Vec<f64> = (0..=20).map(|i| 2.0 * radius * i as f64 / 20.0).collect();
        let edges = [&edges[..20], &[2.0 * radius + 1e-9]].concat();
        let t = transfer(Body::Sphere(radius), 0.99, 1.3, &edges, 4_000, 7, 3);
        let (a, _, _) = escape(Body::Sphere(radius), 0.99, 1.3, 4_000, 7, 3);
        assert_eq!(t.fraction(0..20), a);
        // exits cluster near the entry: the first bin's density is the highest
        assert!((1..20).all(|i| t.density(0) > t.density(i)));
    }
}
