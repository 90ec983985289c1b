//! The medium of a subsurface material at one point of a textured surface:
//! its albedo A and its lengths read there, and how the parameters the
//! BSSRDF needs follow from them (`docs/bssrdf.md` §13). The BSSRDF takes
//! the parameters of the exit point xo, where the path meets the surface.

use std::sync::Arc;

use crate::bssrdf::params::invert_reflectance;
use crate::bssrdf::{AlbedoSource, Fit, SubsurfaceParams};
use crate::geometry::Vec3;

/// The least factor on a preset's or measured medium's lengths: a texel
/// of 0 makes its channel's profile this short, not a division by 0.
pub const MIN_LENGTH_FACTOR: f64 = 1e-6;

/// Intervals of A in [`ReducedAlbedo`]'s table.
const INVERSE_NODES: usize = 1024;

/// How a textured subsurface material's parameters at a point follow from
/// the texture values there.
#[derive(Clone, Debug, PartialEq)]
pub enum MediumRecipe {
    /// The artist form: A = `albedo` × the albedo texture (clamped to
    /// [0, 1]), ℓ = `dmfp` × the length texture (negative texels read as
    /// 0: an inactive channel); d and the random walk's medium are derived
    /// from (A, ℓ) as for a constant material, the medium's reduced albedo
    /// α' from `reduced`.
    Artist {
        albedo: [f64; 3],
        /// ℓ per channel in scene units.
        dmfp: [f64; 3],
        eta: f32,
        fit: Fit,
        reduced: Reduced,
    },
    /// A preset or measured medium: its A is as given, its lengths (d, the
    /// walk's mean free paths) scale by the length texture per channel,
    /// at least [`MIN_LENGTH_FACTOR`].
    Lengths,
}

/// Where the artist form's α' per channel comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Reduced {
    /// A is not textured: α' of the material's A, inverted once (as the
    /// constant material's).
    Fixed([f64; 3]),
    /// A is textured: α'(A) from a table of the inversion.
    Table(Arc<ReducedAlbedo>),
}

impl Reduced {
    /// The α' of the artist form's `albedo` under `source` at index `eta`:
    /// a table when `textured`, else the three values.
    pub fn new(albedo: [f64; 3], eta: f32, source: AlbedoSource, textured: bool) -> Self {
        if textured {
            Reduced::Table(Arc::new(ReducedAlbedo::new(eta, source)))
        } else {
            Reduced::Fixed(albedo.map(|a| invert_reflectance(a, eta as f64, source)))
        }
    }
}

/// α'(A) for one η and albedo source: x = √(1 − α') at A = i/N, i = 0 … N,
/// linear in A between nodes (x is close to linear in A near A = 1, where
/// α' itself is steep). Built once per material; a lookup is two reads
/// instead of the inversion's bisection.
#[derive(Clone, Debug, PartialEq)]
pub struct ReducedAlbedo {
    x: Vec<f64>,
}

impl ReducedAlbedo {
    pub fn new(eta: f32, source: AlbedoSource) -> Self {
        let x = (0..=INVERSE_NODES)
            .map(|i| {
                let a = i as f64 / INVERSE_NODES as f64;
                (1.0 - invert_reflectance(a, eta as f64, source))
                    .max(0.0)
                    .sqrt()
            })
            .collect();
        ReducedAlbedo { x }
    }

    /// α' whose reflectance is `a` ∈ [0, 1].
    pub fn at(&self, a: f64) -> f64 {
        let t = a.clamp(0.0, 1.0) * INVERSE_NODES as f64;
        let i = (t as usize).min(INVERSE_NODES - 1);
        let x = self.x[i] + (self.x[i + 1] - self.x[i]) * (t - i as f64);
        1.0 - x * x
    }
}

impl MediumRecipe {
    /// The parameters at a point where the albedo texture reads `albedo`
    /// and the length texture `factor` (None: not textured), given the
    /// material's constant parameters `base`. `base` where the values
    /// give no valid medium.
    pub fn params_at(
        &self,
        base: &SubsurfaceParams,
        albedo: Option<Vec3>,
        factor: Option<Vec3>,
    ) -> SubsurfaceParams {
        match self {
            MediumRecipe::Artist {
                albedo: a0,
                dmfp,
                eta,
                fit,
                reduced,
            } => {
                let a: [f64; 3] = std::array::from_fn(|c| match albedo {
                    Some(t) => (t[c] as f64 * a0[c]).clamp(0.0, 1.0),
                    None => a0[c],
                });
                let mfp = std::array::from_fn(|c| match factor {
                    Some(k) => dmfp[c] * (k[c] as f64).max(0.0),
                    None => dmfp[c],
                });
                let alpha = |c: usize| match reduced {
                    Reduced::Fixed(alpha) => alpha[c],
                    Reduced::Table(t) => t.at(a[c]),
                };
                SubsurfaceParams::from_artist_reduced(a, mfp, *eta, *fit, alpha).unwrap_or(*base)
            }
            MediumRecipe::Lengths => match factor {
                Some(k) => {
                    base.scaled_channels(k.to_array().map(|k| (k as f64).max(MIN_LENGTH_FACTOR)))
                }
                None => *base,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Caught: a table off the inversion it stands for (nodes misplaced,
    /// x read as α', the interpolation between the wrong nodes).
    #[test]
    fn the_inverse_table_matches_the_inversion() {
        for source in [AlbedoSource::Table, AlbedoSource::Given] {
            let t = ReducedAlbedo::new(1.4, source);
            for k in 0..=200 {
                let a = k as f64 / 200.0 * 0.999;
                let want = invert_reflectance(a, 1.4, source);
                let got = t.at(a);
                assert!(
                    (got - want).abs() < 2e-5 && ((1.0 - got) / (1.0 - want) - 1.0).abs() < 5e-3,
                    "{source:?} A = {a}: {got} against {want}"
                );
            }
        }
    }
}
