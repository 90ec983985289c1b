//! The multi-layer OpenEXR of a frame: beauty in the plain `R`, `G`, `B`,
//! `A` channels (what every viewer shows), every pass as `layer.channel`
//! (`diffuse_direct.R`, `depth.Z`), Cryptomatte layers as the standard lays
//! them out (`CryptoObject00.R` …, [`super::cryptomatte`]), and the header
//! attributes of [`FrameHeader`] — in one file, or one file per pass
//! ([`OutputOptions::split`]). [`write_frame`] is the one entry point; the
//! channel naming, precision, compression and split naming are documented
//! in `docs/output.md` ("The EXR file").
//!
//! - **Precision:** beauty is always 32-bit float (the file a render
//!   without passes writes is pixel for pixel what lucent always wrote);
//!   [`LayerKind::Light`] passes are float or half ([`Precision`]), half
//!   rounding to nearest (relative error ≤ 2^-11; values above 65504
//!   become +inf, as OpenEXR's own conversion does); [`LayerKind::Data`]
//!   and [`LayerKind::Id`] passes and Cryptomatte are always float (half
//!   would destroy depths, positions and IDs).
//! - **Compression:** lossless only ([`ExrCompression`]; default ZIP over
//!   16 scan lines, what lucent always wrote): Cryptomatte IDs and data
//!   passes must come back bit for bit, which rules out PXR24, B44 and DWA.
//! - **Deterministic bytes:** blocks are compressed and written
//!   sequentially in increasing line order (the exr crate's parallel
//!   writer emits them in the order they finish), and the header's
//!   attributes are sorted by name in the written file (the exr crate writes
//!   them in hash-map order, different in every process; OpenEXR itself
//!   keeps them sorted). Sorting keeps the header's length, so the offset
//!   table stays valid. Same inputs → the same bytes, except that the
//!   render time is one of the inputs.
//! - **Windows:** the display window is the whole frame; the data window
//!   is the pixels the file holds ([`Window`]): the frame, or the region of
//!   a region render (`--region`), a normal EXR every viewer places.
//! - **Atomic:** every file (and the PNG preview) is written to a temporary
//!   file and all are committed together ([`super::commit_all`]): all
//!   appear, or none does.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{
    f16, AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, IntegerBounds,
    LayerAttributes, LineOrder, SmallVec, Vec2, WritableImage,
};

mod read;
pub use read::{read_attributes, text_attribute};

use super::cryptomatte::{self, DEFAULT_RANKS};
use super::exr_attributes::text;
pub use super::exr_attributes::FrameHeader;
use super::layers::{Coverage, Layer, LayerKind};
use super::region::Region;
use super::{commit_all, preview_path, Film, Staged, ToneMap};
use crate::error::Error;

/// How [`LayerKind::Light`] passes are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// 16-bit half floats: half the size, 3 decimal digits.
    Half,
    /// 32-bit floats (default): light passes add up to beauty exactly as
    /// rendered.
    #[default]
    Float,
}

impl Precision {
    /// "half" or "float".
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "half" => Some(Precision::Half),
            "float" => Some(Precision::Float),
            _ => None,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Precision::Half => "half",
            Precision::Float => "float",
        }
    }
}

/// The lossless OpenEXR compressions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ExrCompression {
    None,
    /// Run-length: fast, little gain on rendered noise.
    Rle,
    /// zlib over single scan lines.
    Zips,
    /// zlib over 16 scan lines (default): what lucent always wrote, read
    /// by every tool, a good ratio on renders.
    #[default]
    Zip,
    /// Wavelet + Huffman over 32 scan lines: often smaller on noisy
    /// images, slower.
    Piz,
}

impl ExrCompression {
    pub(crate) const NAMES: &'static str = "none, rle, zips, zip or piz";

    /// "none", "rle", "zips", "zip" or "piz".
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "none" => ExrCompression::None,
            "rle" => ExrCompression::Rle,
            "zips" => ExrCompression::Zips,
            "zip" => ExrCompression::Zip,
            "piz" => ExrCompression::Piz,
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            ExrCompression::None => "none",
            ExrCompression::Rle => "rle",
            ExrCompression::Zips => "zips",
            ExrCompression::Zip => "zip",
            ExrCompression::Piz => "piz",
        }
    }
    fn exr(self) -> Compression {
        match self {
            ExrCompression::None => Compression::Uncompressed,
            ExrCompression::Rle => Compression::RLE,
            ExrCompression::Zips => Compression::ZIP1,
            ExrCompression::Zip => Compression::ZIP16,
            ExrCompression::Piz => Compression::PIZ,
        }
    }
}

/// The PNG preview written beside the EXR (beauty only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preview {
    pub tonemap: ToneMap,
    /// Stops.
    pub exposure: f32,
}

/// How a frame is stored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutputOptions {
    pub precision: Precision,
    pub compression: ExrCompression,
    /// One file per pass ([`split_path`]) instead of one multi-layer file.
    pub split: bool,
    /// Cryptomatte ranks per pixel (1 to [`cryptomatte::MAX_RANKS`]).
    pub cryptomatte_ranks: usize,
    /// The PNG preview beside the EXR, if any.
    pub preview: Option<Preview>,
    /// A transparent film: the environment seen directly is left out of
    /// the beauty and `A` is the camera rays' coverage.
    pub transparent: bool,
}

impl Default for OutputOptions {
    fn default() -> Self {
        OutputOptions {
            precision: Precision::Float,
            compression: ExrCompression::Zip,
            split: false,
            cryptomatte_ranks: DEFAULT_RANKS,
            preview: None,
            transparent: false,
        }
    }
}

/// Where pass `pass` goes with [`OutputOptions::split`]: `out.exr` →
/// `out.PASS.exr` (beside it, the same stem). Beauty stays in `out.exr`.
pub fn split_path(path: &Path, pass: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!("{stem}.{pass}.exr"))
}

/// Where a file's pixels sit in the frame: the display window is the
/// whole `frame` (width, height) from (0, 0); the data window, the pixels
/// the file holds, is `data` (the frame itself, or a region).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    pub frame: (u32, u32),
    pub data: Region,
}

impl Window {
    /// The whole `width`×`height` frame.
    pub fn full(width: u32, height: u32) -> Window {
        Window {
            frame: (width, height),
            data: Region::full(width, height),
        }
    }
}

/// Writes the frame: beauty from `film`, the passes `layers` and the
/// Cryptomatte of each `coverage`, with `header`'s attributes, as `opts`
/// says, plus the PNG preview; every file appears or none does.
pub fn write_frame(
    path: &Path,
    film: &Film,
    layers: &[Layer],
    coverage: &[Coverage],
    header: &FrameHeader,
    opts: &OutputOptions,
) -> Result<(), Error> {
    let window = Window::full(film.width, film.height);
    write_window(path, window, film, layers, coverage, header, opts)
}

/// [`write_frame`] for the pixels of `window.data` (`film`, the layers and
/// the coverage are that region's) placed in the frame `window.frame`.
pub fn write_window(
    path: &Path,
    window: Window,
    film: &Film,
    layers: &[Layer],
    coverage: &[Coverage],
    header: &FrameHeader,
    opts: &OutputOptions,
) -> Result<(), Error> {
    commit_all(stage_frame(
        path, window, film, layers, coverage, header, opts,
    )?)
}

/// [`write_window`] to temporary files only, for [`commit_all`] (with
/// other outputs of the same command).
pub(crate) fn stage_frame(
    path: &Path,
    window: Window,
    film: &Film,
    layers: &[Layer],
    coverage: &[Coverage],
    header: &FrameHeader,
    opts: &OutputOptions,
) -> Result<Vec<Staged>, Error> {
    let pixels = film.pixels.len();
    let d = window.data;
    if (d.width(), d.height()) != (film.width, film.height)
        || !d.within(&Region::full(window.frame.0, window.frame.1))
    {
        return Err(Error::Runtime(format!(
            "cannot write a {}×{} image as the pixels {d} of a {}×{} frame",
            film.width, film.height, window.frame.0, window.frame.1
        )));
    }
    check_layers(layers, coverage, pixels)?;
    let attributes = header.attributes(window.frame.0, window.frame.1);
    // a transparent film's alpha replaces the opaque A, beside R, G, B
    let alpha = layers.iter().find(|l| l.name == "A");
    let mut beauty = beauty_planes(film, alpha.is_none())?;
    beauty.extend(
        alpha
            .map(|a| layer_planes(a, Precision::Float))
            .unwrap_or_default(),
    );
    let mut files: Vec<File> = vec![File {
        path: path.to_path_buf(),
        planes: beauty,
        attributes: attributes.clone(),
    }];
    let mut add = |name: &str, planes: Vec<Plane>, extra: Vec<(String, AttributeValue)>| {
        if opts.split {
            let mut a = attributes.clone();
            a.push(("lucent/pass".into(), AttributeValue::Text(text(name))));
            a.extend(extra);
            files.push(File {
                path: split_path(path, name),
                planes,
                attributes: a,
            });
        } else {
            files[0].planes.extend(planes);
            files[0].attributes.extend(extra);
        }
    };
    for layer in layers {
        if layer.name == "A" {
            continue;
        }
        add(&layer.name, layer_planes(layer, opts.precision), Vec::new());
    }
    for cov in coverage {
        let e = cryptomatte::encode(cov, pixels, opts.cryptomatte_ranks)?;
        let planes = e
            .channels
            .into_iter()
            .map(|(name, v)| Plane {
                name,
                samples: FlatSamples::F32(v),
            })
            .collect();
        let extra = e
            .attributes
            .into_iter()
            .map(|(n, v)| (n, AttributeValue::Text(text(&v))))
            .collect();
        add(&e.name, planes, extra);
    }
    let mut staged = Vec::with_capacity(files.len() + 1);
    for f in files {
        staged.push(f.stage(window, opts.compression)?);
    }
    if let Some(p) = opts.preview {
        staged.push(film.stage_png(&preview_path(path), p.tonemap, p.exposure)?);
    }
    Ok(staged)
}

/// One channel's samples, row-major.
struct Plane {
    name: String,
    samples: FlatSamples,
}

/// One EXR file to write.
struct File {
    path: PathBuf,
    planes: Vec<Plane>,
    attributes: Vec<(String, AttributeValue)>,
}

impl File {
    fn stage(self, window: Window, compression: ExrCompression) -> Result<Staged, Error> {
        // the standard attributes the exr crate keeps in fields of their own
        let d = window.data;
        let mut attributes = LayerAttributes {
            layer_position: Vec2(d.x0 as i32, d.y0 as i32),
            ..LayerAttributes::default()
        };
        for (name, value) in self.attributes {
            match (name.as_str(), value) {
                ("software", AttributeValue::Text(t)) => attributes.software_name = Some(t),
                ("capDate", AttributeValue::Text(t)) => attributes.capture_date = Some(t),
                ("utcOffset", AttributeValue::F32(f)) => attributes.utc_offset = Some(f),
                ("worldToCamera", AttributeValue::Matrix4x4(m)) => {
                    attributes.world_to_camera = Some(m)
                }
                ("worldToNDC", AttributeValue::Matrix4x4(m)) => {
                    attributes.world_to_normalized_device = Some(m)
                }
                (_, value) => {
                    attributes.other.insert(text(&name), value);
                }
            }
        }
        let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = self
            .planes
            .into_iter()
            .map(|p| AnyChannel::new(Text::from_slice_unchecked(p.name.as_bytes()), p.samples))
            .collect();
        let encoding = Encoding {
            compression: compression.exr(),
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let layer = exr::image::Layer::new(
            (d.width() as usize, d.height() as usize),
            attributes,
            encoding,
            AnyChannels::sort(channels),
        );
        let mut image = Image::from_layer(layer);
        let (w, h) = (window.frame.0 as usize, window.frame.1 as usize);
        image.attributes.display_window = IntegerBounds::new((0, 0), (w, h));
        stage_image(&self.path, &image)
    }
}

/// A flat single-layer EXR image with any channels, as the exr crate holds it.
pub type AnyImage = Image<exr::image::Layer<AnyChannels<FlatSamples>>>;

/// Stages `image` at `path` with deterministic bytes: blocks compressed
/// and written in order, the header's attributes sorted by name.
pub(crate) fn stage_image(path: &Path, image: &AnyImage) -> Result<Staged, Error> {
    Staged::write(path, |tmp| {
        image.write().non_parallel().to_unbuffered(&mut *tmp)?;
        sort_header_in_file(tmp)
    })
}

/// Why the frame's EXR could not be written to its temporary file: the
/// encoder's or the file system's error, or a header the in-place sort
/// cannot read.
#[derive(Debug, thiserror::Error)]
enum FrameWriteError {
    #[error("{0}")]
    Exr(#[from] exr::error::Error),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("malformed EXR header")]
    MalformedHeader,
    #[error("a multi-part EXR header (not written here)")]
    MultiPart,
}

/// [`sort_header_attributes`] on the file at `path`, reading only its
/// header (the first 64 kB, more if the header is longer), so the pixels
/// are never held in memory twice.
fn sort_header_in_file(f: &mut std::fs::File) -> Result<(), FrameWriteError> {
    use std::io::{Read, Seek, SeekFrom, Write};
    let len = f.metadata()?.len() as usize;
    let mut n = len.min(1 << 16);
    loop {
        let mut head = vec![0u8; n];
        f.seek(SeekFrom::Start(0))?;
        f.read_exact(&mut head)?;
        match sort_header_attributes(&mut head) {
            Ok(end) => {
                f.seek(SeekFrom::Start(0))?;
                return Ok(f.write_all(&head[..end])?);
            }
            Err(_) if n < len => n = (2 * n).min(len),
            Err(e) => return Err(e),
        }
    }
}

/// Beauty: `R`, `G`, `B` from the film and, when `opaque`, `A` = 1, 32-bit
/// float (16 bytes a pixel beside the film's 12; failing with a message,
/// not aborting, when that cannot be allocated).
fn beauty_planes(film: &Film, opaque: bool) -> Result<Vec<Plane>, Error> {
    let n = film.pixels.len();
    let plane = |name: &str, f: fn(&crate::geometry::Vec3) -> f32| {
        let mut v = Vec::new();
        v.try_reserve_exact(n)
            .map_err(|_| super::out_of_memory("the EXR's beauty channels", n.saturating_mul(16)))?;
        v.extend(film.pixels.iter().map(f));
        Ok::<_, Error>(Plane {
            name: name.into(),
            samples: FlatSamples::F32(v),
        })
    };
    let mut planes = vec![
        plane("R", |p| p.x)?,
        plane("G", |p| p.y)?,
        plane("B", |p| p.z)?,
    ];
    if opaque {
        planes.push(plane("A", |_| 1.0)?);
    }
    Ok(planes)
}

/// A pass's channels `layer.channel`, half only for light passes at half
/// precision.
fn layer_planes(layer: &Layer, precision: Precision) -> Vec<Plane> {
    let n = layer.channels.len();
    let half = layer.kind == LayerKind::Light && precision == Precision::Half;
    layer
        .channels
        .iter()
        .enumerate()
        .map(|(c, ch)| {
            let values = layer.values.iter().skip(c).step_by(n).copied();
            Plane {
                name: channel_name(layer, ch),
                samples: if half {
                    FlatSamples::F16(values.map(f16::from_f32).collect())
                } else {
                    FlatSamples::F32(values.collect())
                },
            }
        })
        .collect()
}

/// The EXR channel of `layer`'s channel `ch`: `layer.ch`, or the bare
/// name for a layer of one channel of its own name (depth: `Z`, what
/// compositors read as depth).
fn channel_name(layer: &Layer, ch: &str) -> String {
    if layer.channels.len() == 1 && layer.name == ch {
        ch.to_string()
    } else {
        format!("{}.{ch}", layer.name)
    }
}

/// Layer and channel names that make well-formed, distinct channels, and
/// value counts that match the image (the integrator's side of the
/// boundary; a mismatch is a bug there, reported rather than written).
fn check_layers(layers: &[Layer], coverage: &[Coverage], pixels: usize) -> Result<(), Error> {
    let bad = |what: String| Err(Error::Runtime(format!("cannot write pass {what}")));
    let ok_name = |s: &str| !s.is_empty() && !s.contains('.') && !s.chars().any(char::is_control);
    let mut names = HashSet::new();
    let crypto: Vec<String> = coverage
        .iter()
        .map(|c| cryptomatte::layer_name(&c.kind))
        .collect();
    for l in layers {
        // `A` only as the one-channel alpha of a transparent film
        let alpha = l.name == "A" && l.channels == ["A"];
        if !ok_name(&l.name) || (["R", "G", "B", "A"].contains(&l.name.as_str()) && !alpha) {
            return bad(format!("\"{}\": not a layer name", l.name));
        }
        if l.channels.is_empty() || !l.channels.iter().all(|c| ok_name(c)) {
            return bad(format!("{}: channels {:?}", l.name, l.channels));
        }
        if l.channels.iter().collect::<HashSet<_>>().len() != l.channels.len() {
            return bad(format!("{}: repeated channel in {:?}", l.name, l.channels));
        }
        if l.values.len() != pixels * l.channels.len() {
            return bad(format!(
                "{}: {} values for {pixels} pixels of {} channels",
                l.name,
                l.values.len(),
                l.channels.len()
            ));
        }
        if !names.insert(l.name.as_str()) {
            return bad(format!("{}: two layers of that name", l.name));
        }
    }
    for c in &crypto {
        let clash = names
            .iter()
            .any(|n| n.starts_with(c.as_str()) && n[c.len()..].chars().all(|x| x.is_ascii_digit()));
        if !names.insert(c) || clash {
            return bad(format!("{c}: two layers of that name"));
        }
    }
    Ok(())
}

/// Sorts the attributes of a single-part OpenEXR file's header by name, in
/// place. Each attribute is `name\0 type\0 size:i32 value[size]`, the list
/// ends with an empty name; the header's length, hence the offset table
/// after it, is unchanged. Returns where the attribute list ends (the
/// bytes before it are all this changes); fails on a list cut short.
fn sort_header_attributes(bytes: &mut [u8]) -> Result<usize, FrameWriteError> {
    let malformed = || FrameWriteError::MalformedHeader;
    if bytes.len() < 8 || bytes[..4] != [0x76, 0x2f, 0x31, 0x01] {
        return Err(malformed());
    }
    if bytes[5] & 0x10 != 0 {
        return Err(FrameWriteError::MultiPart);
    }
    let cstr_end = |from: usize| -> Result<usize, FrameWriteError> {
        bytes[from..]
            .iter()
            .position(|&b| b == 0)
            .map(|i| from + i)
            .ok_or_else(malformed)
    };
    let mut records: Vec<(usize, usize, usize)> = Vec::new(); // (start, name end, end)
    let mut at = 8;
    loop {
        let name_end = cstr_end(at)?;
        if name_end == at {
            break;
        }
        let type_end = cstr_end(name_end + 1)?;
        let size_at = type_end + 1;
        let size = bytes
            .get(size_at..size_at + 4)
            .map(|s| i32::from_le_bytes([s[0], s[1], s[2], s[3]]))
            .ok_or_else(malformed)?;
        let end = usize::try_from(size)
            .ok()
            .map(|s| size_at + 4 + s)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(malformed)?;
        records.push((at, name_end, end));
        at = end;
    }
    let mut order = records.clone();
    order.sort_by(|a, b| bytes[a.0..a.1].cmp(&bytes[b.0..b.1]));
    let mut sorted = Vec::with_capacity(at - 8);
    for &(start, _, end) in &order {
        sorted.extend_from_slice(&bytes[start..end]);
    }
    bytes[8..at].copy_from_slice(&sorted);
    Ok(at)
}

#[cfg(test)]
mod tests;
