//! A frame's denoise from its own layers: the guides are the `albedo`
//! (`R`, `G`, `B`) and `N` (`X`, `Y`, `Z`) passes, the result the light
//! layer [`LAYER`] (`denoised.R`, `denoised.G`, `denoised.B`), which the
//! PNG preview shows, and, when asked, each light layer denoised with the
//! same guides as `denoised_<layer>` ([`layer_name`]; docs/output.md,
//! "Denoising").

use super::filter::{denoise_with, DenoiseInput, DenoiseOptions};
use crate::error::Error;
use crate::film::layers::{Layer, LayerKind};
use crate::film::Film;
use crate::geometry::Vec3;

/// The name of the denoised beauty's layer.
pub const LAYER: &str = "denoised";

/// The guide layers a denoise needs, albedo then normal: (layer, its
/// channels), the names of `Pass::Albedo` and `Pass::Normal`.
pub const GUIDES: [(&str, [&str; 3]); 2] = [("albedo", ["R", "G", "B"]), ("N", ["X", "Y", "Z"])];

/// The prefix of a denoised light layer's name.
pub const PREFIX: &str = "denoised_";

/// The name of light layer `name` denoised: `denoised_diffuse_direct`,
/// `denoised_RGBA_key` (not `RGBA_…`, so no tool takes it for a light
/// group and adds it to the others).
pub fn layer_name(name: &str) -> String {
    format!("{PREFIX}{name}")
}

/// Whether the layer `name` of `kind` and `channels` is a light layer a
/// denoise with `layers` denoises: R G B radiance (a light group's `A`
/// beside them is coverage, not denoised), not itself denoised.
pub fn is_denoisable(name: &str, kind: LayerKind, channels: &[String]) -> bool {
    let rgb = matches!(channels, [r, g, b] | [r, g, b, _] if [r, g, b] == ["R", "G", "B"]);
    kind == LayerKind::Light && rgb && name != LAYER && !name.starts_with(PREFIX)
}

/// The denoised beauty of `film` guided by its `albedo` and `N` layers
/// among `layers`: the image (for the preview), its layer, and with
/// `opts.layers` each light layer denoised ([`layer_name`]), in their
/// order.
pub fn denoise_layers(
    film: &Film,
    layers: &[Layer],
    opts: &DenoiseOptions,
) -> Result<(Film, Vec<Layer>), Error> {
    let guide = |(name, _): (&str, [&str; 3])| -> Result<Vec<Vec3>, Error> {
        let l = layers
            .iter()
            .find(|l| l.name == name && l.channels.len() == 3)
            .ok_or_else(|| {
                Error::Input(format!(
                    "cannot denoise: the frame has no {name} pass (a guide OIDN needs)"
                ))
            })?;
        Ok(pixels_of(l))
    };
    let (albedo, normal) = (guide(GUIDES[0])?, guide(GUIDES[1])?);
    let input = DenoiseInput {
        width: film.width,
        height: film.height,
        color: &film.pixels,
        albedo: &albedo,
        normal: &normal,
    };
    let light: Vec<&Layer> = layers
        .iter()
        .filter(|l| opts.layers && is_denoisable(&l.name, l.kind, &l.channels))
        .collect();
    let images: Vec<Vec<Vec3>> = light.iter().map(|l| pixels_of(l)).collect();
    let more: Vec<&[Vec3]> = images.iter().map(Vec::as_slice).collect();
    let mut outs = denoise_with(&input, &more, opts)?.into_iter();
    let pixels = outs.next().expect("the beauty comes first");
    let mut out = vec![layer_of(&pixels)];
    for (l, p) in light.iter().zip(outs) {
        out.push(named_layer(layer_name(&l.name), &p));
    }
    let film = Film {
        width: film.width,
        height: film.height,
        pixels,
    };
    Ok((film, out))
}

/// A layer's first three channels (R G B) as pixels.
fn pixels_of(l: &Layer) -> Vec<Vec3> {
    l.values
        .chunks_exact(l.channels.len())
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect()
}

/// The denoised pixels as the layer [`LAYER`].
pub fn layer_of(pixels: &[Vec3]) -> Layer {
    named_layer(LAYER.into(), pixels)
}

/// Denoised pixels as the light layer `name`.
pub fn named_layer(name: String, pixels: &[Vec3]) -> Layer {
    Layer {
        name,
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
    fn light_layers_are_rgb_radiance_and_not_already_denoised() {
        let ch = |c: &[&str]| c.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let (rgb, rgba) = (ch(&["R", "G", "B"]), ch(&["R", "G", "B", "A"]));
        assert!(is_denoisable("diffuse_direct", LayerKind::Light, &rgb));
        assert!(is_denoisable("RGBA_key", LayerKind::Light, &rgba));
        assert!(!is_denoisable("albedo", LayerKind::Data, &rgb));
        assert!(!is_denoisable("N", LayerKind::Data, &ch(&["X", "Y", "Z"])));
        assert!(!is_denoisable(LAYER, LayerKind::Light, &rgb));
        assert!(!is_denoisable("denoised_RGBA_key", LayerKind::Light, &rgb));
        assert_eq!(layer_name("RGBA_key"), "denoised_RGBA_key");
        assert!(!layer_name("RGBA_key").starts_with("RGBA_"));
    }

    #[test]
    fn the_guides_are_the_albedo_and_normal_passes() {
        assert_eq!(GUIDES[0].0, Pass::Albedo.name());
        assert_eq!(GUIDES[1].0, Pass::Normal.name());
    }
}
