//! Scene loading: TOML text → [`super::format::SceneFile`] → checked
//! values → [`Scene`].
//!
//! Every failure is an [`InputError`] that names the file, the line whenever
//! the input has one, and the field (a dotted key path such as
//! `shapes[2].material`). Nothing here panics on user input. The work is
//! split by concept: `checked.rs` reads spanned values with checks,
//! `material.rs` validates materials, `objects.rs` builds shapes,
//! [`super::obj`] checks and parses OBJ meshes, and [`super::key_path`]
//! locates the errors `toml` itself reports.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::checked::{Cx, Res};
use super::environment::environment;
use super::format::{CameraDef, RenderDef, SceneFile, Spanned};
use super::lens::lens;
use super::lights::light;
use super::material::material;
use super::obj_materials::{self, MtlMaterials};
use super::objects::{generated_triangles, object};
use super::output::output;
pub use super::regular_file::read_regular_file;
use super::regular_file::{read_regular_bytes, utf8_text};
use super::textures;
use super::{show_point, Camera, RenderSettings, Scene, MAX_COORDINATE};
use crate::accel::Traversal;
use crate::error::InputError;
use crate::geometry::Vec3;
use crate::materials::Material;
use crate::sampling::SamplerKind;

/// OBJ loading, also used on its own (the benchmark's meshes).
pub use super::obj::load_obj;

/// Largest accepted image side, in pixels.
pub(crate) const MAX_RESOLUTION: u32 = 16384;

/// Largest accepted image, in pixels (8192², or 16384 × 4096): a render
/// holds about 111 bytes a pixel at its peak (two buffers of exact RGB
/// sums, 48 bytes each, `crate::render`; the film, 12; the 3-byte
/// preview), 7.4 GB at this bound; an allocation that fails is a runtime
/// error, not an abort.
pub(crate) const MAX_PIXELS: u64 = 1 << 26;

/// Largest accepted scene file, in bytes: scenes are a few kB; anything
/// near this is not a scene.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Largest accepted triangle count of a whole scene (2²⁵ ≈ 33.5 M):
/// about 30 bytes a triangle in the meshes and 50–100 more in a backend's
/// acceleration structure, a few GB at this bound.
pub(crate) const MAX_TRIANGLES: u64 = 1 << 25;

/// Largest accepted `render.max_depth`: a path that bounces this often in
/// a closed white box already costs a thousand times a typical depth, and
/// a larger bound would let such a scene render for days.
pub const MAX_DEPTH: u32 = 1024;

/// Reads and loads the scene file at `path`.
pub fn load(path: &Path) -> Result<Scene, InputError> {
    let bytes = read_regular_bytes(path, MAX_SCENE_BYTES)
        .map_err(|e| InputError::new(path, format!("cannot read scene file: {e}")))?;
    let text = utf8_text(bytes).map_err(|e| {
        InputError::new(
            path,
            format!(
                "byte {:#04x} at column {} is not valid UTF-8 (a scene file is UTF-8 text)",
                e.byte, e.column
            ),
        )
        .at_line(e.line)
    })?;
    load_str(&text, path)
}

/// Loads a scene from `text`; `path` names it in errors and is where
/// relative OBJ paths are resolved from (its directory).
pub fn load_str(text: &str, path: &Path) -> Result<Scene, InputError> {
    let cx = Cx { file: path, text };
    cx.no_control_characters()?;
    let def: SceneFile = toml::from_str(text).map_err(|e| cx.toml_error(&e))?;
    build(&cx, def)
}

/// The checked scene of a deserialized file.
fn build(cx: &Cx, def: SceneFile) -> Res<Scene> {
    let units_per_mm = match &def.units_per_mm {
        Some(u) => cx.positive(u, "units_per_mm")?,
        None => 1.0,
    };
    let Some(c) = &def.camera else {
        return Err(InputError::new(
            cx.file,
            "missing table `[camera]`: every scene needs one, with look_from, look_at and \
             resolution",
        )
        .in_field("camera"));
    };
    let camera = camera(cx, c, units_per_mm)?;
    let settings = settings(cx, &def.render)?;

    // Materials: indexed in name order (the map is sorted), so the same file
    // always gives the same indices.
    let scene_dir = cx.file.parent().unwrap_or(Path::new(""));
    let texture_table = textures::table(cx, scene_dir, &def.textures)?;
    let mut materials = Vec::with_capacity(def.materials.len());
    let mut material_index = HashMap::new();
    for (name, m) in &def.materials {
        material_index.insert(name.as_str(), materials.len());
        let units_def = def.units_per_mm.as_ref();
        let base = material(cx, name, m, units_per_mm, units_def, &texture_table)?;
        materials.push(textures::textured(cx, name, m, base, &texture_table)?);
    }
    let reads_textures: Vec<bool> = materials.iter().map(Material::reads_textures).collect();

    // The generated shapes' triangles are counted before any is built, the
    // OBJ meshes' as they are read: a scene beyond MAX_TRIANGLES fails
    // before it allocates them.
    let mut planned = 0;
    for (i, s) in def.shapes.iter().enumerate() {
        planned += generated_triangles(s.get_ref());
        if planned > MAX_TRIANGLES {
            let field = match &s.get_ref().subdivisions {
                Some(_) => format!("shapes[{i}].subdivisions"),
                None => format!("shapes[{i}]"),
            };
            return Err(too_many_triangles(cx, s.span(), &field, planned));
        }
    }
    let mut meshes = Vec::with_capacity(def.shapes.len());
    let mut objects = Vec::with_capacity(def.shapes.len());
    let mut total = planned;
    // An OBJ shape without `material` takes its MTL file's: one object per
    // material, the added materials numbered after the scene's.
    let mut mtl = MtlMaterials::default();
    let mut shape_of = Vec::with_capacity(def.shapes.len());
    for (i, s) in def.shapes.iter().enumerate() {
        let parts = if obj_materials::from_mtl(s.get_ref()) {
            let known = (&material_index, &reads_textures[..], materials.len());
            obj_materials::objects(cx, scene_dir, i, s, known, units_per_mm, &mut mtl)?
        } else {
            vec![object(
                cx,
                scene_dir,
                i,
                s,
                &material_index,
                &reads_textures,
                units_per_mm,
            )?]
        };
        for (mesh, obj) in parts {
            if let Some(f) = &s.get_ref().file {
                total += mesh.triangle_count() as u64;
                if total > MAX_TRIANGLES {
                    let field = format!("shapes[{i}].file");
                    return Err(too_many_triangles(cx, f.span(), &field, total));
                }
            }
            meshes.push(mesh);
            objects.push(obj);
            shape_of.push(i);
        }
    }
    materials.extend(mtl.materials);

    let environment = match &def.environment {
        Some(env) => environment(cx, scene_dir, env)?,
        None => None,
    };

    let lights = (def.lights.iter().enumerate())
        .map(|(i, l)| light(cx, i, l, units_per_mm))
        .collect::<Res<Vec<_>>>()?;
    let output = output(cx, &def, &objects, &shape_of, mtl.names)?;

    Ok(Scene {
        camera,
        settings,
        meshes: Arc::new(meshes),
        objects,
        materials,
        environment,
        lights,
        units_per_mm,
        source: Some(cx.file.to_path_buf()),
        output,
        notes: mtl.notes,
    })
}

/// The scene's triangles beyond [`MAX_TRIANGLES`], counted up to the shape
/// at `span`.
fn too_many_triangles(cx: &Cx, span: std::ops::Range<usize>, field: &str, n: u64) -> InputError {
    cx.err(
        span,
        field,
        format!(
            "the scene's meshes add up to {n} triangles with this shape, more than the \
             {MAX_TRIANGLES} supported (see \"Supported ranges\" in docs/scene-format.md)"
        ),
    )
}

/// `[camera]`: the required keys present, values finite, the field of view
/// in (0°, 180°), the resolution in range, and a well-defined view frame.
fn camera(cx: &Cx, c: &Spanned<CameraDef>, units_per_mm: f32) -> Res<Camera> {
    let d = c.get_ref();
    let required = |v, field| cx.required(v, Some(c.span()), field);
    let look_from = required(&d.look_from, "camera.look_from")?;
    let look_at = required(&d.look_at, "camera.look_at")?;
    let resolution = cx.required(&d.resolution, Some(c.span()), "camera.resolution")?;
    let from = cx.vec3(look_from, "camera.look_from")?;
    let at = cx.vec3(look_at, "camera.look_at")?;
    for (p, v, field) in [
        (from, look_from, "camera.look_from"),
        (at, look_at, "camera.look_at"),
    ] {
        if p.abs().max_element() > MAX_COORDINATE {
            return Err(cx.err(
                v.span(),
                field,
                format!(
                    "{} is beyond ±{MAX_COORDINATE:e} scene units, the supported \
                     range (see \"Supported ranges\" in docs/scene-format.md)",
                    show_point(p.to_array())
                ),
            ));
        }
    }
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
    let [w, h] = resolution.get_ref().0;
    if w == 0 || h == 0 || w > MAX_RESOLUTION || h > MAX_RESOLUTION {
        return Err(cx.err(
            resolution.span(),
            "camera.resolution",
            format!("expected [width, height] each in 1..={MAX_RESOLUTION}, found [{w}, {h}]"),
        ));
    }
    if w as u64 * h as u64 > MAX_PIXELS {
        return Err(cx.err(
            resolution.span(),
            "camera.resolution",
            format!(
                "[{w}, {h}] is {} pixels, more than the {MAX_PIXELS} (8192²) supported (see \
                 \"Supported ranges\" in docs/scene-format.md)",
                w as u64 * h as u64
            ),
        ));
    }
    let view = at - from;
    let scale = from.abs().max(at.abs()).max_element().max(1.0);
    if view.length() <= 1e-6 * scale {
        return Err(cx.err(
            look_at.span(),
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
    let lens = lens(cx, d, fov, view.length(), units_per_mm)?;
    Ok(Camera::new(from, at, up, fov, w, h).with_lens(lens))
}

/// `[render]`: defaults for what it does not give.
fn settings(cx: &Cx, r: &RenderDef) -> Res<RenderSettings> {
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
        if !(1..=MAX_DEPTH).contains(d.get_ref()) {
            return Err(cx.err(
                d.span(),
                "render.max_depth",
                format!(
                    "expected a path depth of 1 to {MAX_DEPTH}, found {}",
                    d.get_ref()
                ),
            ));
        }
        s.max_depth = *d.get_ref();
    }
    if let Some(seed) = r.seed {
        s.seed = seed;
    }
    if let Some(t) = &r.traversal {
        let name = t.get_ref().as_str();
        s.traversal = Traversal::parse(name).ok_or_else(|| {
            cx.err(
                t.span(),
                "render.traversal",
                format!("expected \"fast\" or \"watertight\", found \"{name}\""),
            )
        })?;
    }
    if let Some(k) = &r.sampler {
        let name = k.get_ref().as_str();
        s.sampler = SamplerKind::parse(name).ok_or_else(|| {
            cx.err(
                k.span(),
                "render.sampler",
                format!("expected {}, found \"{name}\"", SamplerKind::expected()),
            )
        })?;
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Mesh;
    use crate::materials::Material;
    use crate::scene::shapes;

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
                .join("../../scenes")
                .join(name),
        )
        .unwrap()
    }

    /// The mistake: an option of the table the scene format has no key
    /// for, or a key read but never handed to the table (the material
    /// keeps the default).
    #[cfg(feature = "subsurface")]
    #[test]
    fn every_estimator_option_is_a_scene_key_that_reaches_the_material() {
        use crate::materials::{EstimatorOptions, OPTIONS};
        let default = EstimatorOptions::default();
        for row in &OPTIONS {
            let d = (row.get)(&default);
            // a value other than the default, as the scene format writes it
            let other = match d.as_str() {
                "true" => "false".to_string(),
                "false" => "true".to_string(),
                _ => match row.values.iter().chain(row.research).find(|v| **v != d) {
                    // an integer-valued option's values are TOML integers
                    Some(v) if v.parse::<i64>().is_ok() => v.to_string(),
                    Some(v) => format!("\"{v}\""),
                    None => "0.5".to_string(),
                },
            };
            let s = scene(&format!(
                "[materials.m]\ntype = \"subsurface\"\npreset = \"marble\"\n{} = {other}\n\
                 [[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\n",
                row.name
            ));
            let Material::Subsurface(ss) = &s.materials[0] else {
                panic!("{}: not a subsurface material", row.name)
            };
            let got = (row.get)(ss.options());
            assert_ne!(got, d, "{} = {other} read as the default", row.name);
            assert_eq!(got, other.trim_matches('"'), "{}", row.name);
        }
    }

    #[test]
    fn traversal_is_fast_unless_the_scene_asks_for_watertight() {
        assert_eq!(scene("").settings.traversal, Traversal::Fast);
        for t in [Traversal::Fast, Traversal::Watertight] {
            let s = scene(&format!("[render]\ntraversal = \"{}\"\n", t.name()));
            assert_eq!(s.settings.traversal, t);
        }
    }

    #[test]
    fn sampler_is_sobol_unless_the_scene_asks_for_random() {
        assert_eq!(scene("").settings.sampler, SamplerKind::Sobol);
        for k in SamplerKind::ALL {
            let s = scene(&format!("[render]\nsampler = \"{}\"\n", k.name()));
            assert_eq!(s.settings.sampler, k);
        }
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
                seed: 99,
                traversal: Traversal::Fast,
                sampler: SamplerKind::Sobol,
            }
        );
        // Field by field: the derived members (tan of the fov) can differ in
        // the last bit between a constant-folded and a runtime `tan`.
        let c = &s.camera;
        assert_eq!(
            (c.look_from, c.look_at, c.up, c.fov_y, c.width, c.height),
            (Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Z, 60.0, 10, 20)
        );
        assert!(matches!(
            s.environment,
            Some(crate::environment::Environment::Constant(c)) if c == Vec3::new(0.5, 1.0, 2.0)
        ));
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
        let root = &Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let doc = std::fs::read_to_string(root.join("docs/scene-format.md")).unwrap();
        let start = doc.find("```toml\n").expect("example block") + "```toml\n".len();
        let end = start + doc[start..].find("```").unwrap();
        let s = load_str(&doc[start..end], &root.join("scenes/example.toml")).unwrap();
        assert_eq!(s.objects.len(), 5);
        assert_eq!(s.meshes[4].triangle_count(), 3674);
        assert_eq!(s.settings.seed, 1);
        assert!(s.environment.is_some());
    }
}
