//! The generator of the tabulated diffusion profile
//! (`bssrdf::profile_table`, `docs/bssrdf.md` §10, "Where the light
//! leaves"): where diffuse light entering the half-space of a medium at
//! one point leaves it, by the random walk's own physics, binned by the
//! distance r from the entry point in diffusion lengths u = r/ℓd.
//!
//! Per node (η, x = √(1 − α')) the table holds the share of the escaping
//! light that leaves in each bin of u — the profile's shape; its total is
//! the albedo table's business. The walk is [`crate::sphere_transfer`]'s on
//! [`Body::HalfSpace`] (lengths in reduced mean free paths, where ℓd =
//! 1/(√3 x)). Bins: [0, u₀) then geometric, [`BINS_PER_OCTAVE`] per factor
//! 2, up to [`U_LAST`]; exits beyond it (a share below e⁻⁶⁰) are dropped.

use crate::halfspace::Entry;
use crate::sphere_albedo::Body;
use crate::sphere_transfer::{transfer, Walks};

/// The first bin's outer edge, u₀ = 2⁻⁹ diffusion lengths.
pub const U_FIRST: f64 = 1.0 / 512.0;
/// The last edge, 64 diffusion lengths.
pub const U_LAST: f64 = 64.0;
/// Geometric bins per factor 2 in u.
pub const BINS_PER_OCTAVE: usize = 4;

/// The bin edges in u: 0, then U_FIRST·2^(k/BINS_PER_OCTAVE) up to U_LAST.
pub fn edges() -> Vec<f64> {
    let octaves = (U_LAST / U_FIRST).log2().round() as usize;
    std::iter::once(0.0)
        .chain(
            (0..=octaves * BINS_PER_OCTAVE)
                .map(|k| U_FIRST * 2f64.powf(k as f64 / BINS_PER_OCTAVE as f64)),
        )
        .collect()
}

/// What the generator runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub etas: Vec<f64>,
    /// x = √(1 − α') nodes, increasing, all in (0, 1).
    pub xs: Vec<f64>,
    pub walks: u64,
    pub seed: u64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            etas: vec![1.0, 1.3, 1.5, 2.0],
            xs: vec![0.01, 0.03, 0.06, 0.1, 0.15, 0.2, 0.3, 0.45, 0.6, 0.8],
            walks: 1_000_000,
            seed: 2027,
        }
    }
}

/// One node: the escape fraction and, per bin, the share of the escaping
/// light leaving there with its standard error.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub eta: f64,
    pub x: f64,
    pub escape: f64,
    pub share: Vec<f64>,
    pub se: Vec<f64>,
}

/// Runs one node of `walks` walks from stream `stream`.
pub fn node(eta: f64, x: f64, walks: u64, seed: u64, stream: u64) -> Node {
    let ld = 1.0 / (3f64.sqrt() * x);
    let e: Vec<f64> = edges().iter().map(|u| u * ld).collect();
    let w = Walks {
        body: Body::HalfSpace,
        entry: Entry::Diffuse,
        alpha: 1.0 - x * x,
        eta: eta as f32,
        walks,
        seed,
        stream,
    };
    let t = transfer(&w, &e);
    let out: u64 = t.counts.iter().sum();
    let n = out.max(1) as f64;
    let share: Vec<f64> = t.counts.iter().map(|&c| c as f64 / n).collect();
    let se = share.iter().map(|&p| (p * (1.0 - p) / n).sqrt()).collect();
    Node {
        eta,
        x,
        escape: out as f64 / walks as f64,
        share,
        se,
    }
}

/// Runs every (η, x) node of `s`; node (i_η, i_x) draws from stream
/// 64·i_η + i_x, so the table does not depend on the thread count.
pub fn generate(s: &Settings, mut progress: impl FnMut(&str)) -> Vec<Node> {
    let mut nodes = Vec::new();
    for (ie, &eta) in s.etas.iter().enumerate() {
        for (ix, &x) in s.xs.iter().enumerate() {
            let n = node(eta, x, s.walks, s.seed, (64 * ie + ix) as u64);
            progress(&format!("eta {eta:.2} x {x:.3}: escape {:.4}", n.escape));
            nodes.push(n);
        }
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere_albedo::escape;

    /// The shares sum to 1 and the escape fraction is the one
    /// [`escape`] counts from the same random numbers: a binning that lost
    /// the first bin or the exits near u₀ would fall short of it.
    #[test]
    fn the_shares_cover_every_exit() {
        let n = node(1.3, 0.1, 6_000, 5, 2);
        assert!((n.share.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let (a, _, _) = escape(Body::HalfSpace, 1.0 - 0.01, 1.3, 6_000, 5, 2);
        assert_eq!(n.escape, a);
        // light leaves near where it entered: most of it within one ℓd
        let within: f64 = edges()
            .windows(2)
            .zip(&n.share)
            .filter(|(e, _)| e[1] <= 1.0)
            .map(|(_, s)| s)
            .sum();
        assert!(within > 0.5 && within < 0.99, "{within}");
    }
}
