//! A part: the exact sums of a region of a frame over a range of sample
//! indices, as an OpenEXR file that says what it is.
//!
//! # Format (version [`FORMAT_VERSION`])
//!
//! One scan-line EXR (ZIP), its data window the part's region, its display
//! window the whole frame. Each summed channel `C` of a layer `L` (beauty
//! today: `beauty.R`, `beauty.G`, `beauty.B`) is stored as four `u32`
//! channels `L.C.w0` … `L.C.w3`, the words of the pixel's `i128` sum, least
//! significant first ([`crate::film::accumulate::to_words`]) — EXR's only
//! integer sample type is u32, and floats could not hold the sums exactly.
//! Header attributes (text):
//!
//! | attribute | value |
//! |---|---|
//! | `lucent.format` | `lucent-part` |
//! | `lucent.format_version` | [`FORMAT_VERSION`] |
//! | `lucent.version` | the lucent version that rendered it |
//! | `lucent.scene` | the scene file's name (for messages only) |
//! | `lucent.scene_hash` | [`super::scene_hash()`] of the scene |
//! | `lucent.seed`, `lucent.spp` | the frame's seed and samples per pixel |
//! | `lucent.options` | every option that changes the image, canonical |
//! | `lucent.frame` | `W,H` |
//! | `lucent.region` | `X0,Y0,X1,Y1` (= the data window) |
//! | `lucent.samples` | `A..B`: the sample indices summed |
//! | `lucent.requested` | `A..E`: what the job was asked for (`B < E` after an interruption) |
//! | `lucent.layers` | `L:C,C,…:F;…`: each layer's channels and fixed-point fraction bits |
//! | `lucent.counters` | `rays,nonfinite,clamped,walks_capped,walks_escaped` |
//!
//! A merge needs nothing else: any set of named layers merges the same way
//! (add the integer sums, divide by spp once), so the AOV layers will ride
//! along as more `lucent.layers` entries.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use crate::error::{Error, InputError};
use crate::film::accumulate::{from_words, to_words, FixedPoint};
use crate::film::region::Region;
use crate::film::Staged;
use crate::integrator::Counters;
use crate::render::Accumulated;

/// The part format this build writes and reads.
pub const FORMAT_VERSION: u32 = 1;

/// What identifies the frame a part belongs to: parts merge only if all of
/// it is equal.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Identity {
    /// lucent's version.
    pub version: String,
    pub scene_hash: String,
    pub seed: u64,
    pub spp: u32,
    /// Every render option that changes the image, canonical (backend,
    /// integrator, subsurface overrides).
    pub options: String,
    /// The frame's width and height.
    pub frame: (u32, u32),
}

impl Identity {
    /// The first field in which `self` and `o` differ: its attribute name,
    /// and the two values.
    pub fn difference(&self, o: &Identity) -> Option<(&'static str, String, String)> {
        let f = |a: &(u32, u32)| format!("{},{}", a.0, a.1);
        [
            ("lucent.version", self.version.clone(), o.version.clone()),
            (
                "lucent.scene_hash",
                self.scene_hash.clone(),
                o.scene_hash.clone(),
            ),
            ("lucent.seed", self.seed.to_string(), o.seed.to_string()),
            ("lucent.spp", self.spp.to_string(), o.spp.to_string()),
            ("lucent.options", self.options.clone(), o.options.clone()),
            ("lucent.frame", f(&self.frame), f(&o.frame)),
        ]
        .into_iter()
        .find(|(_, a, b)| a != b)
    }
}

/// A layer of summed channels.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LayerFormat {
    pub name: String,
    pub channels: Vec<String>,
    pub fixed: FixedPoint,
}

/// Everything a part's header says.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    pub identity: Identity,
    /// The scene file's name, for messages.
    pub scene: String,
    pub region: Region,
    /// The sample indices summed.
    pub samples: Range<u32>,
    /// The sample indices the job was asked for.
    pub requested: Range<u32>,
    pub layers: Vec<LayerFormat>,
    pub counters: Counters,
}

/// The beauty layer every part has.
pub fn beauty_layer() -> LayerFormat {
    LayerFormat {
        name: "beauty".into(),
        channels: vec!["R".into(), "G".into(), "B".into()],
        fixed: Accumulated::FORMAT,
    }
}

fn range_text(r: &Range<u32>) -> String {
    format!("{}..{}", r.start, r.end)
}

fn parse_range(s: &str) -> Option<Range<u32>> {
    let (a, b) = s.split_once("..")?;
    let (a, b) = (a.trim().parse().ok()?, b.trim().parse().ok()?);
    (a <= b).then_some(a..b)
}

/// Parses `A..B` with A < B (the `--samples` option's form).
pub fn parse_samples(s: &str) -> Option<Range<u32>> {
    parse_range(s).filter(|r| !r.is_empty())
}

/// Stages the part file of `sums` at `path` (commit it with
/// [`crate::film::commit_all`]).
pub fn stage(path: &Path, header: &Header, sums: &Accumulated) -> Result<Staged, Error> {
    use exr::prelude::*;
    let r = sums.region;
    let n = r.area() as usize;
    let beauty = beauty_layer();
    let mut channels = SmallVec::<[AnyChannel<FlatSamples>; 4]>::new();
    for (c, ch) in beauty.channels.iter().enumerate() {
        let mut words = [
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        ];
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                for (k, w) in to_words(sums.pixel(x, y)[c]).into_iter().enumerate() {
                    words[k].push(w);
                }
            }
        }
        for (k, w) in words.into_iter().enumerate() {
            channels.push(AnyChannel::new(
                format!("{}.{ch}.w{k}", beauty.name).as_str(),
                FlatSamples::U32(w),
            ));
        }
    }
    let text = |s: &str| {
        // EXR text is bytes 0–255: anything else (a file name) shown escaped
        let t: String = s.chars().flat_map(|c| c.escape_default()).collect();
        AttributeValue::Text(Text::new_or_panic(if s.is_ascii() { s } else { &t }))
    };
    let id = &header.identity;
    let c = &header.counters;
    let mut attrs = LayerAttributes {
        layer_position: Vec2(r.x0 as i32, r.y0 as i32),
        ..LayerAttributes::default()
    };
    for (k, v) in [
        ("lucent.format", "lucent-part".to_string()),
        ("lucent.format_version", FORMAT_VERSION.to_string()),
        ("lucent.version", id.version.clone()),
        ("lucent.scene", header.scene.clone()),
        ("lucent.scene_hash", id.scene_hash.clone()),
        ("lucent.seed", id.seed.to_string()),
        ("lucent.spp", id.spp.to_string()),
        ("lucent.options", id.options.clone()),
        ("lucent.frame", format!("{},{}", id.frame.0, id.frame.1)),
        ("lucent.region", r.to_string()),
        ("lucent.samples", range_text(&header.samples)),
        ("lucent.requested", range_text(&header.requested)),
        (
            "lucent.layers",
            format!(
                "{}:{}:{}",
                beauty.name,
                beauty.channels.join(","),
                beauty.fixed.frac_bits
            ),
        ),
        (
            "lucent.counters",
            format!(
                "{},{},{},{},{}",
                c.rays, c.nonfinite, c.clamped, c.walks_capped, c.walks_escaped
            ),
        ),
    ] {
        attrs.other.insert(Text::new_or_panic(k), text(&v));
    }
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (r.width() as usize, r.height() as usize),
        attrs,
        encoding,
        AnyChannels::sort(channels),
    );
    let mut image = Image::from_layer(layer);
    image.attributes.display_window =
        IntegerBounds::new((0, 0), (id.frame.0 as usize, id.frame.1 as usize));
    Staged::write(path, |tmp| {
        image
            .write()
            .non_parallel()
            .to_file(tmp)
            .map_err(|e| e.to_string())
    })
}

/// A bad part: the file, the attribute (when one is at fault), the problem.
fn bad(path: &Path, field: Option<&str>, problem: impl Into<String>) -> Error {
    let e = InputError::new(path, problem);
    match field {
        Some(f) => e.in_field(f).into(),
        None => e.into(),
    }
}

/// The part header of the EXR header `attrs` (the layer's own attributes).
fn parse_header(
    path: &Path,
    attrs: &HashMap<exr::meta::attribute::Text, exr::meta::attribute::AttributeValue>,
) -> Result<Header, Error> {
    use exr::meta::attribute::AttributeValue;
    let get = |k: &str| -> Result<String, Error> {
        match attrs.get(&exr::meta::attribute::Text::new_or_panic(k)) {
            Some(AttributeValue::Text(t)) => Ok(t.to_string()),
            Some(_) => Err(bad(path, Some(k), "is not text")),
            None => Err(bad(path, Some(k), "is missing")),
        }
    };
    match get("lucent.format") {
        Ok(f) if f == "lucent-part" => {}
        _ => {
            return Err(bad(
                path,
                None,
                "not a lucent part (no `lucent.format = lucent-part` header attribute): \
                 merge takes the parts `lucent render --crop/--tile/--samples` writes",
            ))
        }
    }
    let num = |k: &str| -> Result<u64, Error> {
        let v = get(k)?;
        v.parse()
            .map_err(|_| bad(path, Some(k), format!("`{v}` is not a number")))
    };
    let version = num("lucent.format_version")?;
    if version != FORMAT_VERSION as u64 {
        return Err(bad(
            path,
            Some("lucent.format_version"),
            format!("part format {version}, this lucent reads format {FORMAT_VERSION}"),
        ));
    }
    let spp = u32::try_from(num("lucent.spp")?)
        .map_err(|_| bad(path, Some("lucent.spp"), "out of range"))?;
    let frame = get("lucent.frame")?;
    let frame = frame
        .split_once(',')
        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
        .ok_or_else(|| bad(path, Some("lucent.frame"), format!("`{frame}` is not W,H")))?;
    let region_text = get("lucent.region")?;
    let region = Region::parse(&region_text)
        .filter(|r| !r.is_empty())
        .ok_or_else(|| {
            bad(
                path,
                Some("lucent.region"),
                format!("`{region_text}` is not X0,Y0,X1,Y1"),
            )
        })?;
    let range = |k: &str| -> Result<Range<u32>, Error> {
        let v = get(k)?;
        parse_range(&v).ok_or_else(|| bad(path, Some(k), format!("`{v}` is not A..B")))
    };
    let samples = range("lucent.samples")?;
    let requested = range("lucent.requested")?;
    let layers_text = get("lucent.layers")?;
    let layers = layers_text
        .split(';')
        .map(|l| {
            let mut it = l.split(':');
            let (name, ch, f) = (it.next()?, it.next()?, it.next()?);
            Some(LayerFormat {
                name: name.into(),
                channels: ch.split(',').map(String::from).collect(),
                fixed: FixedPoint::new(f.parse().ok()?)?,
            })
        })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| {
            bad(
                path,
                Some("lucent.layers"),
                format!("`{layers_text}` is not NAME:CHANNELS:BITS"),
            )
        })?;
    if layers != [beauty_layer()] {
        return Err(bad(
            path,
            Some("lucent.layers"),
            format!("`{layers_text}`: this lucent merges the layer beauty:R,G,B:64 only"),
        ));
    }
    let counters_text = get("lucent.counters")?;
    let c: Vec<u64> = counters_text
        .split(',')
        .map(|v| v.parse().ok())
        .collect::<Option<_>>()
        .filter(|v: &Vec<u64>| v.len() == 5)
        .ok_or_else(|| {
            bad(
                path,
                Some("lucent.counters"),
                format!("`{counters_text}` is not 5 counts"),
            )
        })?;
    let header = Header {
        identity: Identity {
            version: get("lucent.version")?,
            scene_hash: get("lucent.scene_hash")?,
            seed: num("lucent.seed")?,
            spp,
            options: get("lucent.options")?,
            frame,
        },
        scene: get("lucent.scene")?,
        region,
        samples: samples.clone(),
        requested: requested.clone(),
        layers,
        counters: Counters {
            rays: c[0],
            nonfinite: c[1],
            clamped: c[2],
            walks_capped: c[3],
            walks_escaped: c[4],
            // parts do not carry the per-effect counts (`--stats` of one
            // render), so a merged frame's are 0
            ..Counters::default()
        },
    };
    let (w, h) = header.identity.frame;
    if !region.within(&Region::full(w, h)) {
        return Err(bad(
            path,
            Some("lucent.region"),
            format!("{region} is not inside the {w}×{h} frame"),
        ));
    }
    if samples.end > spp || requested.end > spp || samples.start != requested.start {
        return Err(bad(
            path,
            Some("lucent.samples"),
            format!(
                "samples {} (asked {}) do not fit 0..{spp}",
                range_text(&samples),
                range_text(&requested)
            ),
        ));
    }
    Ok(header)
}

/// The header of the part at `path`, without its pixels.
pub fn read_header(path: &Path) -> Result<Header, Error> {
    let meta = exr::meta::MetaData::read_from_file(path, true).map_err(|e| {
        bad(
            path,
            None,
            format!("not a readable OpenEXR file (not a lucent part): {e}"),
        )
    })?;
    let [h] = &meta.headers[..] else {
        return Err(bad(
            path,
            None,
            "not a lucent part: more than one EXR layer",
        ));
    };
    parse_header(path, &h.own_attributes.other)
}

/// The part at `path`: its header and sums. A damaged or truncated file,
/// or one whose pixels disagree with its header, is bad input naming it.
pub fn read(path: &Path) -> Result<(Header, Accumulated), Error> {
    use exr::prelude::*;
    let header = read_header(path)?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .pedantic()
        .non_parallel()
        .from_file(path)
        .map_err(|e| bad(path, None, format!("damaged or truncated part: {e}")))?;
    let layer = &image.layer_data;
    let r = header.region;
    let size = (r.width() as usize, r.height() as usize);
    if layer.size != Vec2(size.0, size.1)
        || layer.attributes.layer_position != Vec2(r.x0 as i32, r.y0 as i32)
    {
        return Err(bad(
            path,
            Some("lucent.region"),
            format!(
                "{} but the pixels are {}×{} at ({}, {})",
                r,
                layer.size.0,
                layer.size.1,
                layer.attributes.layer_position.0,
                layer.attributes.layer_position.1
            ),
        ));
    }
    let mut sums = Accumulated::new(r, header.samples.start)?;
    sums.done = header.samples.end;
    sums.counters = header.counters;
    let beauty = beauty_layer();
    let expected = beauty.channels.len() * 4;
    if layer.channel_data.list.len() != expected {
        return Err(bad(
            path,
            None,
            format!(
                "{} channels, a part of layer beauty has {expected}",
                layer.channel_data.list.len()
            ),
        ));
    }
    for (c, ch) in beauty.channels.iter().enumerate() {
        let mut words: Vec<&[u32]> = Vec::with_capacity(4);
        for k in 0..4 {
            let name = format!("{}.{ch}.w{k}", beauty.name);
            let found = layer
                .channel_data
                .list
                .iter()
                .find(|a| a.name == Text::new_or_panic(&name));
            match found.map(|a| &a.sample_data) {
                Some(FlatSamples::U32(v)) if v.len() == r.area() as usize => words.push(v),
                Some(_) => {
                    return Err(bad(path, None, format!("channel {name} is not u32 pixels")))
                }
                None => return Err(bad(path, None, format!("channel {name} is missing"))),
            }
        }
        let mut i = 0;
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                sums.pixel_mut(x, y)[c] =
                    from_words([words[0][i], words[1][i], words[2][i], words[3][i]]);
                i += 1;
            }
        }
    }
    Ok((header, sums))
}
