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
//! - **Atomic:** every file (and the PNG preview) is written to a temporary
//!   file and all are committed together ([`super::commit_all`]): all
//!   appear, or none does.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{
    f16, AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image,
    LayerAttributes, LineOrder, SmallVec, WritableImage,
};

use super::cryptomatte::{self, DEFAULT_RANKS};
use super::exr_attributes::text;
pub use super::exr_attributes::FrameHeader;
use super::layers::{Coverage, Layer, LayerKind};
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
}

impl Default for OutputOptions {
    fn default() -> Self {
        OutputOptions {
            precision: Precision::Float,
            compression: ExrCompression::Zip,
            split: false,
            cryptomatte_ranks: DEFAULT_RANKS,
            preview: None,
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
    commit_all(stage_frame(path, film, layers, coverage, header, opts)?)
}

/// [`write_frame`] to temporary files only, for [`commit_all`] (with other
/// outputs of the same command).
pub(crate) fn stage_frame(
    path: &Path,
    film: &Film,
    layers: &[Layer],
    coverage: &[Coverage],
    header: &FrameHeader,
    opts: &OutputOptions,
) -> Result<Vec<Staged>, Error> {
    let pixels = film.pixels.len();
    check_layers(layers, coverage, pixels)?;
    let attributes = header.attributes(film.width, film.height);
    let mut files: Vec<File> = vec![File {
        path: path.to_path_buf(),
        planes: beauty_planes(film)?,
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
        staged.push(f.stage(film.width, film.height, opts.compression)?);
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
    fn stage(self, width: u32, height: u32, compression: ExrCompression) -> Result<Staged, Error> {
        let mut other = std::collections::HashMap::new();
        let mut software = None;
        for (name, value) in self.attributes {
            if name == "software" {
                if let AttributeValue::Text(t) = value {
                    software = Some(t);
                }
            } else {
                other.insert(text(&name), value);
            }
        }
        let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = self
            .planes
            .into_iter()
            .map(|p| AnyChannel::new(Text::from_slice_unchecked(p.name.as_bytes()), p.samples))
            .collect();
        let attributes = LayerAttributes {
            software_name: software,
            other,
            ..LayerAttributes::default()
        };
        let encoding = Encoding {
            compression: compression.exr(),
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let layer = exr::image::Layer::new(
            (width as usize, height as usize),
            attributes,
            encoding,
            AnyChannels::sort(channels),
        );
        let image = Image::from_layer(layer);
        Staged::write(&self.path, |tmp| {
            image
                .write()
                .non_parallel()
                .to_file(tmp)
                .map_err(|e| e.to_string())?;
            sort_header_in_file(tmp)
        })
    }
}

/// [`sort_header_attributes`] on the file at `path`, reading only its
/// header (the first 64 kB, more if the header is longer), so the pixels
/// are never held in memory twice.
fn sort_header_in_file(path: &Path) -> Result<(), String> {
    use std::io::{Read, Seek, SeekFrom, Write};
    let io = |e: std::io::Error| e.to_string();
    let mut f = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)
        .map_err(io)?;
    let len = f.metadata().map_err(io)?.len() as usize;
    let mut n = len.min(1 << 16);
    loop {
        let mut head = vec![0u8; n];
        f.seek(SeekFrom::Start(0)).map_err(io)?;
        f.read_exact(&mut head).map_err(io)?;
        match sort_header_attributes(&mut head) {
            Ok(end) => {
                f.seek(SeekFrom::Start(0)).map_err(io)?;
                return f.write_all(&head[..end]).map_err(io);
            }
            Err(_) if n < len => n = (2 * n).min(len),
            Err(e) => return Err(e),
        }
    }
}

/// Beauty: `R`, `G`, `B` from the film, `A` = 1, 32-bit float (16 bytes a
/// pixel beside the film's 12; failing with a message, not aborting, when
/// that cannot be allocated).
fn beauty_planes(film: &Film) -> Result<Vec<Plane>, Error> {
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
    Ok(vec![
        plane("R", |p| p.x)?,
        plane("G", |p| p.y)?,
        plane("B", |p| p.z)?,
        plane("A", |_| 1.0)?,
    ])
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
                name: format!("{}.{ch}", layer.name),
                samples: if half {
                    FlatSamples::F16(values.map(f16::from_f32).collect())
                } else {
                    FlatSamples::F32(values.collect())
                },
            }
        })
        .collect()
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
        if !ok_name(&l.name) || ["R", "G", "B", "A"].contains(&l.name.as_str()) {
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
fn sort_header_attributes(bytes: &mut [u8]) -> Result<usize, String> {
    let malformed = || "malformed EXR header".to_string();
    if bytes.len() < 8 || bytes[..4] != [0x76, 0x2f, 0x31, 0x01] {
        return Err(malformed());
    }
    if bytes[5] & 0x10 != 0 {
        return Err("a multi-part EXR header (not written here)".into());
    }
    let cstr_end = |from: usize| -> Result<usize, String> {
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

/// The header attributes of a file, for tests and tools: (name, value).
pub fn read_attributes(path: &Path) -> Result<Vec<(String, AttributeValue)>, Error> {
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| Error::Read {
        path: path.to_path_buf(),
        problem: e.to_string(),
    })?;
    let mut out = Vec::new();
    for h in &meta.headers {
        if let Some(s) = &h.own_attributes.software_name {
            out.push(("software".to_string(), AttributeValue::Text(s.clone())));
        }
        for (k, v) in h
            .own_attributes
            .other
            .iter()
            .chain(&h.shared_attributes.other)
        {
            out.push((k.to_string(), v.clone()));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// The string attribute `name` of `attributes`, if present.
pub fn text_attribute(attributes: &[(String, AttributeValue)], name: &str) -> Option<String> {
    attributes
        .iter()
        .find(|a| a.0 == name)
        .and_then(|a| match &a.1 {
            AttributeValue::Text(t) => String::from_utf8(t.bytes().to_vec()).ok(),
            _ => None,
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    fn film() -> Film {
        let mut f = Film::new(3, 2);
        for (i, p) in f.pixels.iter_mut().enumerate() {
            *p = Vec3::new(i as f32 + 0.1, 1e-7 * i as f32, 70000.0 + i as f32);
        }
        f
    }

    pub(crate) fn layers() -> Vec<Layer> {
        let n = 6;
        let rgb = |s: f32| (0..n * 3).map(|i| s * (i as f32 + 0.3)).collect();
        vec![
            Layer {
                name: "diffuse_direct".into(),
                channels: vec!["R".into(), "G".into(), "B".into()],
                kind: LayerKind::Light,
                values: rgb(1.0 / 3.0),
            },
            Layer {
                name: "depth".into(),
                channels: vec!["Z".into()],
                kind: LayerKind::Data,
                values: (0..n).map(|i| 1000.0 + i as f32 / 7.0).collect(),
            },
            Layer {
                name: "object_id".into(),
                channels: vec!["id".into()],
                kind: LayerKind::Id,
                values: (0..n).map(|i| (16_777_000 + i) as f32).collect(),
            },
        ]
    }

    pub(crate) fn coverage() -> Vec<Coverage> {
        vec![Coverage {
            kind: "object".into(),
            names: vec!["bunny".into(), "floor".into()],
            pixels: vec![
                vec![(0, 1.0)],
                vec![(0, 0.25), (1, 0.75)],
                vec![],
                vec![(1, 1.0)],
                vec![(1, 0.5)],
                vec![(0, 0.5), (1, 0.5)],
            ],
        }]
    }

    fn header() -> FrameHeader {
        FrameHeader {
            scene_path: Some("scenes/x.toml".into()),
            spp: Some(4),
            seed: Some(7),
            render_seconds: Some(0.25),
            ..FrameHeader::default()
        }
    }

    fn channels(path: &Path) -> Vec<(String, FlatSamples)> {
        let img = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
        assert_eq!(img.layer_data.len(), 1);
        img.layer_data[0]
            .channel_data
            .list
            .iter()
            .map(|c| (c.name.to_string(), c.sample_data.clone()))
            .collect()
    }

    #[test]
    fn every_pass_reads_back_with_its_name_type_and_values() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.exr");
        let opts = OutputOptions {
            precision: Precision::Half,
            ..OutputOptions::default()
        };
        let (f, l, c) = (film(), layers(), coverage());
        write_frame(&p, &f, &l, &c, &header(), &opts).unwrap();
        let ch = channels(&p);
        let get = |n: &str| {
            &ch.iter()
                .find(|c| c.0 == n)
                .unwrap_or_else(|| panic!("{n}"))
                .1
        };
        let names: Vec<&str> = ch.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(names.len(), 4 + 3 + 1 + 1 + 12, "{names:?}");
        // beauty: float, exact
        let FlatSamples::F32(r) = get("R") else {
            panic!("R not float")
        };
        assert_eq!(r, &f.pixels.iter().map(|p| p.x).collect::<Vec<_>>());
        let FlatSamples::F32(b) = get("B") else {
            panic!("B not float")
        };
        assert_eq!(b[1], 70001.0); // beyond half's range: beauty stays float
                                   // light pass at half: rounded to nearest half
        let FlatSamples::F16(g) = get("diffuse_direct.G") else {
            panic!("not half")
        };
        let want: Vec<f16> = l[0]
            .values
            .iter()
            .skip(1)
            .step_by(3)
            .map(|&v| f16::from_f32(v))
            .collect();
        assert_eq!(g, &want);
        // data and IDs stay float, exact
        let FlatSamples::F32(z) = get("depth.Z") else {
            panic!("depth not float")
        };
        assert_eq!(z, &l[1].values);
        let FlatSamples::F32(id) = get("object_id.id") else {
            panic!("id not float")
        };
        assert_eq!(id, &l[2].values);
        // Cryptomatte: rank 0 of pixel 1 is floor at 0.75
        let FlatSamples::F32(id0) = get("CryptoObject00.R") else {
            panic!()
        };
        let FlatSamples::F32(cov0) = get("CryptoObject00.G") else {
            panic!()
        };
        assert_eq!((id0[1], cov0[1]), (cryptomatte::name_id("floor"), 0.75));
        assert_eq!((id0[2], cov0[2]), (0.0, 0.0));
        // header
        let a = read_attributes(&p).unwrap();
        let key = cryptomatte::metadata_key("CryptoObject");
        assert_eq!(
            text_attribute(&a, &format!("cryptomatte/{key}/name")).as_deref(),
            Some("CryptoObject")
        );
        assert_eq!(
            text_attribute(&a, &format!("cryptomatte/{key}/manifest")),
            Some(cryptomatte::manifest(&c[0].names))
        );
        assert_eq!(
            text_attribute(&a, "software"),
            Some(format!("lucent {}", env!("CARGO_PKG_VERSION")))
        );
        assert!(a.contains(&("lucent/spp".into(), AttributeValue::I32(4))));
        // float precision: the light pass is float too
        write_frame(&p, &f, &l, &c, &header(), &OutputOptions::default()).unwrap();
        assert!(matches!(
            get_owned(&p, "diffuse_direct.G"),
            FlatSamples::F32(_)
        ));
    }

    fn get_owned(p: &Path, name: &str) -> FlatSamples {
        channels(p).into_iter().find(|c| c.0 == name).unwrap().1
    }

    #[test]
    fn same_frame_same_bytes_for_every_compression() {
        let dir = tempfile::tempdir().unwrap();
        for comp in ["none", "rle", "zips", "zip", "piz"] {
            let opts = OutputOptions {
                compression: ExrCompression::parse(comp).unwrap(),
                ..OutputOptions::default()
            };
            let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
            for p in [&a, &b] {
                write_frame(p, &film(), &layers(), &coverage(), &header(), &opts).unwrap();
            }
            assert_eq!(
                std::fs::read(&a).unwrap(),
                std::fs::read(&b).unwrap(),
                "{comp}"
            );
            // and lossless
            assert_eq!(Film::read_exr(&a).unwrap(), film(), "{comp}");
            assert_eq!(channels(&a), channels(&dir.path().join("b.exr")));
        }
    }

    #[test]
    fn sorting_the_header_keeps_the_file_readable_and_its_length() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.exr");
        film().write_exr(&p).unwrap();
        let mut bytes = std::fs::read(&p).unwrap();
        let before = bytes.clone();
        sort_header_attributes(&mut bytes).unwrap();
        assert_eq!(bytes.len(), before.len());
        // today's header (required attributes first) is not in name order
        assert_ne!(bytes, before);
        std::fs::write(&p, &bytes).unwrap();
        assert_eq!(Film::read_exr(&p).unwrap(), film());
        assert!(sort_header_attributes(&mut bytes[..20].to_vec()).is_err());
        assert!(sort_header_attributes(&mut b"not an exr".to_vec()).is_err());
    }

    #[test]
    fn a_header_longer_than_the_first_read_is_sorted_too() {
        // a manifest of 4000 names: a header of about 100 kB
        let mut c = coverage();
        c[0].names = (0..4000).map(|i| format!("object_number_{i}")).collect();
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
        for p in [&a, &b] {
            write_frame(p, &film(), &[], &c, &header(), &OutputOptions::default()).unwrap();
        }
        let bytes = std::fs::read(&a).unwrap();
        assert!(bytes.len() > 100_000);
        assert_eq!(bytes, std::fs::read(&b).unwrap());
        let key = cryptomatte::metadata_key("CryptoObject");
        let m = text_attribute(
            &read_attributes(&a).unwrap(),
            &format!("cryptomatte/{key}/manifest"),
        );
        assert_eq!(m, Some(cryptomatte::manifest(&c[0].names)));
        assert_eq!(Film::read_exr(&a).unwrap(), film());
    }

    #[test]
    fn beauty_only_frame_has_the_pixels_of_the_plain_writer() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
        film().write_exr(&a).unwrap();
        write_frame(&b, &film(), &[], &[], &header(), &OutputOptions::default()).unwrap();
        assert_eq!(channels(&a), channels(&b));
        assert_eq!(Film::read_exr(&b).unwrap(), film());
    }

    #[test]
    fn split_writes_one_file_per_pass_all_or_none() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.exr");
        let opts = OutputOptions {
            split: true,
            preview: Some(Preview {
                tonemap: ToneMap::Clamp,
                exposure: 0.0,
            }),
            ..OutputOptions::default()
        };
        write_frame(&p, &film(), &layers(), &coverage(), &header(), &opts).unwrap();
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                "f.CryptoObject.exr",
                "f.depth.exr",
                "f.diffuse_direct.exr",
                "f.exr",
                "f.object_id.exr",
                "f.png"
            ]
        );
        let beauty: Vec<String> = channels(&p).into_iter().map(|c| c.0).collect();
        assert_eq!(beauty, ["A", "B", "G", "R"]);
        let depth = dir.path().join("f.depth.exr");
        assert_eq!(channels(&depth).len(), 1);
        let a = read_attributes(&depth).unwrap();
        assert_eq!(text_attribute(&a, "lucent/pass").as_deref(), Some("depth"));
        assert_eq!(
            text_attribute(&a, "lucent/scene").as_deref(),
            Some("scenes/x.toml")
        );
        let crypto = read_attributes(&dir.path().join("f.CryptoObject.exr")).unwrap();
        assert!(crypto.iter().any(|x| x.0.starts_with("cryptomatte/")));
        assert!(!read_attributes(&p)
            .unwrap()
            .iter()
            .any(|x| x.0.starts_with("cryptomatte/")));
        // one destination that cannot be replaced: nothing changes
        for n in &names {
            std::fs::remove_file(dir.path().join(n)).unwrap();
        }
        std::fs::create_dir(dir.path().join("f.depth.exr")).unwrap();
        assert!(write_frame(&p, &film(), &layers(), &coverage(), &header(), &opts).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn malformed_passes_are_refused_and_nothing_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.exr");
        let (f, c) = (film(), coverage());
        let try_with = |edit: &dyn Fn(&mut Vec<Layer>)| {
            let mut l = layers();
            edit(&mut l);
            write_frame(&p, &f, &l, &c, &header(), &OutputOptions::default())
        };
        assert!(try_with(&|l| l[0].name = "a.b".into()).is_err());
        assert!(try_with(&|l| l[0].name = "R".into()).is_err());
        assert!(try_with(&|l| l[0].name = "CryptoObject00".into()).is_err());
        assert!(try_with(&|l| l[1].name = "diffuse_direct".into()).is_err());
        assert!(try_with(&|l| l[0].channels[2] = "R".into()).is_err());
        assert!(try_with(&|l| l[0].channels.clear()).is_err());
        assert!(try_with(&|l| l[1].values.pop().map(|_| ()).unwrap_or(())).is_err());
        assert!(try_with(&|_| ()).is_ok());
        std::fs::remove_file(&p).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        assert_eq!(
            split_path(Path::new("out/a.b.exr"), "sss_direct"),
            Path::new("out/a.b.sss_direct.exr")
        );
    }
}
