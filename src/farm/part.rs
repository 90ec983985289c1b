//! A part: the exact sums of a region of a frame over a range of sample
//! indices, as an OpenEXR file that says what it is.
//!
//! # Format (version [`FORMAT_VERSION`])
//!
//! One scan-line EXR (ZIP), its data window the part's region, its display
//! window the whole frame. Each summed channel `C` of a layer `L` (the
//! beauty's `beauty.R`, `beauty.G`, `beauty.B`, then the passes' summed
//! layers, `crate::integrator::aov::pixels`) is stored as four `u32`
//! channels `L.C.w0` … `L.C.w3`, the words of the pixel's `i128` sum, least
//! significant first ([`crate::film::accumulate::to_words`]) — EXR's only
//! integer sample type is u32, and floats could not hold the sums exactly.
//! With P, Z or an ID pass, the nearest camera hit is stored as the u32
//! channels `nearest.depth`, `nearest.sample`, `nearest.px`/`py`/`pz` (f32
//! bits), `nearest.object`, `nearest.material` (index + 1, 0: none); with
//! Cryptomatte, the sample counts per ID as `coverage.object.id{k}` (the
//! index plus 1, 0: empty) and `coverage.object.n{k}` for k below the most
//! IDs any pixel of the part saw (the same for `material`).
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
//! | `lucent.passes` | the passes, comma-separated (empty: none) |
//! | `lucent.names` | JSON: the light groups, matted objects and materials the passes name |
//! | `lucent.output` | how the frame is written: `precision=… compression=… split=… ranks=…` |
//!
//! A merge needs nothing else. The passes, names and output options are
//! part of the [`Identity`]: the EXR options change no sum, but a merged
//! frame is written as its parts say, so they must agree (and then equal
//! the uncut render's file options); the PNG preview's tone map is the
//! merge command's own.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use crate::error::{Error, InputError};
use crate::film::accumulate::{from_words, to_words, FixedPoint};
use crate::film::exr_layers::{ExrCompression, OutputOptions, Precision};
use crate::film::passes::PassSet;
use crate::film::region::Region;
use crate::film::Staged;
use crate::integrator::aov::pixels::{AovSums, Layout, Nearest};
use crate::integrator::Counters;
use crate::render::Accumulated;

/// The passes of `layout` as `lucent.passes` says them (empty: none).
pub fn passes_text(layout: Option<&Layout>) -> String {
    layout.map_or(String::new(), |l| {
        l.passes
            .iter()
            .map(|p| p.name())
            .collect::<Vec<_>>()
            .join(",")
    })
}

/// The names `layout` uses, as `lucent.names` says them: JSON, non-ASCII
/// characters escaped (EXR text is bytes).
pub fn names_text(layout: Option<&Layout>) -> String {
    let Some(l) = layout else {
        return String::new();
    };
    let json = serde_json::json!({
        "groups": l.groups,
        "objects": l.object_names,
        "materials": l.material_names,
    })
    .to_string();
    let mut out = String::with_capacity(json.len());
    for c in json.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            for u in c.encode_utf16(&mut [0; 2]) {
                out.push_str(&format!("\\u{u:04x}"));
            }
        }
    }
    out
}

/// The file options of a frame, as `lucent.output` says them.
pub fn output_text(o: &OutputOptions) -> String {
    format!(
        "precision={} compression={} split={} ranks={}",
        o.precision.name(),
        o.compression.name(),
        o.split,
        o.cryptomatte_ranks
    )
}

/// The inverse of [`output_text`] (no preview).
pub fn parse_output(s: &str) -> Option<OutputOptions> {
    let mut o = OutputOptions::default();
    let mut seen = 0;
    for kv in s.split(' ') {
        let (k, v) = kv.split_once('=')?;
        match k {
            "precision" => o.precision = Precision::parse(v)?,
            "compression" => o.compression = ExrCompression::parse(v)?,
            "split" => o.split = v.parse().ok()?,
            "ranks" => o.cryptomatte_ranks = v.parse().ok()?,
            _ => return None,
        }
        seen += 1;
    }
    (seen == 4).then_some(o)
}

/// The layout a part's identity describes (None: no passes), or what is
/// wrong with it (the attribute and the problem).
pub fn layout_of(id: &Identity) -> Result<Option<Layout>, (&'static str, String)> {
    if id.passes.is_empty() {
        return Ok(None);
    }
    let passes = PassSet::parse_list(&id.passes).map_err(|e| ("lucent.passes", e.problem()))?;
    let names: serde_json::Value = serde_json::from_str(&id.names)
        .map_err(|e| ("lucent.names", format!("not the JSON of names: {e}")))?;
    let list = |k: &str| -> Result<Vec<String>, (&'static str, String)> {
        names
            .get(k)
            .and_then(|v| v.as_array())
            .and_then(|a| a.iter().map(|s| s.as_str().map(String::from)).collect())
            .ok_or(("lucent.names", format!("no list of names `{k}`")))
    };
    Ok(Some(Layout::new(
        passes,
        &list("groups")?,
        &list("objects")?,
        &list("materials")?,
    )))
}

/// The layers a part of `layout`'s passes sums: the beauty, then the
/// passes' summed layers.
pub fn layers_of(layout: Option<&Layout>) -> Vec<LayerFormat> {
    let mut v = vec![beauty_layer()];
    if let Some(l) = layout {
        v.extend(l.sum_layers().into_iter().map(|s| LayerFormat {
            name: s.name,
            channels: s.channels,
            fixed: FixedPoint {
                frac_bits: s.frac_bits,
            },
        }));
    }
    v
}

/// The part format this build writes and reads.
pub const FORMAT_VERSION: u32 = 2;

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
    /// The passes ([`passes_text`]).
    pub passes: String,
    /// The names the passes use ([`names_text`]).
    pub names: String,
    /// The frame's file options ([`output_text`]).
    pub output: String,
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
            ("lucent.passes", self.passes.clone(), o.passes.clone()),
            ("lucent.names", self.names.clone(), o.names.clone()),
            ("lucent.output", self.output.clone(), o.output.clone()),
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
    let layout = sums.passes.as_ref().map(|p| &p.layout);
    let mut channels = SmallVec::<[AnyChannel<FlatSamples>; 4]>::new();
    // the region's pixels, row by row: their index in the sums
    let order: Vec<usize> = (r.y0..r.y1)
        .flat_map(|y| (r.x0..r.x1).map(move |x| (x, y)))
        .map(|(x, y)| sums.index(x, y))
        .collect();
    let stride = layout.map_or(0, |l| l.stride());
    let mut aov_channel = 0;
    for layer in layers_of(layout) {
        for ch in &layer.channels {
            let value = |i: usize| -> i128 {
                if layer.name == "beauty" {
                    let c = layer.channels.iter().position(|x| x == ch).unwrap_or(0);
                    sums.pixel_at(i)[c]
                } else {
                    sums.passes
                        .as_ref()
                        .map_or(0, |p| p.sums.sums[i * stride + aov_channel])
                }
            };
            let mut words = [
                Vec::with_capacity(n),
                Vec::with_capacity(n),
                Vec::with_capacity(n),
                Vec::with_capacity(n),
            ];
            for &i in &order {
                for (k, w) in to_words(value(i)).into_iter().enumerate() {
                    words[k].push(w);
                }
            }
            for (k, w) in words.into_iter().enumerate() {
                channels.push(AnyChannel::new(
                    format!("{}.{ch}.w{k}", layer.name).as_str(),
                    FlatSamples::U32(w),
                ));
            }
            if layer.name != "beauty" {
                aov_channel += 1;
            }
        }
    }
    if let Some(p) = &sums.passes {
        let aov = &p.sums;
        if !aov.nearest.is_empty() {
            type Field = fn(&Nearest) -> u32;
            let fields: [(&str, Field); 7] = [
                ("depth", |n| n.z.to_bits()),
                ("sample", |n| n.sample),
                ("px", |n| n.p[0].to_bits()),
                ("py", |n| n.p[1].to_bits()),
                ("pz", |n| n.p[2].to_bits()),
                ("object", |n| n.object),
                ("material", |n| n.material),
            ];
            for (name, f) in fields {
                let v = order.iter().map(|&i| f(&aov.nearest[i])).collect();
                channels.push(AnyChannel::new(
                    format!("nearest.{name}").as_str(),
                    FlatSamples::U32(v),
                ));
            }
        }
        for (kind, counts) in [("object", &aov.objects), ("material", &aov.materials)] {
            if counts.is_empty() {
                continue;
            }
            let most = order.iter().map(|&i| counts[i].len()).max().unwrap_or(0);
            for k in 0..most {
                let at = |i: usize| counts[i].get(k).copied();
                let ids = order
                    .iter()
                    .map(|&i| at(i).map_or(0, |e| e.0 + 1))
                    .collect();
                let ns = order.iter().map(|&i| at(i).map_or(0, |e| e.1)).collect();
                channels.push(AnyChannel::new(
                    format!("coverage.{kind}.id{k}").as_str(),
                    FlatSamples::U32(ids),
                ));
                channels.push(AnyChannel::new(
                    format!("coverage.{kind}.n{k}").as_str(),
                    FlatSamples::U32(ns),
                ));
            }
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
            header
                .layers
                .iter()
                .map(|l| format!("{}:{}:{}", l.name, l.channels.join(","), l.fixed.frac_bits))
                .collect::<Vec<_>>()
                .join(";"),
        ),
        ("lucent.passes", id.passes.clone()),
        ("lucent.names", id.names.clone()),
        ("lucent.output", id.output.clone()),
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
                fixed: FixedPoint {
                    frac_bits: f.parse().ok()?,
                },
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
            passes: get("lucent.passes")?,
            names: get("lucent.names")?,
            output: get("lucent.output")?,
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
    let layout = layout_of(&header.identity).map_err(|(f, e)| bad(path, Some(f), e))?;
    if parse_output(&header.identity.output).is_none() {
        return Err(bad(
            path,
            Some("lucent.output"),
            format!(
                "`{}` is not the frame's file options",
                header.identity.output
            ),
        ));
    }
    let expected = layers_of(layout.as_ref());
    if header.layers != expected {
        let show = |ls: &[LayerFormat]| {
            ls.iter()
                .map(|l| format!("{}:{}:{}", l.name, l.channels.join(","), l.fixed.frac_bits))
                .collect::<Vec<_>>()
                .join(";")
        };
        return Err(bad(
            path,
            Some("lucent.layers"),
            format!(
                "`{layers_text}`, but the passes `{}` sum the layers `{}`",
                header.identity.passes,
                show(&expected)
            ),
        ));
    }
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
    let layout = layout_of(&header.identity).map_err(|(f, e)| bad(path, Some(f), e))?;
    let mut sums = Accumulated::with_passes(r, header.samples.start, layout.as_ref())?;
    sums.done = header.samples.end;
    sums.counters = header.counters;
    let list = &layer.channel_data.list;
    let n = r.area() as usize;
    let channel = |name: &str| -> std::result::Result<&[u32], crate::error::Error> {
        let found = list.iter().find(|a| a.name == Text::new_or_panic(name));
        match found.map(|a| &a.sample_data) {
            Some(FlatSamples::U32(v)) if v.len() == n => Ok(v),
            Some(_) => Err(bad(path, None, format!("channel {name} is not u32 pixels"))),
            None => Err(bad(path, None, format!("channel {name} is missing"))),
        }
    };
    // the region's pixels, row by row: their index in the sums
    let order: Vec<usize> = (r.y0..r.y1)
        .flat_map(|y| (r.x0..r.x1).map(move |x| (x, y)))
        .map(|(x, y)| sums.index(x, y))
        .collect();
    let stride = layout.as_ref().map_or(0, |l| l.stride());
    let mut expected = 0;
    let mut aov_channel = 0;
    for l in &header.layers {
        for ch in &l.channels {
            let mut words: Vec<&[u32]> = Vec::with_capacity(4);
            for k in 0..4 {
                words.push(channel(&format!("{}.{ch}.w{k}", l.name))?);
            }
            expected += 4;
            let c = l.channels.iter().position(|x| x == ch).unwrap_or(0);
            for (j, &i) in order.iter().enumerate() {
                let v = from_words([words[0][j], words[1][j], words[2][j], words[3][j]]);
                if l.name == "beauty" {
                    sums.pixel_at_mut(i)[c] = v;
                } else if let Some(p) = &mut sums.passes {
                    p.sums.sums[i * stride + aov_channel] = v;
                }
            }
            if l.name != "beauty" {
                aov_channel += 1;
            }
        }
    }
    if let Some(p) = &mut sums.passes {
        let aov: &mut AovSums = &mut p.sums;
        if !aov.nearest.is_empty() {
            let f = |k: &str| channel(&format!("nearest.{k}"));
            let (z, s, px, py, pz, o, m) = (
                f("depth")?,
                f("sample")?,
                f("px")?,
                f("py")?,
                f("pz")?,
                f("object")?,
                f("material")?,
            );
            expected += 7;
            for (j, &i) in order.iter().enumerate() {
                aov.nearest[i] = Nearest {
                    z: f32::from_bits(z[j]),
                    sample: s[j],
                    p: [px[j], py[j], pz[j]].map(f32::from_bits),
                    object: o[j],
                    material: m[j],
                };
            }
        }
        for (kind, names, counts) in [
            ("object", p.layout.object_names.len(), &mut aov.objects),
            (
                "material",
                p.layout.material_names.len(),
                &mut aov.materials,
            ),
        ] {
            if counts.is_empty() {
                continue;
            }
            let mut k = 0;
            while list
                .iter()
                .any(|a| a.name == Text::new_or_panic(format!("coverage.{kind}.id{k}").as_str()))
            {
                let ids = channel(&format!("coverage.{kind}.id{k}"))?;
                let ns = channel(&format!("coverage.{kind}.n{k}"))?;
                expected += 2;
                for (j, &i) in order.iter().enumerate() {
                    match (ids[j], ns[j]) {
                        (0, 0) => {}
                        (id, c) if id as usize <= names && c > 0 => {
                            let before = counts[i].last().map(|e| e.0 + 1);
                            if before.is_some_and(|b| b > id - 1) {
                                return Err(bad(
                                    path,
                                    None,
                                    format!("coverage.{kind}: IDs out of order"),
                                ));
                            }
                            counts[i].push((id - 1, c));
                        }
                        _ => {
                            return Err(bad(
                                path,
                                None,
                                format!("coverage.{kind}.id{k}: no such {kind}"),
                            ))
                        }
                    }
                }
                k += 1;
            }
        }
    }
    if list.len() != expected {
        return Err(bad(
            path,
            None,
            format!(
                "{} channels, a part of these layers and passes has {expected}",
                list.len()
            ),
        ));
    }
    Ok((header, sums))
}
