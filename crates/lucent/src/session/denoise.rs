//! Denoised frames as the commands write them (docs/output.md,
//! "Denoising"): `render --denoise` and `merge --denoise` add the layer
//! from the frame's layers in memory ([`stage_denoised`]); `lucent denoise`
//! reads a finished frame back and adds it there ([`denoise_file`]); with
//! `--denoise-layers` each light layer too, as `denoised_<layer>`. Both
//! hand OIDN the same float beauty, layers and guides, so a frame denoised
//! after a merge is the frame denoised by the single render. The PNG preview shows
//! the denoised beauty; every file appears or none does.

use std::path::Path;
use std::time::Instant;

use exr::meta::attribute::Text;
use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, SmallVec};

use super::output::{check_exr_output, check_not_an_input};
use crate::denoise::filter::denoise_with;
use crate::denoise::frame::{denoise_layers, layer_name, layer_of, named_layer, GUIDES, LAYER};
use crate::denoise::{DenoiseInput, DenoiseOptions};
use crate::error::{Error, InputError};
use crate::film::exr_attributes::FrameHeader;
use crate::film::exr_layers::{stage_frame, stage_image, AnyImage, OutputOptions, Preview, Window};
use crate::film::layers::{Coverage, Layer};
use crate::film::passes::LIGHT_PATHS;
use crate::film::{commit_all, preview_path, Film, Staged};
use crate::geometry::Vec3;

/// The frame of [`stage_frame`] with the denoised beauty added as
/// [`LAYER`] and shown by the preview (`out.preview`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn stage_denoised(
    path: &Path,
    window: Window,
    film: &Film,
    layers: &[Layer],
    coverage: &[Coverage],
    header: &FrameHeader,
    out: &OutputOptions,
    opts: &DenoiseOptions,
) -> Result<Vec<Staged>, Error> {
    let (clean, denoised) = denoise_layers(film, layers, opts)?;
    let mut all = layers.to_vec();
    all.extend(denoised);
    let frame_only = OutputOptions {
        preview: None,
        ..*out
    };
    let mut staged = stage_frame(path, window, film, &all, coverage, header, &frame_only)?;
    if let Some(p) = out.preview {
        staged.push(clean.stage_png(&preview_path(path), p.tonemap, p.exposure)?);
    }
    Ok(staged)
}

/// What `lucent denoise` did.
#[derive(Clone, Debug)]
pub struct Denoised {
    pub width: usize,
    pub height: usize,
    /// The denoise alone (OIDN's device, filters and run).
    pub seconds: f64,
}

impl Denoised {
    /// One line: where the frame went, its size and the denoise's time.
    pub fn summary(&self, output: &Path) -> String {
        format!(
            "{}: denoised {}×{} in {:.2} s (layer {LAYER})",
            output.display(),
            self.width,
            self.height,
            self.seconds
        )
    }
}

/// Denoises the finished frame `input` from its own beauty and guides,
/// writing it with the layer [`LAYER`] added (or replaced) to `output`
/// (which may be `input`: replaced atomically) and the denoised preview.
pub fn denoise_file(
    input: &Path,
    output: &Path,
    preview: Preview,
    opts: &DenoiseOptions,
) -> Result<Denoised, Error> {
    check_exr_output(output)?;
    let png = preview_path(output);
    check_not_an_input(&[&png], &[input.to_path_buf()])?;
    crate::denoise::load::api()?;
    let mut image = super::paste::read(input)?;
    let (w, h) = (image.layer_data.size.0, image.layer_data.size.1);
    let color = planes(input, &image, ["R", "G", "B"])?;
    let guide =
        |(layer, ch): (&str, [&str; 3])| planes(input, &image, ch.map(|c| format!("{layer}.{c}")));
    let (albedo, normal) = (guide(GUIDES[0])?, guide(GUIDES[1])?);
    let light = if opts.layers {
        light_layers(&image)
    } else {
        Vec::new()
    };
    let images = light
        .iter()
        .map(|l| planes(input, &image, ["R", "G", "B"].map(|c| format!("{l}.{c}"))))
        .collect::<Result<Vec<_>, _>>()?;
    let more: Vec<&[Vec3]> = images.iter().map(Vec::as_slice).collect();
    let start = Instant::now();
    let mut outs = denoise_with(
        &DenoiseInput {
            width: w as u32,
            height: h as u32,
            color: &color,
            albedo: &albedo,
            normal: &normal,
        },
        &more,
        opts,
    )?
    .into_iter();
    let seconds = start.elapsed().as_secs_f64();
    let clean = outs.next().expect("the beauty comes first");
    put_layer(&mut image, &layer_of(&clean));
    for (l, p) in light.iter().zip(outs) {
        put_layer(&mut image, &named_layer(layer_name(l), &p));
    }
    let film = Film {
        width: w as u32,
        height: h as u32,
        pixels: clean,
    };
    commit_all(vec![
        stage_image(output, &image)?,
        film.stage_png(&png, preview.tonemap, preview.exposure)?,
    ])?;
    Ok(Denoised {
        width: w,
        height: h,
        seconds,
    })
}

/// The three channels `names` of `image` as pixels: bad input naming the
/// file and channel when one is missing or not finite.
fn planes<S: AsRef<str>>(path: &Path, image: &AnyImage, names: [S; 3]) -> Result<Vec<Vec3>, Error> {
    let list = &image.layer_data.channel_data.list;
    let width = image.layer_data.size.0;
    let mut chans = Vec::with_capacity(3);
    for n in &names {
        let n = n.as_ref();
        let c = list.iter().find(|c| c.name == *n).ok_or_else(|| {
            bad(
                path,
                "channels",
                format!(
                "no {n} channel: denoising needs the beauty (R, G, B) and the albedo and N passes \
                 (render with --denoise, or --aov albedo,N)"
            ),
            )
        })?;
        chans.push((n, &c.sample_data));
    }
    let mut out = vec![Vec3::ZERO; image.layer_data.size.area()];
    for (i, p) in out.iter_mut().enumerate() {
        let mut v = [0.0; 3];
        for (k, (n, s)) in chans.iter().enumerate() {
            v[k] = s.value_by_flat_index(i).to_f32();
            if !v[k].is_finite() {
                let (x, y) = (i % width, i / width);
                return Err(bad(
                    path,
                    n,
                    format!("not finite at pixel ({x}, {y}): {}", v[k]),
                ));
            }
        }
        *p = Vec3::from(v);
    }
    Ok(out)
}

/// The frame's light layers with `R`, `G`, `B` channels, in name order:
/// the light paths and the light groups (`RGBA_<group>`), the layers a
/// render's `--denoise-layers` denoises.
fn light_layers(image: &AnyImage) -> Vec<String> {
    let names: Vec<String> = image
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let mut out: Vec<String> = names
        .iter()
        .filter_map(|n| n.strip_suffix(".R"))
        .filter(|l| LIGHT_PATHS.iter().any(|p| p.name() == *l) || l.starts_with("RGBA_"))
        .filter(|l| {
            ["G", "B"]
                .iter()
                .all(|c| names.contains(&format!("{l}.{c}")))
        })
        .map(String::from)
        .collect();
    out.sort();
    out
}

/// Bad input in `path`, in `field`.
fn bad(path: &Path, field: &str, problem: String) -> Error {
    InputError::new(path, problem).in_field(field).into()
}

/// `layer`'s channels in `image` (float), replacing any of the same names.
fn put_layer(image: &mut AnyImage, layer: &Layer) {
    let prefix = format!("{}.", layer.name);
    let old = std::mem::take(&mut image.layer_data.channel_data.list);
    let mut list: Vec<AnyChannel<FlatSamples>> = old
        .into_iter()
        .filter(|c| !c.name.to_string().starts_with(&prefix))
        .collect();
    for (k, ch) in layer.channels.iter().enumerate() {
        let values = layer.values.iter().skip(k).step_by(3).copied().collect();
        let name = format!("{prefix}{ch}");
        list.push(AnyChannel::new(
            Text::from_slice_unchecked(name.as_bytes()),
            FlatSamples::F32(values),
        ));
    }
    image.layer_data.channel_data = AnyChannels::sort(SmallVec::from_vec(list));
}
