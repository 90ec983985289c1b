//! A part file opened as untrusted input: its EXR structure checked
//! against what its own header says this build writes, before any pixel
//! buffer is sized (docs/farm.md, "Parts as untrusted input").
//!
//! The file is opened only if it is a regular file ([`open_regular`]), its
//! headers are read (their reads are bounded by the file), and then the EXR
//! layer must be exactly the part [`super::part::stage`] writes for that
//! header: one flat scan-line layer, ZIP16, the region's data window, the
//! frame's display window, u32 channels with the names the header's layers
//! and passes imply. A file too small to hold its pixels at deflate's
//! largest ratio ([`MAX_DEFLATE_RATIO`]) is truncated or forged and refused
//! before its pixels are read, so what reading allocates is bounded by a
//! fixed multiple of the file's size.

use std::fs::File;
use std::io::{BufReader, Seek, SeekFrom};
use std::path::Path;

use exr::meta::attribute::{ChannelDescription, SampleType};
use exr::meta::{BlockDescription, MetaData};
use exr::prelude::{Compression, Vec2};

use super::header::{bad, layout_of, Header};
use crate::error::Error;
use crate::film::pass_layout::Layout;
use crate::film::passes::Pass;
use crate::scene::regular_file::open_regular;

/// Deflate's largest compression ratio (a 258-byte match coded in two
/// bits): no ZIP chunk holds more than this many bytes per stored byte.
pub const MAX_DEFLATE_RATIO: u64 = 1032;

/// The nearest hit's channels, `nearest.<name>`, in `part::nearest_words`
/// order.
pub(super) const NEAREST: [&str; 7] = ["depth", "sample", "px", "py", "pz", "object", "material"];

/// A part file whose header and EXR structure are checked, its pixels not
/// yet read.
pub(crate) struct PartFile {
    pub header: Header,
    file: File,
}

impl PartFile {
    /// Opens and checks the part at `path`.
    pub fn open(path: &Path) -> Result<PartFile, Error> {
        let (file, len) = open_regular(path)
            .map_err(|e| bad(path, None, format!("cannot read the part: {e}")))?;
        let meta = MetaData::read_from_buffered(BufReader::new(&file), true).map_err(|e| {
            let problem = format!("not a readable OpenEXR file (not a lucent part): {e}");
            bad(path, None, problem)
        })?;
        let [exr] = &meta.headers[..] else {
            let problem = "not a lucent part: more than one EXR layer";
            return Err(bad(path, None, problem));
        };
        let header = Header::read(path, &exr.own_attributes.other)?;
        check_structure(path, &header, exr, len)?;
        Ok(PartFile { header, file })
    }

    /// The file from its start, to read its pixels.
    pub fn rewound(mut self) -> Result<BufReader<File>, Error> {
        self.file
            .seek(SeekFrom::Start(0))
            .map_err(|e| Error::Runtime(format!("cannot read the part again: {e}")))?;
        Ok(BufReader::new(self.file))
    }
}

/// That the EXR layer `exr` is the one a part with `header` has, in a file
/// of `len` bytes.
fn check_structure(
    path: &Path,
    header: &Header,
    exr: &exr::meta::header::Header,
    len: u64,
) -> Result<(), Error> {
    let fail = |problem: String| Err(bad(path, None, problem));
    if exr.deep || !matches!(exr.blocks, BlockDescription::ScanLines) {
        return fail("deep or tiled EXR data: a part is flat scan lines".into());
    }
    if exr.compression != Compression::ZIP16 {
        return fail(format!(
            "EXR compression {:?}: parts are written with ZIP16 (damaged or forged)",
            exr.compression
        ));
    }
    let r = header.region;
    let at = exr.own_attributes.layer_position;
    if exr.layer_size != Vec2(r.width() as usize, r.height() as usize)
        || at != Vec2(r.x0 as i32, r.y0 as i32)
    {
        let (w, h) = (exr.layer_size.0, exr.layer_size.1);
        let problem = format!("{r} but the pixels are {w}×{h} at ({}, {})", at.0, at.1);
        return Err(bad(path, Some("lucent.region"), problem));
    }
    let display = exr.shared_attributes.display_window;
    let (fw, fh) = header.identity.frame;
    if display.position != Vec2(0, 0) || display.size != Vec2(fw as usize, fh as usize) {
        let problem = format!(
            "a {fw}×{fh} frame, but the EXR display window is {}×{} at ({}, {})",
            display.size.0, display.size.1, display.position.0, display.position.1
        );
        return Err(bad(path, Some("lucent.frame"), problem));
    }
    let layout = layout_of(&header.identity).map_err(|e| e.at(path))?;
    for c in &exr.channels.list {
        check_channel(c, header, layout.as_ref()).map_err(|p| bad(path, None, p.to_string()))?;
    }
    let raw = r.area() as u128 * exr.channels.list.len() as u128 * 4;
    if raw > len as u128 * MAX_DEFLATE_RATIO as u128 {
        return fail(format!(
            "{len} bytes cannot hold the {raw} bytes of its {} channels of {r}: \
             truncated or forged",
            exr.channels.list.len()
        ));
    }
    Ok(())
}

/// That channel `c` is one a part with `header` (passes `layout`) writes:
/// full-resolution u32, named by its layers, nearest hit or coverage.
fn check_channel(
    c: &ChannelDescription,
    header: &Header,
    layout: Option<&Layout>,
) -> Result<(), ChannelFault> {
    let name = c.name.to_string();
    if c.sample_type != SampleType::U32 || c.sampling != Vec2(1, 1) {
        return Err(ChannelFault::Samples {
            name,
            kind: format!("{:?}", c.sample_type),
            every: (c.sampling.0, c.sampling.1),
        });
    }
    let summed = header.layers.iter().any(|l| {
        l.channels
            .iter()
            .any(|ch| (0..4).any(|w| name == format!("{}.{ch}.w{w}", l.name)))
    });
    let nearest = layout.is_some_and(|l| l.nearest())
        && NEAREST.iter().any(|n| name == format!("nearest.{n}"));
    if summed || nearest || is_coverage(&name, layout) {
        return Ok(());
    }
    Err(ChannelFault::Foreign { name })
}

/// A channel no part writes.
#[derive(Debug, thiserror::Error)]
enum ChannelFault {
    /// Not u32 at every pixel.
    #[error(
        "channel {name}: {kind} samples every {}×{} pixels, parts hold u32 at every pixel",
        every.0,
        every.1
    )]
    Samples {
        name: String,
        kind: String,
        every: (usize, usize),
    },
    /// A name none of the part's layers and passes has.
    #[error("channel {name}: not a channel of this part's layers and passes")]
    Foreign { name: String },
}

/// Whether `name` is a coverage channel `coverage.<kind>.id{k}` / `n{k}`
/// of a kind the passes keep, with `k` below the number of names of that
/// kind (a pixel holds each ID at most once).
fn is_coverage(name: &str, layout: Option<&Layout>) -> bool {
    let Some(l) = layout else {
        return false;
    };
    let kinds = [
        ("object", Pass::CryptoObject, l.object_names.len()),
        ("material", Pass::CryptoMaterial, l.material_names.len()),
    ];
    kinds.iter().any(|(kind, pass, names)| {
        let Some(rest) = name.strip_prefix(&format!("coverage.{kind}.")) else {
            return false;
        };
        let digits = rest.strip_prefix("id").or_else(|| rest.strip_prefix('n'));
        // canonical digits only: `id01` is not a name the writer makes
        let k = digits.and_then(|d| d.parse::<usize>().ok().filter(|k| k.to_string() == d));
        l.passes.contains(*pass) && k.is_some_and(|k| k < *names)
    })
}
