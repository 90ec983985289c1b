//! Scene loading and validation: TOML text → [`super::format::SceneFile`] →
//! checked values → [`Scene`].
//!
//! Every failure is a [`SceneError`] that names the file, the line whenever
//! the input has one, and the field (a dotted key path such as
//! `shapes[2].material`). Nothing here panics on user input: OBJ files are
//! checked line by line before `tobj` sees them (it can index out of bounds
//! or overflow on bad face indices), and the `tobj` call is additionally
//! fenced with `catch_unwind`.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use super::format::{MaterialDef, MaterialKind, SceneFile, ShapeDef, ShapeKind, Spanned, Triple};
use super::transform::Transform;
use super::{shapes, Camera, Object, RenderSettings, Scene, SceneError};
use crate::geometry::{Mesh, Vec3};
use crate::materials::{Material, Subsurface};

/// Highest accepted `subdivisions` for spheres: 20·4⁹ ≈ 5.2 M triangles.
pub const MAX_SPHERE_SUBDIVISIONS: u32 = 9;
/// Largest accepted image side, in pixels.
pub const MAX_RESOLUTION: u32 = 16384;

/// Reads and loads the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::new(path, format!("cannot read scene file: {e}")))?;
    load_str(&text, path)
}

/// Loads a scene from `text`; `path` names it in errors and is where
/// relative OBJ paths are resolved from (its directory).
pub fn load_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let cx = Cx { file: path, text };
    let def: SceneFile = toml::from_str(text).map_err(|e| cx.toml_error(&e))?;
    build(&cx, def)
}

/// The scene file being loaded, for locating errors.
struct Cx<'a> {
    file: &'a Path,
    text: &'a str,
}

type Res<T> = Result<T, SceneError>;

impl Cx<'_> {
    fn line_of(&self, offset: usize) -> usize {
        line_of(self.text, offset)
    }

    /// An error at `span` in the scene file, in `field`.
    fn err(&self, span: Range<usize>, field: &str, msg: impl Into<String>) -> SceneError {
        SceneError::new(self.file, msg)
            .at_line(self.line_of(span.start))
            .in_field(field)
    }

    /// Converts a `toml` syntax or type error. Its message has no key path
    /// when the error carries a span, so the path is recovered from the
    /// span's position in the text.
    fn toml_error(&self, e: &toml::de::Error) -> SceneError {
        // Syntax errors carry a multi-line message; keep it on one line.
        let msg = e.message().trim_end().replace('\n', "; ");
        let mut err = SceneError::new(self.file, msg);
        let missing = missing_field(e.message());
        match (e.span(), missing) {
            // A required top-level key comes with the empty span 0..0: there
            // is no line to point at. (A table's missing key has the table's
            // span, which starts at its header.)
            (Some(span), Some(key)) if span.is_empty() => err = err.in_field(key),
            (None, Some(key)) => err = err.in_field(key),
            (Some(span), missing) => {
                err = err.at_line(self.line_of(span.start));
                let path = key_path_at(self.text, span.start);
                let field = match (path, missing) {
                    (Some(p), Some(k)) => Some(format!("{p}.{k}")),
                    (None, Some(k)) => Some(k),
                    (p, None) => p,
                };
                if let Some(f) = field {
                    err = err.in_field(f);
                }
            }
            (None, None) => {}
        }
        err
    }

    /// A finite `Vec3` (finite also after narrowing to f32).
    fn vec3(&self, v: &Spanned<Triple>, field: &str) -> Res<Vec3> {
        let a = v.get_ref();
        let out = Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
        if !out.is_finite() {
            return Err(self.err(
                v.span(),
                field,
                format!(
                    "expected finite numbers, found [{}, {}, {}]",
                    a[0], a[1], a[2]
                ),
            ));
        }
        Ok(out)
    }

    fn scalar(&self, v: &Spanned<f64>, field: &str) -> Res<f32> {
        let x = *v.get_ref() as f32;
        if !x.is_finite() {
            return Err(self.err(
                v.span(),
                field,
                format!("expected a finite number, found {}", v.get_ref()),
            ));
        }
        Ok(x)
    }

    fn positive(&self, v: &Spanned<f64>, field: &str) -> Res<f32> {
        let x = self.scalar(v, field)?;
        if x <= 0.0 {
            return Err(self.err(v.span(), field, format!("expected a number > 0, found {x}")));
        }
        Ok(x)
    }

    /// RGB with every component ≥ 0 (and ≤ 1 if `unit`).
    fn rgb(&self, v: &Spanned<Triple>, field: &str, unit: bool) -> Res<Vec3> {
        let c = self.vec3(v, field)?;
        let ok = c.min_element() >= 0.0 && (!unit || c.max_element() <= 1.0);
        if !ok {
            let range = if unit { "in [0, 1]" } else { ">= 0" };
            return Err(self.err(
                v.span(),
                field,
                format!(
                    "expected RGB components {range}, found [{}, {}, {}]",
                    c.x, c.y, c.z
                ),
            ));
        }
        Ok(c)
    }
}

fn build(cx: &Cx, def: SceneFile) -> Res<Scene> {
    let units_per_mm = match &def.units_per_mm {
        Some(u) => cx.positive(u, "units_per_mm")?,
        None => 1.0,
    };
    let camera = camera(cx, &def.camera)?;
    let settings = settings(cx, &def.render)?;

    // Materials: indexed in name order (the map is sorted), so the same file
    // always gives the same indices.
    let mut materials = Vec::with_capacity(def.materials.len());
    let mut material_index = HashMap::new();
    for (name, m) in &def.materials {
        material_index.insert(name.as_str(), materials.len());
        materials.push(material(cx, name, m, units_per_mm)?);
    }

    let scene_dir = cx.file.parent().unwrap_or(Path::new(""));
    let mut meshes = Vec::with_capacity(def.shapes.len());
    let mut objects = Vec::with_capacity(def.shapes.len());
    for (i, s) in def.shapes.iter().enumerate() {
        let field = format!("shapes[{i}]");
        let sd = s.get_ref();
        let m = sd.material.get_ref();
        let Some(&mat) = material_index.get(m.as_str()) else {
            let mut known: Vec<&str> = material_index.keys().copied().collect();
            known.sort_unstable();
            let known = if known.is_empty() {
                "no materials are defined".to_string()
            } else {
                format!("defined: {}", known.join(", "))
            };
            return Err(cx.err(
                sd.material.span(),
                &format!("{field}.material"),
                format!("unknown material \"{m}\" ({known})"),
            ));
        };
        let emission = match &sd.emission {
            Some(e) => {
                Some(cx.rgb(e, &format!("{field}.emission"), false)?).filter(|e| *e != Vec3::ZERO)
            }
            None => None,
        };
        let mut mesh = shape_mesh(cx, scene_dir, &field, s)?;
        transform(cx, &field, sd)?.apply(&mut mesh);
        meshes.push(mesh);
        objects.push(Object {
            name: sd.name.clone().unwrap_or(field),
            material: mat,
            emission,
        });
    }

    let environment = match &def.environment {
        Some(env) => {
            Some(cx.rgb(&env.radiance, "environment.radiance", false)?).filter(|r| *r != Vec3::ZERO)
        }
        None => None,
    };

    Ok(Scene {
        camera,
        settings,
        meshes: Arc::new(meshes),
        objects,
        materials,
        environment,
        units_per_mm,
        source: Some(cx.file.to_path_buf()),
    })
}

fn camera(cx: &Cx, c: &Spanned<super::format::CameraDef>) -> Res<Camera> {
    let d = c.get_ref();
    let from = cx.vec3(&d.look_from, "camera.look_from")?;
    let at = cx.vec3(&d.look_at, "camera.look_at")?;
    let up = match &d.up {
        Some(u) => cx.vec3(u, "camera.up")?,
        None => Vec3::Y,
    };
    let fov = match &d.fov_y {
        Some(f) => {
            let v = cx.scalar(f, "camera.fov_y")?;
            if !(v > 0.0 && v < 180.0) {
                return Err(cx.err(
                    f.span(),
                    "camera.fov_y",
                    format!("expected degrees strictly between 0 and 180, found {v}"),
                ));
            }
            v
        }
        None => 40.0,
    };
    let [w, h] = *d.resolution.get_ref();
    if w == 0 || h == 0 || w > MAX_RESOLUTION || h > MAX_RESOLUTION {
        return Err(cx.err(
            d.resolution.span(),
            "camera.resolution",
            format!("expected [width, height] each in 1..={MAX_RESOLUTION}, found [{w}, {h}]"),
        ));
    }
    let view = at - from;
    let scale = from.abs().max(at.abs()).max_element().max(1.0);
    if view.length() <= 1e-6 * scale {
        return Err(cx.err(
            d.look_at.span(),
            "camera.look_at",
            "look_at must differ from look_from",
        ));
    }
    let (up_span, up_field) = match &d.up {
        Some(u) => (u.span(), "camera.up"),
        None => (c.span(), "camera.up"),
    };
    if up.length() == 0.0 || view.normalize().cross(up.normalize()).length() < 1e-4 {
        return Err(cx.err(
            up_span,
            up_field,
            format!(
                "up [{}, {}, {}] must be non-zero and not parallel to the view direction",
                up.x, up.y, up.z
            ),
        ));
    }
    Ok(Camera::new(from, at, up, fov, w, h))
}

fn settings(cx: &Cx, r: &super::format::RenderDef) -> Res<RenderSettings> {
    let mut s = RenderSettings::default();
    if let Some(spp) = &r.spp {
        if *spp.get_ref() == 0 {
            return Err(cx.err(
                spp.span(),
                "render.spp",
                "expected at least 1 sample per pixel, found 0",
            ));
        }
        s.spp = *spp.get_ref();
    }
    if let Some(d) = &r.max_depth {
        if *d.get_ref() == 0 {
            return Err(cx.err(
                d.span(),
                "render.max_depth",
                "expected a path depth of at least 1, found 0",
            ));
        }
        s.max_depth = *d.get_ref();
    }
    if let Some(seed) = r.seed {
        s.seed = seed;
    }
    Ok(s)
}

/// Rejects keys that belong to other types than `kind`.
fn only_keys(
    cx: &Cx,
    field: &str,
    kind: &str,
    present: Vec<(&'static str, Range<usize>)>,
    allowed: &[&str],
) -> Res<()> {
    for (key, span) in present {
        if !allowed.contains(&key) {
            let allowed = if allowed.is_empty() {
                "none".to_string()
            } else {
                allowed.join(", ")
            };
            return Err(cx.err(
                span,
                &format!("{field}.{key}"),
                format!("`{key}` does not apply to type \"{kind}\" (its keys: {allowed})"),
            ));
        }
    }
    Ok(())
}

fn material(cx: &Cx, name: &str, m: &Spanned<MaterialDef>, units_per_mm: f32) -> Res<Material> {
    let field = format!("materials.{name}");
    let d = m.get_ref();
    let kind = *d.kind.get_ref();
    let missing = |key: &str| {
        cx.err(
            m.span(),
            &format!("{field}.{key}"),
            format!(
                "missing field `{key}` (required for type \"{}\")",
                kind.name()
            ),
        )
    };
    match kind {
        MaterialKind::Diffuse => {
            only_keys(cx, &field, kind.name(), d.present_keys(), &["albedo"])?;
            let a = d.albedo.as_ref().ok_or_else(|| missing("albedo"))?;
            Ok(Material::Diffuse {
                albedo: cx.rgb(a, &format!("{field}.albedo"), true)?,
            })
        }
        MaterialKind::Dielectric => {
            only_keys(cx, &field, kind.name(), d.present_keys(), &["eta"])?;
            let e = d.eta.as_ref().ok_or_else(|| missing("eta"))?;
            Ok(Material::Dielectric {
                eta: cx.positive(e, &format!("{field}.eta"))?,
            })
        }
        MaterialKind::Subsurface => {
            only_keys(cx, &field, kind.name(), d.present_keys(), SUBSURFACE_KEYS)?;
            subsurface(cx, &field, m, units_per_mm)
        }
    }
}

const SUBSURFACE_KEYS: &[&str] = &[
    "preset",
    "sigma_s_prime",
    "sigma_a",
    "g",
    "albedo",
    "dmfp",
    "eta",
    "fit",
    "radius",
    "rmax_quantile",
    "axes",
    "channel",
    "renormalize",
    "exit_sw",
    "specular",
];

fn text(v: &Option<Spanned<String>>) -> Option<(&str, std::ops::Range<usize>)> {
    v.as_ref().map(|s| (s.get_ref().as_str(), s.span()))
}

/// A `type = "subsurface"` material: one of three parameter forms (preset;
/// measured σs', σa, A; artist A, dmfp), then the sampling options.
fn subsurface(cx: &Cx, field: &str, m: &Spanned<MaterialDef>, units_per_mm: f32) -> Res<Material> {
    use crate::bssrdf::{
        ChannelStrategy, Fit, Measured, ProbeAxes, ProbeOptions, RadiusSampler, SubsurfaceParams,
    };
    let d = m.get_ref();
    let f = |k: &str| format!("{field}.{k}");
    let units = units_per_mm as f64;
    // Errors from the bssrdf module start with the offending key, named as
    // there: `sigma_s` for the σs' given here, `mfp` for `dmfp`.
    let param_err = |mut msg: String| {
        for (from, to) in [("sigma_s.", "sigma_s_prime."), ("mfp.", "dmfp.")] {
            if let Some(rest) = msg.strip_prefix(from) {
                msg = format!("{to}{rest}");
            }
        }
        let key = msg
            .split([':', '.'])
            .next()
            .unwrap_or("")
            .trim()
            .to_string();
        let span = d
            .present_keys()
            .into_iter()
            .find(|(k, _)| *k == key)
            .map(|(_, s)| s)
            .unwrap_or(m.span());
        cx.err(span, &f(&key), msg)
    };
    let fit = match text(&d.fit) {
        Some((s, span)) => Fit::parse(s).map_err(|e| cx.err(span, &f("fit"), e))?,
        None => Fit::Searchlight,
    };
    let eta = d
        .eta
        .as_ref()
        .map(|e| cx.positive(e, &f("eta")))
        .transpose()?;
    let triple = |v: &Option<Spanned<[f64; 3]>>, k: &str| -> Res<Option<[f64; 3]>> {
        v.as_ref()
            .map(|t| {
                // checked as f32, kept as written (no 1.2000000476837158)
                cx.vec3(t, &f(k)).map(|_| *t.get_ref())
            })
            .transpose()
    };
    let albedo = triple(&d.albedo, "albedo")?;
    let (sigma_s, sigma_a, dmfp) = (
        triple(&d.sigma_s_prime, "sigma_s_prime")?,
        triple(&d.sigma_a, "sigma_a")?,
        triple(&d.dmfp, "dmfp")?,
    );
    let forms =
        "give exactly one of: `preset`; `sigma_s_prime` + `sigma_a` + `albedo`; `albedo` + `dmfp`";
    // Keys of two forms: name the first key of each, at the later one's line
    // (`albedo` belongs to the measured and the artist form).
    let present = d.present_keys();
    let span_of = |k: &str| {
        present
            .iter()
            .find(|(p, _)| *p == k)
            .map(|(_, s)| s.clone())
    };
    let groups: [&[&str]; 3] = [
        &["preset"],
        &["sigma_s_prime", "sigma_a", "g"],
        &["dmfp", "albedo"],
    ];
    let firsts: Vec<&str> = groups
        .iter()
        .filter_map(|g| g.iter().copied().find(|k| span_of(k).is_some()))
        .collect();
    if let [a, b, ..] = firsts[..] {
        if a == "preset" || b == "dmfp" {
            let msg = format!("`{a}` cannot be combined with `{b}`; {forms}");
            return Err(cx.err(span_of(b).unwrap_or(m.span()), &f(b), msg));
        }
    }
    let params = match (text(&d.preset), sigma_s.or(sigma_a), dmfp) {
        (Some((name, span)), None, None) if albedo.is_none() && d.g.is_none() => {
            let mut p = SubsurfaceParams::from_preset(name, units, fit)
                .map_err(|e| cx.err(span, &f("preset"), e))?;
            if let Some(eta) = eta {
                p.eta = eta;
            }
            p
        }
        (None, Some(_), None) => {
            let (Some(ss), Some(sa)) = (sigma_s, sigma_a) else {
                let missing = if sigma_s.is_none() {
                    "sigma_s_prime"
                } else {
                    "sigma_a"
                };
                return Err(cx.err(
                    m.span(),
                    &f(missing),
                    format!("missing field `{missing}`: measured parameters need `sigma_s_prime`, `sigma_a` and `albedo`"),
                ));
            };
            let Some(albedo) = albedo else {
                return Err(cx.err(
                    m.span(),
                    &f("albedo"),
                    format!("missing field `albedo` for measured parameters; {forms}"),
                ));
            };
            // g is checked here, before σs = σs'/(1 − g) below (g = 1 would
            // make that infinite), and so is σs' as written.
            let g = match &d.g {
                Some(gs) => {
                    let g = *gs.get_ref();
                    if !(g > -1.0 && g < 1.0) {
                        return Err(cx.err(
                            gs.span(),
                            &f("g"),
                            format!("g: {g} must be in (-1, 1)"),
                        ));
                    }
                    g
                }
                None => 0.0,
            };
            if let Some((c, x)) = ss
                .iter()
                .enumerate()
                .find(|(_, x)| !x.is_finite() || **x < 0.0)
            {
                let ch = ["r", "g", "b"][c];
                return Err(param_err(format!(
                    "sigma_s.{ch}: {x} must be finite and non-negative"
                )));
            }
            // σs' is given: σs = σs' / (1 − g) so that the loader's σs(1 − g) is σs' again.
            let sigma_s = ss.map(|x| x / (1.0 - g));
            let measured = Measured {
                sigma_s,
                sigma_a: sa,
                g,
                albedo,
                eta: eta.unwrap_or(1.3),
            };
            SubsurfaceParams::from_measured(&measured, units, fit).map_err(param_err)?
        }
        (None, None, Some(mfp)) if d.g.is_none() => {
            let Some(albedo) = albedo else {
                return Err(cx.err(
                    m.span(),
                    &f("albedo"),
                    format!("missing field `albedo` for the artist form; {forms}"),
                ));
            };
            SubsurfaceParams::from_artist(albedo, mfp.map(|x| x * units), eta.unwrap_or(1.3), fit)
                .map_err(param_err)?
        }
        _ => return Err(cx.err(m.span(), field, format!("subsurface parameters: {forms}"))),
    };

    let mut opts = ProbeOptions::default();
    if let Some((s, span)) = text(&d.radius) {
        opts.radius = RadiusSampler::parse(s).map_err(|e| {
            // the bssrdf module's name for this key is `radius_sampler`
            let e = e
                .replacen("radius_sampler.table_size: ", "table size ", 1)
                .replacen("radius_sampler: ", "", 1);
            cx.err(span, &f("radius"), e)
        })?;
    }
    if let Some(q) = &d.rmax_quantile {
        let v = cx.scalar(q, &f("rmax_quantile"))? as f64;
        if !(v > 0.0 && v < 1.0) {
            return Err(cx.err(
                q.span(),
                &f("rmax_quantile"),
                format!("expected a number in (0, 1), found {v}"),
            ));
        }
        opts.rmax_quantile = *q.get_ref();
    }
    if let Some((s, span)) = text(&d.axes) {
        opts.axes = match s.to_ascii_lowercase().as_str() {
            "normal" => ProbeAxes::Normal,
            "mis3" => ProbeAxes::Mis3,
            _ => {
                return Err(cx.err(
                    span,
                    &f("axes"),
                    format!("expected \"normal\" or \"mis3\", found \"{s}\""),
                ))
            }
        };
    }
    if let Some((s, span)) = text(&d.channel) {
        opts.channel = match s.to_ascii_lowercase().as_str() {
            "single" => ChannelStrategy::Single,
            "mis" => ChannelStrategy::Mis,
            _ => {
                return Err(cx.err(
                    span,
                    &f("channel"),
                    format!("expected \"single\" or \"mis\", found \"{s}\""),
                ))
            }
        };
    }
    if let Some(b) = &d.renormalize {
        opts.renormalize = *b.get_ref();
    }
    let flag = |b: &Option<Spanned<bool>>| b.as_ref().map(|b| *b.get_ref()).unwrap_or(true);
    let ss = Subsurface::new(params, &opts, flag(&d.exit_sw), flag(&d.specular))
        .map_err(|e| cx.err(m.span(), field, e))?;
    Ok(Material::Subsurface(Arc::new(ss)))
}

fn shape_mesh(cx: &Cx, dir: &Path, field: &str, s: &Spanned<ShapeDef>) -> Res<Mesh> {
    let d = s.get_ref();
    let kind = *d.kind.get_ref();
    let allowed: &[&str] = match kind {
        ShapeKind::Obj => &["file", "smooth"],
        ShapeKind::Sphere => &["subdivisions"],
        ShapeKind::Quad | ShapeKind::Box => &[],
    };
    only_keys(cx, field, kind.name(), d.present_type_keys(), allowed)?;
    match kind {
        ShapeKind::Obj => {
            let Some(f) = &d.file else {
                return Err(cx.err(
                    s.span(),
                    &format!("{field}.file"),
                    "missing field `file` (required for type \"obj\")",
                ));
            };
            let path = dir.join(f.get_ref());
            let text = std::fs::read_to_string(&path).map_err(|e| {
                cx.err(
                    f.span(),
                    &format!("{field}.file"),
                    format!("cannot read OBJ file {}: {e}", path.display()),
                )
            })?;
            let mut mesh = load_obj(&text, &path)?;
            if d.smooth.as_ref().is_some_and(|b| *b.get_ref()) && mesh.normals.is_none() {
                mesh.compute_smooth_normals();
            }
            Ok(mesh)
        }
        ShapeKind::Sphere => {
            let level = match &d.subdivisions {
                Some(l) if *l.get_ref() > MAX_SPHERE_SUBDIVISIONS => {
                    return Err(cx.err(
                        l.span(),
                        &format!("{field}.subdivisions"),
                        format!(
                        "expected at most {MAX_SPHERE_SUBDIVISIONS} (20·4^n triangles), found {}",
                        l.get_ref()
                    ),
                    ))
                }
                Some(l) => *l.get_ref(),
                None => 4,
            };
            Ok(shapes::sphere(level))
        }
        ShapeKind::Quad => Ok(shapes::quad()),
        ShapeKind::Box => Ok(shapes::cuboid()),
    }
}

fn transform(cx: &Cx, field: &str, d: &ShapeDef) -> Res<Transform> {
    let scale = match &d.scale {
        Some(s) => {
            let f = format!("{field}.scale");
            let v = cx.vec3(&Spanned::new(s.span(), s.get_ref().0), &f)?;
            if v.x == 0.0 || v.y == 0.0 || v.z == 0.0 {
                return Err(cx.err(
                    s.span(),
                    &f,
                    "scale components must be non-zero (negative mirrors)",
                ));
            }
            v
        }
        None => Vec3::ONE,
    };
    let mut rotations = Vec::new();
    for (k, r) in d.rotate.iter().flatten().enumerate() {
        let f = format!("{field}.rotate[{k}]");
        let rot = r.get_ref();
        let angle = cx.scalar(&Spanned::new(r.span(), rot.angle_deg), &f)?;
        let axis = cx.vec3(&Spanned::new(r.span(), rot.axis), &f)?;
        if axis.length() == 0.0 || !axis.length().is_finite() {
            return Err(cx.err(r.span(), &f, "rotation axis must be non-zero"));
        }
        rotations.push((angle, axis));
    }
    let translate = match &d.translate {
        Some(t) => cx.vec3(t, &format!("{field}.translate"))?,
        None => Vec3::ZERO,
    };
    Ok(Transform::from_srt(scale, &rotations, translate))
}

/// Loads an OBJ file's faces (all objects and groups) as one mesh. Shading
/// normals are kept only if every vertex has one; materials (`mtllib`) are
/// ignored — the scene file assigns the material.
pub fn load_obj(text: &str, path: &Path) -> Res<Mesh> {
    check_obj(text).map_err(|(line, msg)| SceneError::new(path, msg).at_line(line))?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let result = std::panic::catch_unwind(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| {
            Err(tobj::LoadError::GenericFailure)
        })
    });
    let models = match result {
        Ok(Ok((models, _materials))) => models,
        Ok(Err(e)) => return Err(SceneError::new(path, format!("invalid OBJ data: {e}"))),
        Err(_) => {
            return Err(SceneError::new(
                path,
                "invalid OBJ data (the OBJ parser failed on this file)",
            ))
        }
    };

    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut all_normals = true;
    let mut indices = Vec::new();
    for m in &models {
        let m = &m.mesh;
        let base = positions.len();
        let nv = m.positions.len() / 3;
        if m.positions.len() % 3 != 0 || m.indices.len() % 3 != 0 {
            return Err(SceneError::new(
                path,
                "invalid OBJ data: malformed mesh arrays",
            ));
        }
        for p in m.positions.chunks_exact(3) {
            positions.push(Vec3::new(p[0], p[1], p[2]));
        }
        if m.normals.len() == m.positions.len() {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        } else {
            all_normals = false;
        }
        for t in m.indices.chunks_exact(3) {
            if t.iter().any(|&i| i as usize >= nv) {
                return Err(SceneError::new(
                    path,
                    "invalid OBJ data: face index out of range",
                ));
            }
            let off = |i: u32| u32::try_from(base + i as usize);
            match (off(t[0]), off(t[1]), off(t[2])) {
                (Ok(a), Ok(b), Ok(c)) => indices.push([a, b, c]),
                _ => return Err(SceneError::new(path, "OBJ file has too many vertices")),
            }
        }
    }
    if indices.is_empty() {
        return Err(SceneError::new(
            path,
            "OBJ file contains no triangles (no `f` lines with 3 or more vertices)",
        ));
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(SceneError::new(
            path,
            "OBJ file has non-finite vertex positions",
        ));
    }
    let normals = (all_normals && normals.iter().all(|n| n.is_finite() && n.length() > 0.0))
        .then(|| normals.into_iter().map(Vec3::normalize).collect());
    Ok(Mesh::new(positions, indices, normals))
}

/// Checks the OBJ statements `tobj` would trust: numbers in `v`/`vt`/`vn`
/// lines must parse and be finite, and every face index must be non-zero
/// and refer to an element defined before it. Returns (line, message).
fn check_obj(text: &str) -> Result<(), (usize, String)> {
    let (mut nv, mut nt, mut nn) = (0usize, 0usize, 0usize);
    for (ln, line) in text.lines().enumerate() {
        let ln = ln + 1;
        let mut words = line.split_whitespace();
        let Some(tag) = words.next() else { continue };
        let numbers = |words: std::str::SplitWhitespace, need: usize, what: &str| {
            let vals: Vec<&str> = words.collect();
            if vals.len() < need {
                return Err((
                    ln,
                    format!("`{what}` needs {need} numbers, found {}", vals.len()),
                ));
            }
            let mut out = Vec::with_capacity(vals.len());
            for w in vals {
                match w.parse::<f32>() {
                    Ok(x) if x.is_finite() => out.push(x),
                    Ok(_) => return Err((ln, format!("`{what}` has a non-finite number `{w}`"))),
                    Err(_) => return Err((ln, format!("`{what}` has `{w}`, expected a number"))),
                }
            }
            Ok(out)
        };
        match tag {
            "v" => {
                // tobj reads `x y z`, `x y z w` (dividing by w) or
                // `x y z r g b`, and rejects other counts.
                let v = numbers(words, 3, "v")?;
                match v.len() {
                    3 | 6 => {}
                    4 if v[3] != 0.0 && v[..3].iter().all(|x| (x / v[3]).is_finite()) => {}
                    4 => {
                        return Err((
                            ln,
                            format!("`v` has weight w = {} that makes it non-finite", v[3]),
                        ))
                    }
                    n => {
                        return Err((
                            ln,
                            format!("`v` has {n} numbers, expected x y z, x y z w or x y z r g b"),
                        ))
                    }
                }
                nv += 1;
            }
            "vt" => {
                numbers(words, 2, "vt")?;
                nt += 1;
            }
            "vn" => {
                let n = numbers(words, 3, "vn")?;
                if n[..3].iter().all(|&x| x == 0.0) {
                    return Err((ln, "`vn` is a zero-length normal".into()));
                }
                nn += 1;
            }
            "f" | "l" | "p" => {
                let refs: Vec<&str> = words.collect();
                if tag == "f" && refs.len() < 3 {
                    return Err((
                        ln,
                        format!("face has {} vertices, expected at least 3", refs.len()),
                    ));
                }
                for r in refs {
                    let parts: Vec<&str> = r.split('/').collect();
                    if parts.len() > 3 || parts[0].is_empty() {
                        return Err((
                            ln,
                            format!(
                                "malformed face vertex `{r}` (expected v, v/vt, v//vn or v/vt/vn)"
                            ),
                        ));
                    }
                    for (k, (p, count, what)) in parts
                        .iter()
                        .zip([(nv, "vertex"), (nt, "texture coordinate"), (nn, "normal")])
                        .map(|(p, (c, w))| (p, c, w))
                        .enumerate()
                    {
                        if k > 0 && p.is_empty() {
                            continue;
                        }
                        let i: i64 = p.parse().map_err(|_| {
                            (
                                ln,
                                format!(
                                    "malformed face vertex `{r}`: `{p}` is not an integer index"
                                ),
                            )
                        })?;
                        let ok = if i > 0 {
                            (i as u64) <= count as u64
                        } else {
                            i != 0 && i.unsigned_abs() <= count as u64
                        };
                        if !ok {
                            return Err((
                                ln,
                                format!(
                                    "face {what} index {i} out of range: {count} defined before this line (indices start at 1; negative ones count back)"
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The 1-based line containing byte `offset` of `text`.
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The field named by serde's "missing field `x`" message, if that is what
/// `msg` is.
fn missing_field(msg: &str) -> Option<String> {
    let rest = msg.strip_prefix("missing field `")?;
    Some(rest[..rest.find('`')?].to_string())
}

/// The dotted key path (`materials.red.albedo`, `shapes[1].file`) of the
/// TOML statement containing byte `offset`, from a lightweight scan that
/// follows table headers, keys, strings, comments and bracket nesting.
/// Array-of-tables entries are numbered from 0. Values nested in inline
/// tables are attributed to the enclosing key.
pub(crate) fn key_path_at(text: &str, offset: usize) -> Option<String> {
    let b = text.as_bytes();
    let mut header = String::new();
    let mut aot: HashMap<String, usize> = HashMap::new();
    let mut i = 0;
    let join = |h: &str, k: &str| {
        if h.is_empty() {
            k.to_string()
        } else {
            format!("{h}.{k}")
        }
    };
    while i < b.len() {
        // Skip blank space and comments between statements.
        match b[i] {
            b' ' | b'\t' | b'\r' | b'\n' => {
                i += 1;
                continue;
            }
            b'#' => {
                i = skip_line(b, i);
                continue;
            }
            _ => {}
        }
        let start = i;
        if b[i] == b'[' {
            let double = b.get(i + 1) == Some(&b'[');
            let name_start = i + if double { 2 } else { 1 };
            let close = scan_key_until(b, name_start, b']');
            let name = normalize_key(&text[name_start..close]);
            let end = skip_line(b, close);
            if double {
                let n = aot.entry(name.clone()).or_insert(0);
                header = format!("{name}[{n}]");
                *n += 1;
            } else {
                header = name;
            }
            if (start..end).contains(&offset) {
                return Some(header);
            }
            i = end;
        } else {
            let eq = scan_key_until(b, i, b'=');
            if b.get(eq) != Some(&b'=') {
                // Not a key-value pair (a syntax error): no field to name.
                if (start..eq.max(start + 1)).contains(&offset) {
                    return None;
                }
                i = eq.max(start + 1);
                continue;
            }
            let key = normalize_key(&text[start..eq]);
            let end = skip_value(b, (eq + 1).min(b.len()));
            if (start..end.max(start + 1)).contains(&offset) {
                return Some(join(&header, &key));
            }
            i = end.max(start + 1);
        }
    }
    (!header.is_empty() && offset >= text.len()).then_some(header)
}

fn skip_line(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i] != b'\n' {
        i += 1;
    }
    i
}

/// Index of the first `stop` byte outside quotes at or after `i`, or the end
/// of the line.
fn scan_key_until(b: &[u8], mut i: usize, stop: u8) -> usize {
    while i < b.len() && b[i] != b'\n' {
        match b[i] {
            c if c == stop => return i,
            q @ (b'"' | b'\'') => {
                i += 1;
                while i < b.len() && b[i] != q && b[i] != b'\n' {
                    i += if q == b'"' && b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            _ => i += 1,
        }
    }
    i.min(b.len())
}

/// End of the value starting at `i`: the first newline outside strings,
/// comments and brackets.
fn skip_value(b: &[u8], mut i: usize) -> usize {
    let mut depth = 0usize;
    while i < b.len() {
        match b[i] {
            b'\n' if depth == 0 => return i,
            b'[' | b'{' => depth += 1,
            b']' | b'}' => depth = depth.saturating_sub(1),
            b'#' => {
                i = skip_line(b, i);
                continue;
            }
            q @ (b'"' | b'\'') => {
                let triple = b.get(i + 1) == Some(&q) && b.get(i + 2) == Some(&q);
                if triple {
                    i += 3;
                    while i < b.len()
                        && !(b[i] == q && b.get(i + 1) == Some(&q) && b.get(i + 2) == Some(&q))
                    {
                        i += if q == b'"' && b[i] == b'\\' { 2 } else { 1 };
                    }
                    i += 3;
                } else {
                    i += 1;
                    while i < b.len() && b[i] != q && b[i] != b'\n' {
                        i += if q == b'"' && b[i] == b'\\' { 2 } else { 1 };
                    }
                    i += 1;
                }
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    b.len()
}

/// `a . "b c"` → `a."b c"`; bare keys keep their spelling.
fn normalize_key(k: &str) -> String {
    let mut out = String::new();
    let mut in_q: Option<char> = None;
    for c in k.trim().chars() {
        match in_q {
            Some(q) => {
                out.push(c);
                if c == q {
                    in_q = None;
                }
            }
            None if c == '"' || c == '\'' => {
                in_q = Some(c);
                out.push(c);
            }
            None if c.is_whitespace() => {}
            None => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: &str =
        "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [64, 32]\n";

    fn scene(body: &str) -> Scene {
        load_str(&format!("{CAMERA}{body}"), Path::new("test.toml")).unwrap()
    }

    fn geometric_normal(m: &Mesh, i: u32) -> Vec3 {
        let [a, b, c] = m.triangle(i);
        (b - a).cross(c - a).normalize()
    }

    fn demo(name: &str) -> Scene {
        load(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("scenes")
                .join(name),
        )
        .unwrap()
    }

    #[test]
    fn defaults_fill_everything_optional() {
        let s = scene("");
        assert_eq!(s.settings, RenderSettings::default());
        assert_eq!(
            (s.settings.spp, s.settings.max_depth, s.settings.seed),
            (16, 8, 0)
        );
        assert_eq!(s.camera.up, Vec3::Y);
        assert_eq!(s.camera.fov_y, 40.0);
        assert_eq!((s.camera.width, s.camera.height), (64, 32));
        assert_eq!(s.units_per_mm, 1.0);
        assert!(s.environment.is_none() && s.meshes.is_empty() && s.objects.is_empty());
        assert_eq!(s.source.as_deref(), Some(Path::new("test.toml")));
    }

    #[test]
    fn explicit_values_are_kept() {
        let s = load_str(
            "units_per_mm = 2.5\n[camera]\nlook_from = [1, 2, 3]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\nfov_y = 60\nresolution = [10, 20]\n\
             [render]\nspp = 4\nmax_depth = 3\nseed = 99\n[environment]\nradiance = [0.5, 1, 2]\n",
            Path::new("x.toml"),
        )
        .unwrap();
        assert_eq!(
            s.settings,
            RenderSettings {
                spp: 4,
                max_depth: 3,
                seed: 99
            }
        );
        // Field by field: the derived members (tan of the fov) can differ in
        // the last bit between a constant-folded and a runtime `tan`.
        let c = &s.camera;
        assert_eq!(
            (c.look_from, c.look_at, c.up, c.fov_y, c.width, c.height),
            (Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Z, 60.0, 10, 20)
        );
        assert_eq!(s.environment, Some(Vec3::new(0.5, 1.0, 2.0)));
        assert_eq!(s.units_per_mm, 2.5);
    }

    #[test]
    fn materials_are_indexed_by_name_and_shapes_resolve_them() {
        let s = scene(
            "[materials.zinc]\ntype = \"diffuse\"\nalbedo = [0.1, 0.2, 0.3]\n\
             [materials.glass]\ntype = \"dielectric\"\neta = 1.33\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"zinc\"\n\
             [[shapes]]\ntype = \"box\"\nname = \"cube\"\nmaterial = \"glass\"\nemission = [1, 2, 3]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"zinc\"\nemission = [0, 0, 0]\n",
        );
        assert_eq!(
            s.materials,
            vec![
                Material::Dielectric { eta: 1.33 },
                Material::Diffuse {
                    albedo: Vec3::new(0.1, 0.2, 0.3)
                }
            ]
        );
        assert_eq!(s.objects.len(), 3);
        assert_eq!(s.meshes.len(), 3);
        assert_eq!((s.objects[0].material, s.objects[1].material), (1, 0));
        assert_eq!(s.objects[0].name, "shapes[0]");
        assert_eq!(s.objects[1].name, "cube");
        assert_eq!(s.objects[0].emission, None);
        assert_eq!(s.objects[1].emission, Some(Vec3::new(1.0, 2.0, 3.0)));
        // Zero emission is not a light.
        assert_eq!(s.objects[2].emission, None);
        assert_eq!(s.meshes[1].triangle_count(), 12);
    }

    #[test]
    fn transforms_apply_scale_then_rotations_then_translation() {
        let s = scene(
            "[materials.m]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nscale = [2, 1, 1]\n\
             rotate = [[90, 0, 0, 1], [90, 1, 0, 0]]\ntranslate = [10, 0, 0]\n",
        );
        let m = &s.meshes[0];
        // (1,-1,0) → (2,-1,0) → z90 → (1,2,0) → x90 → (1,0,2) → +10x.
        assert!(m.positions()[1].abs_diff_eq(Vec3::new(11.0, 0.0, 2.0), 1e-5));
        // The +z facing quad now faces z → x90 → -y.
        for i in 0..2 {
            assert!(geometric_normal(m, i).abs_diff_eq(-Vec3::Y, 1e-5));
        }
        let n = m.normals.as_ref().unwrap();
        assert!(n.iter().all(|n| n.abs_diff_eq(-Vec3::Y, 1e-5)));
        // Uniform scale from a single number.
        let s = scene(
            "[materials.m]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\
             [[shapes]]\ntype = \"box\"\nmaterial = \"m\"\nscale = 0.5\n",
        );
        let max = s.meshes[0]
            .positions()
            .iter()
            .fold(Vec3::ZERO, |a, p| a.max(p.abs()));
        assert!(max.abs_diff_eq(Vec3::splat(0.5), 1e-6));
    }

    #[test]
    fn negative_scale_flips_winding() {
        let s = scene(
            "[materials.m]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nscale = [1, 1, -1]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nscale = [-2, 1, 1]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nscale = [-1, -1, 1]\n",
        );
        let flipped: Vec<[u32; 3]> = shapes::quad()
            .indices
            .iter()
            .map(|&[a, b, c]| [a, c, b])
            .collect();
        // z-mirror: faces -z now, front face and shading normal agree.
        assert_eq!(s.meshes[0].indices, flipped);
        assert!(geometric_normal(&s.meshes[0], 0).abs_diff_eq(-Vec3::Z, 1e-6));
        assert!(s.meshes[0].normals.as_ref().unwrap()[0].abs_diff_eq(-Vec3::Z, 1e-6));
        // x-mirror of a z-facing quad: still faces +z, via the flipped winding.
        assert_eq!(s.meshes[1].indices, flipped);
        assert!(geometric_normal(&s.meshes[1], 0).abs_diff_eq(Vec3::Z, 1e-6));
        // Two mirrors are a rotation: no flip.
        assert_eq!(s.meshes[2].indices, shapes::quad().indices);
        assert!(geometric_normal(&s.meshes[2], 0).abs_diff_eq(Vec3::Z, 1e-6));
    }

    #[test]
    fn sphere_subdivisions_default_and_explicit() {
        let s = scene(
            "[materials.m]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\
             [[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\n\
             [[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\nsubdivisions = 1\n",
        );
        assert_eq!(s.meshes[0].triangle_count(), 20 * 256);
        assert_eq!(s.meshes[1].triangle_count(), 80);
    }

    #[test]
    fn obj_files_resolve_relative_to_the_scene_and_keep_valid_normals() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("m")).unwrap();
        // A quad (triangulated to 2) with normals, then a triangle using
        // relative indices in a second group.
        std::fs::write(
            dir.path().join("m/a.obj"),
            "# test\nmtllib none.mtl\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 2\n\
             f 1//1 2//1 3//1 4//1\ng tri\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf -3//1 -2//1 -1//1\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("b.obj"),
            "v 0 0 0\nv 2 0 0 2\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1 2 4\n",
        )
        .unwrap();
        let text = format!(
            "{CAMERA}[materials.m]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n\
             [[shapes]]\ntype = \"obj\"\nfile = \"m/a.obj\"\nmaterial = \"m\"\ntranslate = [0, 0, 1]\n\
             [[shapes]]\ntype = \"obj\"\nfile = \"b.obj\"\nmaterial = \"m\"\n"
        );
        let path = dir.path().join("s.toml");
        std::fs::write(&path, text).unwrap();
        let s = load(&path).unwrap();
        let a = &s.meshes[0];
        assert_eq!(a.triangle_count(), 3);
        let n = a.normals.as_ref().expect("every vertex has a normal");
        assert!(n.iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-6)));
        assert!(a
            .positions()
            .iter()
            .any(|p| p.abs_diff_eq(Vec3::new(1.0, 1.0, 1.0), 1e-6)));
        assert!(a
            .positions()
            .iter()
            .any(|p| p.abs_diff_eq(Vec3::new(0.0, 1.0, 2.0), 1e-6)));
        for i in 0..3 {
            assert!(geometric_normal(a, i).abs_diff_eq(Vec3::Z, 1e-6));
        }
        // Only some vertices have normals: fall back to geometric normals.
        assert_eq!(s.meshes[1].triangle_count(), 2);
        // `v x y z w` is divided by w.
        assert_eq!(s.meshes[1].positions()[1], Vec3::X);
        assert!(s.meshes[1].normals.is_none());
    }

    #[test]
    fn cornell_demo_is_a_closed_room_with_a_downward_light() {
        let s = demo("cornell.toml");
        assert_eq!(s.objects.len(), 8);
        assert_eq!(s.meshes.len(), 8);
        assert_eq!((s.camera.width, s.camera.height), (512, 512));
        let by_name = |n: &str| s.objects.iter().position(|o| o.name == n).unwrap();
        let lights: Vec<_> = s.objects.iter().filter(|o| o.emission.is_some()).collect();
        assert_eq!(lights.len(), 1);
        let light = by_name("light");
        assert!(geometric_normal(&s.meshes[light], 0).abs_diff_eq(-Vec3::Y, 1e-5));
        let glass = &s.materials[s.objects[by_name("glass sphere")].material];
        assert_eq!(*glass, Material::Dielectric { eta: 1.5 });
        let red = &s.materials[s.objects[by_name("left wall")].material];
        assert!(matches!(red, Material::Diffuse { albedo } if albedo.x > albedo.y));
        // Each wall faces the room's centre.
        let centre = Vec3::new(0.0, 1.0, 0.0);
        for wall in ["floor", "ceiling", "back wall", "left wall", "right wall"] {
            let m = &s.meshes[by_name(wall)];
            let [a, b, c] = m.triangle(0);
            let mid = (a + b + c) / 3.0;
            assert!(geometric_normal(m, 0).dot(centre - mid) > 0.0, "{wall}");
        }
        // Everything is inside the box.
        for m in s.meshes.iter() {
            for p in m.positions() {
                assert!(p.x.abs() <= 1.0 + 1e-5 && p.z.abs() <= 1.0 + 1e-5);
                assert!(p.y >= -1e-5 && p.y <= 2.0 + 1e-5);
            }
        }
    }

    #[test]
    fn bunny_demo_sits_on_the_floor() {
        let s = demo("bunny.toml");
        let bunny = s.objects.iter().position(|o| o.name == "bunny").unwrap();
        let m = &s.meshes[bunny];
        assert_eq!(m.triangle_count(), 3674);
        assert_eq!(m.vertex_count(), 1839);
        let (lo, hi) = m
            .positions()
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        assert!(lo.y >= 0.0 && lo.y < 1e-3, "{lo}");
        assert!((hi.y - 0.965).abs() < 0.01, "{hi}");
        assert_eq!(s.objects.iter().filter(|o| o.emission.is_some()).count(), 1);
    }

    #[test]
    fn the_documented_example_loads() {
        // The complete example of docs/scene-format.md, resolved as if it
        // were in scenes/ (it uses meshes/bunny.obj).
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let doc = std::fs::read_to_string(root.join("docs/scene-format.md")).unwrap();
        let start = doc.find("```toml\n").expect("example block") + "```toml\n".len();
        let end = start + doc[start..].find("```").unwrap();
        let s = load_str(&doc[start..end], &root.join("scenes/example.toml")).unwrap();
        assert_eq!(s.objects.len(), 5);
        assert_eq!(s.meshes[4].triangle_count(), 3674);
        assert_eq!(s.settings.seed, 1);
        assert!(s.environment.is_some());
    }

    #[test]
    fn key_paths_follow_headers_arrays_and_strings() {
        let t =
            "a = 1\n[camera]\nlook_from = [\n  0, # ] comment\n  1,\n  2]\nname = \"x = [ #\"\n\
                 [[shapes]]\ntype = 'quad'\n[[shapes]]\n  file = \"\"\"\nmulti = line\n\"\"\"\n\
                 [ materials . \"my red\" ]\nalbedo = {r = 1}\n";
        let at = |needle: &str| key_path_at(t, t.find(needle).unwrap());
        assert_eq!(at("a = 1").as_deref(), Some("a"));
        assert_eq!(at("[camera]").as_deref(), Some("camera"));
        assert_eq!(at("1,").as_deref(), Some("camera.look_from"));
        assert_eq!(at("2]").as_deref(), Some("camera.look_from"));
        assert_eq!(at("\"x =").as_deref(), Some("camera.name"));
        assert_eq!(at("'quad'").as_deref(), Some("shapes[0].type"));
        assert_eq!(at("multi").as_deref(), Some("shapes[1].file"));
        assert_eq!(at("r = 1").as_deref(), Some("materials.\"my red\".albedo"));
        assert_eq!(line_of(t, t.find("2]").unwrap()), 6);
        assert_eq!(line_of(t, 0), 1);
        assert_eq!(line_of(t, usize::MAX), t.lines().count() + 1);
    }
}
