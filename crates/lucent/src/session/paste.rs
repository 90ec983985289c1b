//! Pasting a region render into a frame (`lucent paste`, docs/output.md,
//! "Region renders"): the region file's samples replace the frame's in its
//! data window, channel by channel, bit for bit; every other pixel, the
//! frame's header and its storage (compression, blocks) stay. The two
//! files must agree on the display window and on the channels (names and
//! sample types), and the region must lie inside the frame's data window;
//! anything else is bad input naming the file and what differs. Both are
//! read as untrusted files: regular files only, one flat layer, sized
//! from a header whose pixel count the file's bytes could hold.

use std::io::{BufReader, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use exr::meta::attribute::{AttributeValue, Text};
use exr::meta::MetaData;
use exr::prelude::{FlatSamples, IntegerBounds, ReadChannels, ReadLayers};

use super::output::{check_exr_output, check_not_an_input};
use crate::error::{Error, InputError};
use crate::film::exr_layers::{stage_image, AnyImage, Preview};
use crate::film::{commit_all, preview_path, Film};
use crate::geometry::Vec3;
use crate::scene::regular_file::open_regular;

/// The most bytes of pixels one byte of a file can hold (deflate's
/// largest ratio, 1032:1, with room for the other lossless codecs):
/// a header claiming more is truncated or forged.
const MAX_RATIO: u128 = 2048;

/// The header attribute listing what was pasted into a frame.
pub const PASTED: &str = "lucent/pasted";

/// What a paste did: the region's pixels and how many channels.
#[derive(Clone, Debug)]
pub struct Pasted {
    pub region: IntegerBounds,
    pub channels: usize,
}

impl Pasted {
    /// One line: where the frame went and what changed.
    pub fn summary(&self, output: &Path) -> String {
        let (p, s) = (self.region.position, self.region.size);
        format!(
            "{}: pasted {}×{} pixels at ({}, {}), {} channels",
            output.display(),
            s.0,
            s.1,
            p.0,
            p.1,
            self.channels
        )
    }
}

/// Pastes the region render `region` into `frame`, writing `output` and
/// its PNG preview (from `R`, `G`, `B`, when the file has them).
pub fn paste(
    region: &Path,
    frame: &Path,
    output: &Path,
    preview: Preview,
) -> Result<Pasted, Error> {
    check_exr_output(output)?;
    let png = preview_path(output);
    let inputs = [region.to_path_buf(), frame.to_path_buf()];
    check_not_an_input(&[output, &png], &inputs)?;
    let part = read(region)?;
    let mut image = read(frame)?;
    let bounds = check_match(region, &part, frame, &image)?;
    splice(&part, &mut image);
    note(&mut image, bounds, region);
    let mut staged = vec![stage_image(output, &image)?];
    if let Some(film) = beauty(&image) {
        staged.push(film.stage_png(&png, preview.tonemap, preview.exposure)?);
    }
    commit_all(staged)?;
    Ok(Pasted {
        region: bounds,
        channels: image.layer_data.channel_data.list.len(),
    })
}

/// Bad input in `path`, optionally in one field.
fn bad(path: &Path, field: Option<&str>, problem: impl Into<String>) -> Error {
    let e = InputError::new(path, problem);
    match field {
        Some(f) => e.in_field(f).into(),
        None => e.into(),
    }
}

/// Reads the single-layer flat EXR at `path`, checked as untrusted input
/// before its pixels are sized.
pub(crate) fn read(path: &Path) -> Result<AnyImage, Error> {
    let (mut file, len) =
        open_regular(path).map_err(|e| bad(path, None, format!("cannot read it: {e}")))?;
    let meta = MetaData::read_from_buffered(BufReader::new(&file), true)
        .map_err(|e| bad(path, None, format!("not a readable OpenEXR file: {e}")))?;
    let [h] = &meta.headers[..] else {
        return Err(bad(
            path,
            None,
            "more than one EXR part (a single-part file is needed)",
        ));
    };
    if h.deep {
        return Err(bad(path, None, "deep EXR data: only flat images paste"));
    }
    if let Some(c) = h
        .channels
        .list
        .iter()
        .find(|c| c.sampling.0 != 1 || c.sampling.1 != 1)
    {
        return Err(bad(
            path,
            Some("channels"),
            format!("channel {} is subsampled", c.name),
        ));
    }
    let bytes: u128 = h
        .channels
        .list
        .iter()
        .map(|c| c.sample_type.bytes_per_sample() as u128)
        .sum();
    let raw = h.layer_size.area() as u128 * bytes;
    if raw > len as u128 * MAX_RATIO {
        return Err(bad(path, None, format!(
            "{len} bytes cannot hold the {raw} bytes of pixels its header claims: truncated or forged"
        )));
    }
    file.seek(SeekFrom::Start(0))
        .map_err(|e| bad(path, None, format!("cannot read it again: {e}")))?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(BufReader::new(file))
        .map_err(|e| bad(path, None, format!("cannot read its pixels: {e}")))?;
    Ok(image)
}

/// The region's data window, once the two files are checked to agree:
/// the same display window, the same channels, and the region inside the
/// frame's pixels.
fn check_match(
    region_path: &Path,
    region: &AnyImage,
    frame_path: &Path,
    frame: &AnyImage,
) -> Result<IntegerBounds, Error> {
    let window = |i: &AnyImage| i.attributes.display_window;
    let (dr, df) = (window(region), window(frame));
    if dr != df {
        return Err(bad(
            region_path,
            Some("displayWindow"),
            format!(
                "{} but the frame {} has {}",
                show(dr),
                frame_path.display(),
                show(df)
            ),
        ));
    }
    let channels = |i: &AnyImage| -> Vec<String> {
        let list = &i.layer_data.channel_data.list;
        list.iter()
            .map(|c| format!("{} ({})", c.name, kind(&c.sample_data)))
            .collect()
    };
    let (cr, cf) = (channels(region), channels(frame));
    if cr != cf {
        let missing: Vec<&String> = cf.iter().filter(|c| !cr.contains(c)).collect();
        let extra: Vec<&String> = cr.iter().filter(|c| !cf.contains(c)).collect();
        return Err(bad(region_path, Some("channels"), format!(
            "differ from the frame {}'s: the frame's not here {missing:?}, here but not in the frame {extra:?}",
            frame_path.display()
        )));
    }
    let data = |i: &AnyImage| i.layer_data.absolute_bounds();
    let (r, f) = (data(region), data(frame));
    let inside = r.position.0 >= f.position.0
        && r.position.1 >= f.position.1
        && r.end().0 <= f.end().0
        && r.end().1 <= f.end().1;
    if !inside {
        return Err(bad(
            region_path,
            Some("dataWindow"),
            format!(
                "{} is not inside the frame {}'s pixels {}",
                show(r),
                frame_path.display(),
                show(f)
            ),
        ));
    }
    Ok(r)
}

/// A window as `W×H at (X, Y)`.
fn show(b: IntegerBounds) -> String {
    format!(
        "{}×{} at ({}, {})",
        b.size.0, b.size.1, b.position.0, b.position.1
    )
}

/// A sample type's name.
fn kind(s: &FlatSamples) -> &'static str {
    match s {
        FlatSamples::F16(_) => "half",
        FlatSamples::F32(_) => "float",
        FlatSamples::U32(_) => "uint",
    }
}

/// Copies every channel of `region` into `frame` at the region's pixels
/// (the channel lists are equal, so they pair up in order).
fn splice(region: &AnyImage, frame: &mut AnyImage) {
    let r = region.layer_data.absolute_bounds();
    let f = frame.layer_data.absolute_bounds();
    let (rw, fw) = (r.size.0, f.size.0);
    let dx = (r.position.0 - f.position.0) as usize;
    let dy = (r.position.1 - f.position.1) as usize;
    let src = &region.layer_data.channel_data.list;
    let dst = &mut frame.layer_data.channel_data.list;
    for (s, d) in src.iter().zip(dst.iter_mut()) {
        for row in 0..r.size.1 {
            let from = row * rw..(row + 1) * rw;
            let to = (dy + row) * fw + dx;
            match (&s.sample_data, &mut d.sample_data) {
                (FlatSamples::F16(a), FlatSamples::F16(b)) => {
                    b[to..to + rw].copy_from_slice(&a[from])
                }
                (FlatSamples::F32(a), FlatSamples::F32(b)) => {
                    b[to..to + rw].copy_from_slice(&a[from])
                }
                (FlatSamples::U32(a), FlatSamples::U32(b)) => {
                    b[to..to + rw].copy_from_slice(&a[from])
                }
                _ => unreachable!("channel types were checked equal"),
            }
        }
    }
}

/// Adds the pasted region and its file to the frame's [`PASTED`]
/// attribute (`X0,Y0,X1,Y1 from NAME`, `; `-separated, oldest first).
fn note(frame: &mut AnyImage, r: IntegerBounds, from: &Path) {
    let other = &mut frame.layer_data.attributes.other;
    let key = Text::from_slice_unchecked(PASTED.as_bytes());
    let name = from.file_name().map(PathBuf::from).unwrap_or_default();
    let entry = format!(
        "{},{},{},{} from {}",
        r.position.0,
        r.position.1,
        r.end().0,
        r.end().1,
        name.display()
    );
    let text = match other.get(&key) {
        Some(AttributeValue::Text(t)) => format!("{}; {entry}", String::from_utf8_lossy(t.bytes())),
        _ => entry,
    };
    other.insert(
        key,
        AttributeValue::Text(Text::from_slice_unchecked(text.as_bytes())),
    );
}

/// The beauty (`R`, `G`, `B`) of the frame's pixels, for the preview.
fn beauty(image: &AnyImage) -> Option<Film> {
    let list = &image.layer_data.channel_data.list;
    let get = |n: &str| list.iter().find(|c| c.name == *n).map(|c| &c.sample_data);
    let (r, g, b) = (get("R")?, get("G")?, get("B")?);
    let size = image.layer_data.size;
    let mut film = Film::try_new(size.0 as u32, size.1 as u32).ok()?;
    for (i, p) in film.pixels.iter_mut().enumerate() {
        *p = Vec3::new(
            r.value_by_flat_index(i).to_f32(),
            g.value_by_flat_index(i).to_f32(),
            b.value_by_flat_index(i).to_f32(),
        );
    }
    Some(film)
}
