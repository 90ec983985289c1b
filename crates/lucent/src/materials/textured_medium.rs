//! The medium of a subsurface material at one point of a textured surface:
//! its albedo A and its lengths read there, and how the parameters the
//! BSSRDF needs follow from them (`docs/bssrdf.md` §13). The BSSRDF takes
//! the parameters of the exit point xo, where the path meets the surface.

use crate::bssrdf::{AlbedoSource, Fit, SubsurfaceParams};
use crate::geometry::Vec3;

/// The least factor on a preset's or measured medium's lengths: a texel
/// of 0 makes its channel's profile this short, not a division by 0.
pub const MIN_LENGTH_FACTOR: f64 = 1e-6;

/// How a textured subsurface material's parameters at a point follow from
/// the texture values there.
#[derive(Clone, Debug, PartialEq)]
pub enum MediumRecipe {
    /// The artist form: A = `albedo` × the albedo texture (clamped to
    /// [0, 1]), ℓ = `dmfp` × the length texture (negative texels read as
    /// 0: an inactive channel); d and the random walk's medium are derived
    /// from (A, ℓ) exactly as for a constant material.
    Artist {
        albedo: [f64; 3],
        /// ℓ per channel in scene units.
        dmfp: [f64; 3],
        eta: f32,
        fit: Fit,
        source: AlbedoSource,
    },
    /// A preset or measured medium: its A is as given, its lengths (d, the
    /// walk's mean free paths) scale by the length texture per channel,
    /// at least [`MIN_LENGTH_FACTOR`].
    Lengths,
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
                source,
            } => {
                let a = std::array::from_fn(|c| match albedo {
                    Some(t) => (t[c] as f64 * a0[c]).clamp(0.0, 1.0),
                    None => a0[c],
                });
                let mfp = std::array::from_fn(|c| match factor {
                    Some(k) => dmfp[c] * (k[c] as f64).max(0.0),
                    None => dmfp[c],
                });
                SubsurfaceParams::from_artist_with(a, mfp, *eta, *fit, *source).unwrap_or(*base)
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
