//! Serde structures of the TOML scene format (`docs/scene-format.md`).
//!
//! These types only describe the *shape* of a scene file: every table
//! rejects unknown keys, and every value that [`super::load()`] validates
//! afterwards is wrapped in [`Spanned`] so a rejected value can be reported
//! with its line. Range checks, name resolution and conversion to a
//! [`super::Scene`] live in the loader (`load.rs` and the files it uses).
//!
//! Keys the format requires are `Option`s here too: the loader reports a
//! missing one at its table's span, as data, rather than reading the key
//! back out of serde's "missing field" message.
//!
//! Materials and shapes are flat tables with a `type` key rather than serde
//! internally-tagged enums: serde buffers internally-tagged content, which
//! throws the spans away. Instead each table lists the union of the keys of
//! its types, and `load.rs` checks that only the keys of the given `type`
//! are present. A new material type is one more [`MaterialKind`] variant,
//! its keys here, and one more match arm in the loader.

use std::collections::BTreeMap;
use std::fmt;
use std::ops::Range;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
pub use toml::Spanned;

/// Three numbers: a point, a direction or an RGB triple.
pub(crate) type Triple = [f64; 3];

/// Exactly `N` numbers, as a TOML array: unlike serde's `[T; N]`, which
/// stops reading after `N` elements and ignores the rest, a wrong length is
/// rejected ("expected 3 numbers, found 4"). Derefs to the array.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Numbers<T, const N: usize>(pub [T; N]);

/// A [`Triple`] as written in the file: exactly three numbers.
pub(crate) type Triple3 = Numbers<f64, 3>;

impl<T, const N: usize> std::ops::Deref for Numbers<T, N> {
    type Target = [T; N];
    fn deref(&self) -> &[T; N] {
        &self.0
    }
}

impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Deserialize<'de> for Numbers<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T, const N: usize>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Copy + Default, const N: usize> Visitor<'de> for V<T, N> {
            type Value = Numbers<T, N>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an array of {N} numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                let out = exactly::<A, T, N>(seq, &format!("{N} numbers"))?;
                Ok(Numbers(out))
            }
        }
        d.deserialize_seq(V::<T, N>(std::marker::PhantomData))
    }
}

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene units per millimetre (subsurface parameters are in mm).
    pub units_per_mm: Option<Spanned<f64>>,
    /// Required.
    pub camera: Option<Spanned<CameraDef>>,
    #[serde(default)]
    pub render: RenderDef,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDef>>,
    #[serde(default)]
    pub shapes: Vec<Spanned<ShapeDef>>,
    pub environment: Option<Spanned<EnvironmentDef>>,
    /// `[[lights]]`: sphere, spot and distant lights.
    #[serde(default)]
    pub lights: Vec<Spanned<LightDef>>,
    #[serde(default)]
    pub output: OutputDef,
    /// Image textures by name, read once and shared by the materials that
    /// name them.
    #[serde(default)]
    pub textures: BTreeMap<String, Spanned<TextureDef>>,
}

/// `[textures.NAME]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureDef {
    /// A PNG, OpenEXR or Radiance `.hdr` image, relative to the scene
    /// file's directory. Required.
    pub file: Option<Spanned<String>>,
    /// `"srgb"` (the default) or `"linear"`: how PNG values are decoded.
    pub color_space: Option<Spanned<String>>,
    /// `"repeat"` (the default) or `"clamp"`.
    pub wrap: Option<Spanned<String>>,
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    /// Required.
    pub look_from: Option<Spanned<Triple3>>,
    /// Required.
    pub look_at: Option<Spanned<Triple3>>,
    pub up: Option<Spanned<Triple3>>,
    /// Vertical field of view in degrees.
    pub fov_y: Option<Spanned<f64>>,
    /// `[width, height]` in pixels. Required.
    pub resolution: Option<Spanned<Numbers<u32, 2>>>,
    // The thin lens (none of these: a pinhole).
    /// Aperture radius in scene units.
    pub aperture_radius: Option<Spanned<f64>>,
    /// Aperture as an f-number of a 35 mm film camera of this `fov_y`.
    pub f_number: Option<Spanned<f64>>,
    /// Distance to the plane in focus, scene units.
    pub focus_distance: Option<Spanned<f64>>,
}

/// `[render]`; every key is optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDef {
    pub spp: Option<Spanned<u32>>,
    pub max_depth: Option<Spanned<u32>>,
    pub seed: Option<u64>,
    /// `"fast"` or `"watertight"` (`crate::accel::Traversal`).
    pub traversal: Option<Spanned<String>>,
    /// `"sobol"` or `"random"` (`crate::sampling::SamplerKind`).
    pub sampler: Option<Spanned<String>>,
}

/// `[output]`: the passes and how the frame is stored; every key is
/// optional (the CLI's options override them).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputDef {
    /// Pass names (`crate::film::passes`), as `--aov` takes them.
    pub aovs: Option<Vec<Spanned<String>>>,
    /// `"half"` or `"float"`: light passes' precision.
    pub aov_precision: Option<Spanned<String>>,
    /// A lossless EXR compression name.
    pub exr_compression: Option<Spanned<String>>,
    /// One file per pass.
    pub aov_split: Option<bool>,
    /// Cryptomatte ranks per pixel.
    pub cryptomatte_ranks: Option<Spanned<u32>>,
    /// A transparent film.
    pub transparent: Option<bool>,
}

/// `[environment]`: a constant `radiance`, or an image `file` with its
/// `rotation`, `intensity` and `exposure` (exactly one of the two forms).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDef {
    pub radiance: Option<Spanned<Triple3>>,
    /// The light group of the environment's light (`RGBA_<group>` pass).
    pub light_group: Option<Spanned<String>>,
    // The image form.
    /// A latitude-longitude OpenEXR or Radiance `.hdr` image, relative to
    /// the scene file's directory.
    pub file: Option<Spanned<String>>,
    /// Degrees about +y (counter-clockwise seen from above).
    pub rotation: Option<Spanned<f64>>,
    /// A factor on the texels.
    pub intensity: Option<Spanned<f64>>,
    /// Stops: a further factor 2^exposure.
    pub exposure: Option<Spanned<f64>>,
}

/// The `type` of a `[[lights]]` entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Sphere,
    Distant,
}

/// One `[[lights]]` entry: the keys of both types (which a `type`
/// accepts is checked by the loader).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDef {
    /// Required.
    #[serde(rename = "type")]
    pub kind: Option<Spanned<LightKind>>,
    /// Radiance L (sphere; distant with an `angle` > 0).
    pub radiance: Option<Spanned<Triple3>>,
    /// The light group (`RGBA_<group>` pass).
    pub light_group: Option<Spanned<String>>,
    // sphere
    pub position: Option<Spanned<Triple3>>,
    pub radius: Option<Spanned<f64>>,
    /// Emitted power in W per channel.
    pub power: Option<Spanned<Triple3>>,
    /// The spot cone's axis (the direction its light travels).
    pub spot_direction: Option<Spanned<Triple3>>,
    /// The spot cone's half-angle, degrees.
    pub spot_angle: Option<Spanned<f64>>,
    /// The width of the spot's soft edge inside the cone, degrees.
    pub spot_falloff: Option<Spanned<f64>>,
    // distant
    /// The direction the light travels (from the light into the scene).
    pub direction: Option<Spanned<Triple3>>,
    /// Angular diameter, degrees.
    pub angle: Option<Spanned<f64>>,
    /// W/m² on a surface facing the light, per channel.
    pub irradiance: Option<Spanned<Triple3>>,
}

impl LightDef {
    /// The type-specific keys that are present, with their spans.
    pub(crate) fn present_type_keys(&self) -> Vec<(&'static str, Range<usize>)> {
        let mut v = Vec::new();
        let mut key = |name, span: Option<Range<usize>>| {
            if let Some(s) = span {
                v.push((name, s));
            }
        };
        key("position", self.position.as_ref().map(|x| x.span()));
        key("radius", self.radius.as_ref().map(|x| x.span()));
        key("power", self.power.as_ref().map(|x| x.span()));
        key(
            "spot_direction",
            self.spot_direction.as_ref().map(|x| x.span()),
        );
        key("spot_angle", self.spot_angle.as_ref().map(|x| x.span()));
        key("spot_falloff", self.spot_falloff.as_ref().map(|x| x.span()));
        key("direction", self.direction.as_ref().map(|x| x.span()));
        key("angle", self.angle.as_ref().map(|x| x.span()));
        key("irradiance", self.irradiance.as_ref().map(|x| x.span()));
        v
    }
}

/// The `type` of a `[materials.NAME]` table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MaterialKind {
    Diffuse,
    Dielectric,
    Subsurface,
    Conductor,
    Plastic,
}

impl MaterialKind {
    pub fn name(self) -> &'static str {
        match self {
            MaterialKind::Diffuse => "diffuse",
            MaterialKind::Dielectric => "dielectric",
            MaterialKind::Subsurface => "subsurface",
            MaterialKind::Conductor => "conductor",
            MaterialKind::Plastic => "plastic",
        }
    }
}

/// `[materials.NAME]`: the keys of all material types; which of them a
/// given `type` accepts is checked by the loader.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDef {
    /// Required.
    #[serde(rename = "type")]
    pub kind: Option<Spanned<MaterialKind>>,
    pub albedo: Option<Spanned<Triple3>>,
    /// A texture's name: the diffuse albedo (times `albedo`, if given).
    pub albedo_texture: Option<Spanned<String>>,
    /// A texture's name: a tangent-space normal map.
    pub normal_map: Option<Spanned<String>>,
    /// A texture's name: a height map whose slopes tilt the shading normal.
    pub bump: Option<Spanned<String>>,
    /// The height, in scene units, of a bump texel of value 1.
    pub bump_scale: Option<Spanned<f64>>,
    /// A texture's name: the roughness of a conductor, rough dielectric,
    /// plastic coat or subsurface coat (times `roughness`, if given).
    pub roughness_texture: Option<Spanned<String>>,
    pub eta: Option<Spanned<f64>>,
    // subsurface: parameters (one of three forms)
    pub preset: Option<Spanned<String>>,
    pub sigma_s_prime: Option<Spanned<Triple3>>,
    pub sigma_a: Option<Spanned<Triple3>>,
    pub g: Option<Spanned<f64>>,
    pub dmfp: Option<Spanned<Triple3>>,
    /// A texture's name: a factor per channel on a subsurface medium's
    /// lengths (`dmfp`, or a preset's or measured medium's).
    pub dmfp_texture: Option<Spanned<String>>,
    pub fit: Option<Spanned<String>>,
    pub albedo_source: Option<Spanned<String>>,
    // subsurface: sampling options
    pub radius: Option<Spanned<String>>,
    pub rmax_quantile: Option<Spanned<f64>>,
    pub axes: Option<Spanned<String>>,
    pub channel: Option<Spanned<String>>,
    pub renormalize: Option<Spanned<bool>>,
    pub exit_sw: Option<Spanned<bool>>,
    pub specular: Option<Spanned<bool>>,
    // subsurface: the random walk's boundary model
    pub boundary: Option<Spanned<String>>,
    // subsurface: the diffusion weight's curvature correction
    pub curvature_correction: Option<Spanned<String>>,
    pub roughness: Option<Spanned<f64>>,
    // subsurface: level of detail
    pub lod: Option<Spanned<String>>,
    pub lod_threshold: Option<Spanned<f64>>,
    // subsurface: variance reduction at the camera vertex
    pub control_variate: Option<Spanned<bool>>,
    pub probe_pair: Option<Spanned<bool>>,
    pub pair_paths: Option<Spanned<i64>>,
    // subsurface: the coat's least roughness after a non-specular vertex
    pub regularize: Option<Spanned<f64>>,
    // subsurface: the diffusion profile's shape
    pub profile: Option<Spanned<String>>,
    // subsurface: the accuracy budget
    pub accuracy: Option<Spanned<f64>>,
    // conductor: a named metal, or its complex index n + ik per channel
    // (`roughness` above serves the conductor, plastic and dielectric too)
    pub metal: Option<Spanned<String>>,
    pub n: Option<Spanned<Triple3>>,
    pub k: Option<Spanned<Triple3>>,
}

impl MaterialDef {
    /// The optional keys that are present, with their spans.
    pub(crate) fn present_keys(&self) -> Vec<(&'static str, Range<usize>)> {
        let mut v = Vec::new();
        let mut add = |k: &'static str, span: Option<Range<usize>>| {
            if let Some(span) = span {
                v.push((k, span));
            }
        };
        add("albedo", self.albedo.as_ref().map(|x| x.span()));
        add(
            "albedo_texture",
            self.albedo_texture.as_ref().map(|x| x.span()),
        );
        add("normal_map", self.normal_map.as_ref().map(|x| x.span()));
        add("bump", self.bump.as_ref().map(|x| x.span()));
        add("bump_scale", self.bump_scale.as_ref().map(|x| x.span()));
        add(
            "roughness_texture",
            self.roughness_texture.as_ref().map(|x| x.span()),
        );
        add("dmfp_texture", self.dmfp_texture.as_ref().map(|x| x.span()));
        add("metal", self.metal.as_ref().map(|x| x.span()));
        add("n", self.n.as_ref().map(|x| x.span()));
        add("k", self.k.as_ref().map(|x| x.span()));
        add("eta", self.eta.as_ref().map(|x| x.span()));
        add("preset", self.preset.as_ref().map(|x| x.span()));
        add(
            "sigma_s_prime",
            self.sigma_s_prime.as_ref().map(|x| x.span()),
        );
        add("sigma_a", self.sigma_a.as_ref().map(|x| x.span()));
        add("g", self.g.as_ref().map(|x| x.span()));
        add("dmfp", self.dmfp.as_ref().map(|x| x.span()));
        add("fit", self.fit.as_ref().map(|x| x.span()));
        add(
            "albedo_source",
            self.albedo_source.as_ref().map(|x| x.span()),
        );
        add("radius", self.radius.as_ref().map(|x| x.span()));
        add(
            "rmax_quantile",
            self.rmax_quantile.as_ref().map(|x| x.span()),
        );
        add("axes", self.axes.as_ref().map(|x| x.span()));
        add("channel", self.channel.as_ref().map(|x| x.span()));
        add("renormalize", self.renormalize.as_ref().map(|x| x.span()));
        add("exit_sw", self.exit_sw.as_ref().map(|x| x.span()));
        add("specular", self.specular.as_ref().map(|x| x.span()));
        add("boundary", self.boundary.as_ref().map(|x| x.span()));
        add("accuracy", self.accuracy.as_ref().map(|x| x.span()));
        add(
            "curvature_correction",
            self.curvature_correction.as_ref().map(|x| x.span()),
        );
        add("roughness", self.roughness.as_ref().map(|x| x.span()));
        add("lod", self.lod.as_ref().map(|x| x.span()));
        add(
            "lod_threshold",
            self.lod_threshold.as_ref().map(|x| x.span()),
        );
        add(
            "control_variate",
            self.control_variate.as_ref().map(|x| x.span()),
        );
        add("probe_pair", self.probe_pair.as_ref().map(|x| x.span()));
        add("pair_paths", self.pair_paths.as_ref().map(|x| x.span()));
        add("regularize", self.regularize.as_ref().map(|x| x.span()));
        add("profile", self.profile.as_ref().map(|x| x.span()));
        v
    }
}

/// The `type` of a `[[shapes]]` entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    Obj,
    Sphere,
    Quad,
    Box,
}

impl ShapeKind {
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Obj => "obj",
            ShapeKind::Sphere => "sphere",
            ShapeKind::Quad => "quad",
            ShapeKind::Box => "box",
        }
    }
}

/// One `[[shapes]]` entry: the keys of all shape types (type-specific ones
/// checked by the loader) plus the common material, emission, name and
/// transform.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeDef {
    /// Required.
    #[serde(rename = "type")]
    pub kind: Option<Spanned<ShapeKind>>,
    pub name: Option<String>,
    /// `obj`: path of the OBJ file, relative to the scene file's directory.
    pub file: Option<Spanned<String>>,
    /// `obj`: compute smooth (area-weighted) vertex normals when the file
    /// has none.
    pub smooth: Option<Spanned<bool>>,
    /// `obj` taking its materials from its MTL: what the `map_Bump` /
    /// `bump` images are, `"height"` (the MTL format's meaning, the
    /// default) or `"normal"` (what some exporters write there).
    pub map_bump: Option<Spanned<String>>,
    /// `sphere`: icosphere subdivision level.
    pub subdivisions: Option<Spanned<u32>>,
    /// The material's name. Required.
    pub material: Option<Spanned<String>>,
    pub emission: Option<Spanned<Triple3>>,
    /// Emitted power in W per channel: the other form of `emission`.
    pub power: Option<Spanned<Triple3>>,
    /// The light group of an emitter (`RGBA_<group>` pass).
    pub light_group: Option<Spanned<String>>,
    pub scale: Option<Spanned<Scale>>,
    pub rotate: Option<Vec<Spanned<Rotation>>>,
    pub translate: Option<Spanned<Triple3>>,
}

impl ShapeDef {
    /// The type-specific keys that are present, with their spans.
    pub(crate) fn present_type_keys(&self) -> Vec<(&'static str, Range<usize>)> {
        let mut v = Vec::new();
        if let Some(x) = &self.file {
            v.push(("file", x.span()));
        }
        if let Some(x) = &self.smooth {
            v.push(("smooth", x.span()));
        }
        if let Some(x) = &self.map_bump {
            v.push(("map_bump", x.span()));
        }
        if let Some(x) = &self.subdivisions {
            v.push(("subdivisions", x.span()));
        }
        v
    }
}

/// `scale`: one number (uniform) or `[x, y, z]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale(pub Triple);

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Scale;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or an array [x, y, z] of 3 numbers")
            }
            fn visit_f64<E: de::Error>(self, s: f64) -> Result<Scale, E> {
                Ok(Scale([s; 3]))
            }
            fn visit_i64<E: de::Error>(self, s: i64) -> Result<Scale, E> {
                Ok(Scale([s as f64; 3]))
            }
            fn visit_u64<E: de::Error>(self, s: u64) -> Result<Scale, E> {
                Ok(Scale([s as f64; 3]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Scale, A::Error> {
                let [x, y, z] = numbers::<A, 3>(seq, "an array [x, y, z] of 3 numbers")?;
                Ok(Scale([x, y, z]))
            }
        }
        d.deserialize_any(V)
    }
}

/// One rotation of `rotate`: `[angle_degrees, axis_x, axis_y, axis_z]`,
/// counter-clockwise about the axis (right-hand rule).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation {
    pub angle_deg: f64,
    pub axis: Triple,
}

impl<'de> Deserialize<'de> for Rotation {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Rotation;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a rotation [angle_degrees, axis_x, axis_y, axis_z]")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Rotation, A::Error> {
                let [a, x, y, z] = numbers::<A, 4>(
                    seq,
                    "a rotation [angle_degrees, axis_x, axis_y, axis_z] of 4 numbers",
                )?;
                Ok(Rotation {
                    angle_deg: a,
                    axis: [x, y, z],
                })
            }
        }
        d.deserialize_seq(V)
    }
}

/// Reads exactly `N` numbers from `seq` for a `scale` or `rotate` entry;
/// a wrong length is reported as "expected `what`, found M".
fn numbers<'de, A: SeqAccess<'de>, const N: usize>(
    seq: A,
    what: &str,
) -> Result<[f64; N], A::Error> {
    exactly::<A, f64, N>(seq, what)
}

/// Reads exactly `N` elements from `seq`; any other length is an error
/// "expected `what`, found M" that counts every element given.
fn exactly<'de, A: SeqAccess<'de>, T: Deserialize<'de> + Copy + Default, const N: usize>(
    mut seq: A,
    what: &str,
) -> Result<[T; N], A::Error> {
    let mut out = [T::default(); N];
    let mut found = 0;
    while found < N {
        match seq.next_element()? {
            Some(v) => out[found] = v,
            None => break,
        }
        found += 1;
    }
    if found == N {
        while seq.next_element::<de::IgnoredAny>()?.is_some() {
            found += 1;
        }
    }
    if found != N {
        return Err(de::Error::custom(format_args!(
            "expected {what}, found {found}"
        )));
    }
    Ok(out)
}
