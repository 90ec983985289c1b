//! A part's header: the frame it belongs to ([`Identity`]), the pixels and
//! samples it sums, its layers and tallies ([`Header`]). Each field is one
//! EXR text attribute `lucent.<field>` holding the field's JSON (serde; a
//! text field as its text), read back one field at a time so that a bad
//! one is named; `lucent.format` and `lucent.format_version` say what the
//! file is. docs/farm.md, "Parts".

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::error::{Error, InputError};
use crate::film::accumulate::FixedPoint;
use crate::film::exr_attributes::FrameHeader;
use crate::film::exr_layers::{ExrCompression, OutputOptions, Precision};
use crate::film::pass_layout::Layout;
use crate::film::passes::PassSet;
use crate::film::region::Region;
use crate::film::Sums;
use crate::stats::Counters;

/// The part format this build writes and reads.
pub const FORMAT_VERSION: u32 = 4;

/// What `lucent.format` says of a part.
const FORMAT: &str = "lucent-part";

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
    /// Its attributes, in the order a difference is reported.
    fn attributes(&self) -> [(&'static str, String); 9] {
        [
            ("lucent.version", text(&self.version)),
            ("lucent.scene_hash", text(&self.scene_hash)),
            ("lucent.seed", text(&self.seed)),
            ("lucent.spp", text(&self.spp)),
            ("lucent.options", text(&self.options)),
            ("lucent.frame", text(&self.frame)),
            ("lucent.passes", text(&self.passes)),
            ("lucent.names", text(&self.names)),
            ("lucent.output", text(&self.output)),
        ]
    }

    /// The identity with the backend of its options (`accel=…`) left out:
    /// what parts rendered on different backends share (`lucent merge
    /// --mixed-backends`).
    pub fn without_backend(&self) -> Identity {
        let options = self
            .options
            .split(' ')
            .map(|t| {
                if t.starts_with("accel=") {
                    "accel=*"
                } else {
                    t
                }
            })
            .collect::<Vec<_>>()
            .join(" ");
        Identity {
            options,
            ..self.clone()
        }
    }

    /// The first field in which `self` and `o` differ: its attribute name,
    /// and the two values.
    pub fn difference(&self, o: &Identity) -> Option<(&'static str, String, String)> {
        self.attributes()
            .into_iter()
            .zip(o.attributes())
            .find(|((_, a), (_, b))| a != b)
            .map(|((field, a), (_, b))| (field, a, b))
    }

    /// The identity `attrs` say.
    fn read(attrs: &Attributes) -> Result<Identity, Error> {
        Ok(Identity {
            version: attrs.get("lucent.version")?,
            scene_hash: attrs.get("lucent.scene_hash")?,
            seed: attrs.get("lucent.seed")?,
            spp: attrs.get("lucent.spp")?,
            options: attrs.get("lucent.options")?,
            frame: attrs.get("lucent.frame")?,
            passes: attrs.get("lucent.passes")?,
            names: attrs.get("lucent.names")?,
            output: attrs.get("lucent.output")?,
        })
    }
}

/// A layer of summed channels.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerFormat {
    pub name: String,
    pub channels: Vec<String>,
    #[serde(rename = "frac_bits")]
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
    /// What the frame's EXR header is to say of the render (its scene,
    /// backend, plan, camera, …; no date or render time), with this part's
    /// host: a merge writes it, so a merged frame says what a single render
    /// says. Empty in a part of a build that did not record it.
    pub frame: FrameHeader,
}

impl Header {
    /// Its EXR text attributes: (name, text).
    pub fn attributes(&self) -> Vec<(&'static str, String)> {
        let mut v = vec![
            ("lucent.format", FORMAT.to_string()),
            ("lucent.format_version", text(&FORMAT_VERSION)),
        ];
        v.extend(self.identity.attributes());
        v.extend([
            ("lucent.scene", text(&self.scene)),
            ("lucent.region", text(&self.region)),
            ("lucent.samples", text(&self.samples)),
            ("lucent.requested", text(&self.requested)),
            ("lucent.layers", text(&self.layers)),
            ("lucent.counters", text(&self.counters)),
            ("lucent.provenance", ascii(text(&self.frame))),
        ]);
        v
    }

    /// The header of the part at `path` whose EXR layer has the attributes
    /// `attrs`, checked to be one this build reads and consistent.
    pub fn read(path: &Path, attrs: &HashMap<Text, AttributeValue>) -> Result<Header, Error> {
        let attrs = Attributes { path, attrs };
        attrs.check_format()?;
        let header = Header {
            identity: Identity::read(&attrs)?,
            scene: attrs.get("lucent.scene")?,
            region: attrs.get("lucent.region")?,
            samples: attrs.get("lucent.samples")?,
            requested: attrs.get("lucent.requested")?,
            layers: attrs.get("lucent.layers")?,
            counters: attrs.get("lucent.counters")?,
            frame: match attrs
                .attrs
                .contains_key(&Text::new_or_panic("lucent.provenance"))
            {
                true => attrs.get("lucent.provenance")?,
                false => FrameHeader::default(),
            },
        };
        header.check().map_err(|e| e.at(path))?;
        Ok(header)
    }

    /// Whether the fields agree with each other: the layers are those the
    /// passes sum, the region lies in the frame, the samples in `0..spp`.
    fn check(&self) -> Result<(), FieldError> {
        let id = &self.identity;
        let layout = layout_of(id)?;
        if parse_output(&id.output).is_none() {
            let problem = format!("`{}` is not the frame's file options", id.output);
            return Err(FieldError::new("lucent.output", problem));
        }
        let expected = layers_of(layout.as_ref());
        if self.layers != expected {
            let problem = format!(
                "`{}`, but the passes `{}` sum the layers `{}`",
                text(&self.layers),
                id.passes,
                text(&expected)
            );
            return Err(FieldError::new("lucent.layers", problem));
        }
        let (w, h) = id.frame;
        let r = self.region;
        if r.is_empty() || !r.within(&Region::full(w, h)) {
            let problem = format!("{r} is not a region inside the {w}×{h} frame");
            return Err(FieldError::new("lucent.region", problem));
        }
        let (s, q) = (&self.samples, &self.requested);
        if s.start > s.end
            || q.start > q.end
            || s.end > id.spp
            || q.end > id.spp
            || s.start != q.start
        {
            let problem = format!(
                "samples {}..{} (asked {}..{}) do not fit 0..{}",
                s.start, s.end, q.start, q.end, id.spp
            );
            return Err(FieldError::new("lucent.samples", problem));
        }
        Ok(())
    }
}

/// A part's EXR attributes, read one field at a time.
struct Attributes<'a> {
    path: &'a Path,
    attrs: &'a HashMap<Text, AttributeValue>,
}

impl Attributes<'_> {
    /// The text of attribute `k`.
    fn text(&self, k: &'static str) -> Result<String, Error> {
        match self.attrs.get(&Text::new_or_panic(k)) {
            Some(AttributeValue::Text(t)) => Ok(t.to_string()),
            Some(_) => Err(bad(self.path, Some(k), "is not text")),
            None => Err(bad(self.path, Some(k), "is missing")),
        }
    }

    /// The field of attribute `k`: its text if `T` is text, else its JSON.
    fn get<T: DeserializeOwned>(&self, k: &'static str) -> Result<T, Error> {
        let raw = self.text(k)?;
        T::deserialize(Value::String(raw.clone()))
            .or_else(|_| serde_json::from_str(&raw))
            .map_err(|e| bad(self.path, Some(k), format!("`{}`: {e}", shown(&raw))))
    }

    /// That the file is a part of the format this build reads.
    fn check_format(&self) -> Result<(), Error> {
        if !matches!(self.text("lucent.format"), Ok(f) if f == FORMAT) {
            return Err(bad(
                self.path,
                None,
                "not a lucent part (no `lucent.format = lucent-part` header attribute): \
                 merge takes the parts `lucent render --crop/--tile/--samples` writes",
            ));
        }
        let version: u64 = self.get("lucent.format_version")?;
        if version != FORMAT_VERSION as u64 {
            return Err(bad(
                self.path,
                Some("lucent.format_version"),
                format!("part format {version}, this lucent reads format {FORMAT_VERSION}"),
            ));
        }
        Ok(())
    }
}

/// `text` as a message quotes it: at most 200 characters, then how many
/// more there are (a forged 100 kB field makes a short message).
fn shown(text: &str) -> String {
    match text.char_indices().nth(200) {
        None => text.to_string(),
        Some((at, _)) => format!(
            "{}… ({} more characters)",
            &text[..at],
            text[at..].chars().count()
        ),
    }
}

/// A field's attribute text: the text of a text field, else its JSON.
fn text<T: Serialize>(v: &T) -> String {
    match serde_json::to_value(v).expect("header fields are plain data") {
        Value::String(s) => s,
        v => v.to_string(),
    }
}

/// A bad part: the file, the attribute (when one is at fault), the problem.
pub fn bad(path: &Path, field: Option<&str>, problem: impl Into<String>) -> Error {
    let e = InputError::new(path, problem);
    match field {
        Some(f) => e.in_field(f).into(),
        None => e.into(),
    }
}

/// What is wrong with a field of a part's header, before the file is known.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct FieldError {
    /// The attribute at fault.
    pub field: &'static str,
    pub problem: String,
}

impl FieldError {
    pub fn new(field: &'static str, problem: impl Into<String>) -> FieldError {
        FieldError {
            field,
            problem: problem.into(),
        }
    }

    /// The error located in the part at `path`.
    pub fn at(self, path: &Path) -> Error {
        bad(path, Some(self.field), self.problem)
    }
}

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

/// The names a layout uses, as `lucent.names` holds them.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Names {
    groups: Vec<String>,
    objects: Vec<String>,
    materials: Vec<String>,
}

/// The names `layout` uses, as `lucent.names` says them: JSON, non-ASCII
/// characters escaped (EXR text is bytes).
pub fn names_text(layout: Option<&Layout>) -> String {
    let Some(l) = layout else {
        return String::new();
    };
    let names = Names {
        groups: l.groups.clone(),
        objects: l.object_names.clone(),
        materials: l.material_names.clone(),
    };
    ascii(text(&names))
}

/// JSON text with its non-ASCII characters escaped (`\uXXXX`; EXR text is
/// bytes): the same JSON value.
fn ascii(json: String) -> String {
    let mut out = String::new();
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
        "precision={} compression={} split={} ranks={}{}",
        o.precision.name(),
        o.compression.name(),
        o.split,
        o.cryptomatte_ranks,
        // said only when on: an opaque film's text is what it always was
        if o.transparent {
            " transparent=true"
        } else {
            ""
        }
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
            "transparent" if v == "true" && seen == 4 => {
                o.transparent = true;
                seen += 1;
                continue;
            }
            _ => return None,
        }
        seen += 1;
        if seen > 4 {
            return None;
        }
    }
    (seen == 4 || (seen == 5 && o.transparent)).then_some(o)
}

/// The layout a part's identity describes (None: no passes).
pub fn layout_of(id: &Identity) -> Result<Option<Layout>, FieldError> {
    if id.passes.is_empty() {
        return Ok(None);
    }
    let passes = PassSet::parse_list(&id.passes)
        .map_err(|e| FieldError::new("lucent.passes", e.problem()))?;
    let names: Names = serde_json::from_str(&id.names)
        .map_err(|e| FieldError::new("lucent.names", format!("not the JSON of names: {e}")))?;
    Ok(Some(Layout::new(
        passes,
        &names.groups,
        &names.objects,
        &names.materials,
    )))
}

/// The beauty layer every part has.
pub fn beauty_layer() -> LayerFormat {
    LayerFormat {
        name: "beauty".into(),
        channels: vec!["R".into(), "G".into(), "B".into()],
        fixed: Sums::FORMAT,
    }
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

/// Parses `A..B` with A < B (the `--samples` option's form).
pub fn parse_samples(s: &str) -> Option<Range<u32>> {
    let (a, b) = s.split_once("..")?;
    let (a, b): (u32, u32) = (a.trim().parse().ok()?, b.trim().parse().ok()?);
    (a < b).then_some(a..b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Header {
        Header {
            identity: Identity {
                version: "1.0".into(),
                scene_hash: "00ff".into(),
                seed: 7,
                spp: 4,
                options: "accel=bvh".into(),
                frame: (8, 6),
                passes: String::new(),
                names: String::new(),
                output: output_text(&OutputOptions::default()),
            },
            scene: "scene.toml".into(),
            region: Region {
                x0: 0,
                y0: 2,
                x1: 8,
                y1: 6,
            },
            samples: 1..3,
            requested: 1..4,
            layers: layers_of(None),
            counters: Counters {
                rays: 5,
                clamped: 1,
                ..Counters::default()
            },
            frame: FrameHeader {
                scene_path: Some("scènes/a.toml".into()),
                backend: Some("embree4".into()),
                hosts: vec!["node-7".into()],
                world_to_camera: Some([0.5; 16]),
                ..FrameHeader::default()
            },
        }
    }

    fn exr_attributes(h: &Header) -> HashMap<Text, AttributeValue> {
        h.attributes()
            .into_iter()
            .map(|(k, v)| {
                (
                    Text::new_or_panic(k),
                    AttributeValue::Text(Text::new_or_panic(v.as_str())),
                )
            })
            .collect()
    }

    /// Text fields are read as text even when they would parse as JSON (a
    /// number, a quoted string): read as JSON, they would change or fail.
    #[test]
    fn a_header_reads_back_as_written_even_text_that_looks_like_json() {
        let mut h = header();
        h.identity.scene_hash = "1234".into();
        h.scene = "\"quoted\"".into();
        let back = Header::read(Path::new("p.exr"), &exr_attributes(&h)).unwrap();
        assert_eq!(back, h);
    }

    /// Every bad field is named with the file, whether its JSON does not
    /// parse, is missing a member, or disagrees with another field.
    #[test]
    fn a_bad_field_names_the_file_and_the_field() {
        for (field, text) in [
            ("lucent.seed", "seven"),
            ("lucent.frame", "[8]"),
            ("lucent.region", r#"{"x0":0,"y0":0,"x1":9,"y1":6}"#),
            ("lucent.samples", r#"{"start":0,"end":3}"#),
            ("lucent.counters", r#"{"rays":1}"#),
            ("lucent.layers", "[]"),
            ("lucent.output", "precision=full"),
            ("lucent.format_version", "2"),
        ] {
            let mut attrs = exr_attributes(&header());
            let value = AttributeValue::Text(Text::new_or_panic(text));
            attrs.insert(Text::new_or_panic(field), value);
            let e = Header::read(Path::new("p.exr"), &attrs)
                .unwrap_err()
                .to_string();
            assert!(e.contains("p.exr") && e.contains(field), "{field}: {e}");
        }
        let mut attrs = exr_attributes(&header());
        attrs.remove(&Text::new_or_panic("lucent.spp"));
        let e = Header::read(Path::new("p.exr"), &attrs)
            .unwrap_err()
            .to_string();
        assert!(e.contains("lucent.spp") && e.contains("missing"), "{e}");
    }

    /// The first differing field is reported in the identity's order, so
    /// parts with other passes name the passes, not the names they imply.
    #[test]
    fn a_difference_names_the_first_field_in_order() {
        let (a, mut b) = (header().identity, header().identity);
        assert_eq!(a.difference(&b), None);
        b.passes = "Z".into();
        b.names = "{}".into();
        let (field, ours, theirs) = a.difference(&b).unwrap();
        assert_eq!(
            (field, ours.as_str(), theirs.as_str()),
            ("lucent.passes", "", "Z")
        );
    }
}
