//! Where light that enters a sphere (or the half-space) at one point
//! leaves it, by the random walk's own physics: the point-to-point
//! transfer T(r) per unit exit area as a function of the chord distance r
//! from the entry point — what the diffusion estimator models as
//! A·Rd(r)·√(f(κo)f(κi)) (`docs/bssrdf.md` §10, "Where the light
//! leaves"). For diffuse incidence T depends on r alone; for light from
//! one side ([`Entry::Oblique`]) the exits ahead of the entry point (on
//! the side the refracted light heads to, x < 0) are counted apart.
//!
//! The walk is [`crate::sphere_albedo::walk_to_exit`]'s (lengths in reduced mean
//! free paths). On a sphere of radius R the area within chord distance r
//! of a surface point is πr² for r ≤ 2R (Archimedes), as on the plane, so
//! a bin [r_a, r_b) has area π(r_b² − r_a²) on both bodies.

use crate::halfspace::Entry;
use crate::sphere_albedo::{walk_to_exit, Body};
use lucent::sampling::Rng;

/// Exits of `walks` walks binned by chord distance from the entry point.
#[derive(Clone, Debug, PartialEq)]
pub struct Transfer {
    /// Bin edges (reduced mean free paths), increasing, from 0.
    pub edges: Vec<f64>,
    /// Exits per bin; exits beyond the last edge are not counted.
    pub counts: Vec<u64>,
    /// Of those, the exits ahead of the entry point (x < 0).
    pub ahead: Vec<u64>,
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

/// One set of walks: where and how the light enters, the medium, how
/// many walks and their random streams.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Walks {
    pub body: Body,
    pub entry: Entry,
    /// Reduced single-scattering albedo α'.
    pub alpha: f64,
    /// Relative index of refraction (inside / outside).
    pub eta: f32,
    pub walks: u64,
    pub seed: u64,
    pub stream: u64,
}

/// Runs `w` and bins the exits by `edges`. Chunk k draws from the stream
/// (seed, stream, k): the result does not depend on the thread count.
pub fn transfer(w: &Walks, edges: &[f64]) -> Transfer {
    let &Walks {
        body,
        entry,
        alpha,
        eta,
        walks,
        seed,
        stream,
    } = w;
    use rayon::prelude::*;
    const CHUNK: u64 = 2_000;
    let entry_point = match body {
        Body::Sphere(r) => glam::DVec3::new(0.0, 0.0, r),
        Body::HalfSpace => glam::DVec3::ZERO,
    };
    let bins = edges.len() - 1;
    let (counts, ahead) = (0..walks.div_ceil(CHUNK))
        .into_par_iter()
        .map(|k| {
            let mut rng = Rng::new(seed, stream, k);
            let (mut counts, mut ahead) = (vec![0u64; bins], vec![0u64; bins]);
            for _ in 0..CHUNK.min(walks - k * CHUNK) {
                let Some(p) = walk_to_exit(body, entry, alpha, eta, &mut rng).0 else {
                    continue;
                };
                let r = (p - entry_point).length();
                let i = edges.partition_point(|&e| e <= r);
                if (1..=bins).contains(&i) {
                    counts[i - 1] += 1;
                    ahead[i - 1] += (p.x < 0.0) as u64;
                }
            }
            (counts, ahead)
        })
        .reduce(
            || (vec![0u64; bins], vec![0u64; bins]),
            |a, b| (add(&a.0, &b.0), add(&a.1, &b.1)),
        );
    Transfer {
        edges: edges.to_vec(),
        counts,
        ahead,
        walks,
    }
}

fn add(a: &[u64], b: &[u64]) -> Vec<u64> {
    a.iter().zip(b).map(|(x, y)| x + y).collect()
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
        let sphere = Body::Sphere(radius);
        let w = Walks {
            body: sphere,
            entry: Entry::Diffuse,
            alpha: 0.99,
            eta: 1.3,
            walks: 4_000,
            seed: 7,
            stream: 3,
        };
        let t = transfer(&w, &edges);
        let (a, _, _) = escape(sphere, 0.99, 1.3, 4_000, 7, 3);
        assert_eq!(t.fraction(0..20), a);
        // exits cluster near the entry: the first bin's density is the highest
        assert!((1..20).all(|i| t.density(0) > t.density(i)));
    }

    /// Diffuse light leaves as much ahead of the entry point as behind it
    /// (within 4σ); light from the +x side at 80° to the normal refracts
    /// towards −x and leaves ahead of it more often than behind, most of
    /// all near the entry point.
    #[test]
    fn light_from_one_side_leaves_ahead_of_its_entry_point() {
        let edges = [0.0, 1.0, 4.0, 1e9];
        let share = |entry| {
            let w = Walks {
                body: Body::HalfSpace,
                entry,
                alpha: 0.99,
                eta: 1.5,
                walks: 40_000,
                seed: 7,
                stream: 5,
            };
            let t = transfer(&w, &edges);
            let n = t.counts.iter().sum::<u64>() as f64;
            (
                t.ahead.iter().sum::<u64>() as f64 / n,
                t.ahead[0] as f64 / t.counts[0] as f64,
                n,
            )
        };
        let (diffuse, _, n) = share(Entry::Diffuse);
        assert!((diffuse - 0.5).abs() < 4.0 * (0.25 / n).sqrt(), "{diffuse}");
        let (oblique, near, _) = share(Entry::Oblique(0.17));
        assert!(oblique > 0.55 && near > oblique, "{oblique} {near}");
    }
}
