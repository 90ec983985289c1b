//! What a frame's EXR header says about the render that made it: the
//! renderer, its version and build, the scene file and its content hash,
//! the resolution, samples, seed, backend, integrator, sampler, every sampling
//! option, the render plan (JSON, `crate::integrator::plan`), the hosts,
//! the date (`capDate`, `utcOffset`), the camera (`worldToCamera`,
//! `worldToNDC`, the OpenEXR standard attributes) and the render time, as
//! standard OpenEXR attribute types (`string`, `int`, `float`, `v2i`,
//! `m44f`) so `exrheader`, OpenImageIO (`iinfo -v`, `oiiotool --info -v`)
//! and compositors show them. A single render and a merge of its parts
//! write the same fields (the parts carry them, `crate::farm`). The names
//! are listed in `docs/output.md` ("Header attributes").
//!
//! Strings are stored as their UTF-8 bytes (OpenEXR strings are byte
//! strings; OpenImageIO and Nuke read them as UTF-8). The seed is a string
//! of its decimal digits: OpenEXR has no 64-bit integer attribute, and a
//! double would round seeds above 2^53.

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::Vec2;
use serde::{Deserialize, Serialize};

/// The renderer's name, written into `software` with its version.
pub(crate) const RENDERER: &str = "lucent";

/// What the header records about one render. Every field but the
/// resolution (taken from the film) is filled by the caller; `None` and
/// empty fields are left out of the file. Parts carry it (as JSON) so that
/// a merged frame says what a single render says.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FrameHeader {
    /// The scene file as given on the command line.
    pub scene_path: Option<String>,
    /// SHA-256 of the scene file's bytes, lowercase hex.
    pub scene_sha256: Option<String>,
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    pub max_depth: Option<u32>,
    /// The ray-query backend (`embree`, `bvh`) and its version.
    pub backend: Option<String>,
    pub backend_version: Option<String>,
    /// The estimator (`path`, `randomwalk`).
    pub integrator: Option<String>,
    /// The sampler (`sobol`, `random`).
    pub sampler: Option<String>,
    /// Sampling options by material: (material name, `key=value …`).
    pub sampling: Vec<(String, String)>,
    /// The render plan as one line of JSON
    /// (`crate::integrator::plan::Explanation::to_json`).
    pub plan: Option<String>,
    /// Wall time of the render, seconds.
    pub render_seconds: Option<f64>,
    /// When the frame was made, UTC, as `capDate` says it
    /// (`YYYY:MM:DD hh:mm:ss`).
    pub date: Option<String>,
    /// The machines that rendered it (a merge: every part's).
    pub hosts: Vec<String>,
    /// The lucent build ([`crate::session::build_id`]).
    pub build: Option<String>,
    /// The camera: world to camera space (left-handed, +z the view
    /// direction, +y up) and world to NDC (x right, y down, (0, 0) and
    /// (1, 1) the display window's corners after dividing by w), row
    /// vectors times the matrix, as the OpenEXR standard attributes say.
    pub world_to_camera: Option<[f32; 16]>,
    pub world_to_ndc: Option<[f32; 16]>,
}

/// A string attribute value: the UTF-8 bytes of `s`.
pub fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

/// An unsigned count as an `int` attribute when it fits in one, else as a
/// string of its digits.
fn count(n: u64) -> AttributeValue {
    match i32::try_from(n) {
        Ok(i) => AttributeValue::I32(i),
        Err(_) => AttributeValue::Text(text(&n.to_string())),
    }
}

impl FrameHeader {
    /// The header's attributes (name, value) for an image of
    /// `width`×`height` pixels, in name order. `software` is the standard
    /// attribute; the others are under `lucent/`.
    pub fn attributes(&self, width: u32, height: u32) -> Vec<(String, AttributeValue)> {
        let mut a: Vec<(String, AttributeValue)> = Vec::new();
        let mut put = |name: &str, v: AttributeValue| a.push((name.to_string(), v));
        let version = env!("CARGO_PKG_VERSION");
        put(
            "software",
            AttributeValue::Text(text(&format!("{RENDERER} {version}"))),
        );
        put("lucent/version", AttributeValue::Text(text(version)));
        put(
            "lucent/resolution",
            AttributeValue::IntVec2(Vec2(
                i32::try_from(width).unwrap_or(i32::MAX),
                i32::try_from(height).unwrap_or(i32::MAX),
            )),
        );
        let s = |v: &Option<String>| v.as_deref().map(|v| AttributeValue::Text(text(v)));
        let fields = [
            ("lucent/scene", s(&self.scene_path)),
            ("lucent/sceneSha256", s(&self.scene_sha256)),
            ("lucent/spp", self.spp.map(|n| count(n.into()))),
            (
                "lucent/seed",
                self.seed
                    .map(|n| AttributeValue::Text(text(&n.to_string()))),
            ),
            ("lucent/maxDepth", self.max_depth.map(|n| count(n.into()))),
            ("lucent/backend", s(&self.backend)),
            ("lucent/backendVersion", s(&self.backend_version)),
            ("lucent/integrator", s(&self.integrator)),
            ("lucent/sampler", s(&self.sampler)),
            ("lucent/plan", s(&self.plan)),
            ("lucent/build", s(&self.build)),
            ("capDate", s(&self.date)),
            (
                "utcOffset",
                self.date.as_ref().map(|_| AttributeValue::F32(0.0)),
            ),
            (
                "worldToCamera",
                self.world_to_camera.map(AttributeValue::Matrix4x4),
            ),
            (
                "worldToNDC",
                self.world_to_ndc.map(AttributeValue::Matrix4x4),
            ),
            (
                "lucent/renderTime",
                self.render_seconds.map(|t| AttributeValue::F32(t as f32)),
            ),
        ];
        for (name, v) in fields {
            if let Some(v) = v {
                put(name, v);
            }
        }
        if !self.hosts.is_empty() {
            put(
                "lucent/hosts",
                AttributeValue::Text(text(&self.hosts.join(", "))),
            );
        }
        if !self.sampling.is_empty() {
            let joined = self
                .sampling
                .iter()
                .map(|(m, o)| format!("{m}: {o}"))
                .collect::<Vec<_>>()
                .join("; ");
            put("lucent/sampling", AttributeValue::Text(text(&joined)));
        }
        a.sort_by(|x, y| x.0.cmp(&y.0));
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_become_typed_attributes_and_absent_ones_are_left_out() {
        let h = FrameHeader {
            scene_path: Some("scenes/é.toml".into()),
            spp: Some(16),
            seed: Some(u64::MAX),
            sampling: vec![
                ("a".into(), "axes=normal".into()),
                ("b".into(), "axes=mis3".into()),
            ],
            render_seconds: Some(1.5),
            ..FrameHeader::default()
        };
        let a = h.attributes(640, 480);
        let get = |n: &str| a.iter().find(|x| x.0 == n).map(|x| x.1.clone());
        assert_eq!(
            get("lucent/resolution"),
            Some(AttributeValue::IntVec2(Vec2(640, 480)))
        );
        assert_eq!(get("lucent/spp"), Some(AttributeValue::I32(16)));
        assert_eq!(
            get("lucent/seed"),
            Some(AttributeValue::Text(text("18446744073709551615")))
        );
        assert_eq!(get("lucent/renderTime"), Some(AttributeValue::F32(1.5)));
        assert_eq!(
            get("lucent/sampling"),
            Some(AttributeValue::Text(text("a: axes=normal; b: axes=mis3")))
        );
        // UTF-8 bytes, not Latin-1
        assert_eq!(
            get("lucent/scene"),
            Some(AttributeValue::Text(text("scenes/é.toml")))
        );
        assert_eq!(text("é").bytes(), "é".as_bytes());
        assert_eq!(get("lucent/backend"), None);
        assert_eq!(count(1 << 31), AttributeValue::Text(text("2147483648")));
        let names: Vec<&str> = a.iter().map(|x| x.0.as_str()).collect();
        let mut sorted = names.clone();
        sorted.sort();
        assert_eq!(names, sorted);
    }
}
