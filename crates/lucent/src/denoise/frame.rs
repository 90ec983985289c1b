//! A frame's denoise from its own layers: the guides are the `albedo`
//! (`R`, `G`, `B`) and `N` (`X`, `Y`, `Z`) passes, the result the light
//! layer [`LAYER`] (`denoised.R`, `denoised.G`, `denoised.B`), which the
//! PNG preview shows (docs/output.md, "Denoising").

use super::filter::{denoise, DenoiseInput, DenoiseOptions};
use crate::error::Error;
use crate::film::layers::{Layer, LayerKind};
use crate::film::Film;
use crate::geometry::Vec3;

/// The name of the denoised beauty's layer.
pub const LAYER: &str = "denoised";

/// The guide layers a denoise needs, albedo then normal: (layer, its
/// channels), the names of `Pass::Albedo` and `Pass::Normal`.
pub const GUIDES: [(&str, [&str; 3]); 2] = [("albedo", ["R", "G", "B"]), ("N", ["X", "Y", "Z"])];

/// The denoised beauty of `film` guided by its `albedo` and `N` layers
/// among `layers`: the image (for the preview) and its layer.
pub fn denoise_layers(
    film: &Film,
    layers: &[Layer],
    opts: &DenoiseOptions,
) -> Result<(Film, Layer), Error> {
    let guide = |(name, _): (&str, [&str; 3])| -> Result<Vec<Vec3>, Error> {
        let l = layers
            .iter()
            .find(|l| l.name == name && l.channels.len() == 3)
            .ok_or_else(|| {
                Error::Input(format!(
                    "cannot denoise: the frame has no {name} pass (a guide OIDN needs)"
                ))
            })?;
        Ok(l.values
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect())
    };
    let (albedo, normal) = (guide(GUIDES[0])?, guide(GUIDES[1])?);
    let input = DenoiseInput {
        width: film.width,
        height: film.height,
        color: &film.pixels,
        albedo: &albedo,
        normal: &normal,
    };
    let pixels = denoise(&input, opts)?;
    let layer = layer_of(&pixels);
    let film = Film {
        width: film.width,
        height: film.height,
        pixels,
    };
    Ok((film, layer))
}

/// The denoised pixels as the layer [`LAYER`].
pub fn layer_of(pixels: &[Vec3]) -> Layer {
    Layer {
        name: LAYER.into(),
        channels: ["R", "G", "B"].map(String::from).to_vec(),
        kind: LayerKind::Light,
        values: pixels.iter().flat_map(|p| p.to_array()).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::passes::Pass;

    #[test]
    fn the_guides_are_the_albedo_and_normal_passes() {
        assert_eq!(GUIDES[0].0, Pass::Albedo.name());
        assert_eq!(GUIDES[1].0, Pass::Normal.name());
    }
}
