//! `[[shapes]]` entries → meshes and [`Object`]s: the shape's mesh (a
//! generated sphere, quad or box, or an OBJ file), its transform (scale,
//! then rotations in order, then translation), its material by name and its
//! emission.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::checked::{Cx, Res};
use super::format::{Numbers, ShapeDef, ShapeKind, Spanned};
use super::key_path::{key_segment, quoted};
use super::lights::shape_emission;
use super::obj::{first_vertex_where, load_obj};
use super::regular_file::read_regular_file;
use super::transform::Transform;
use super::{shape_uvs, shapes, show_point, Object, MAX_COORDINATE};
use crate::error::InputError;
use crate::geometry::{Mesh, Vec3};

/// Highest accepted `subdivisions` for spheres: 20·4⁹ ≈ 5.2 M triangles.
pub(crate) const MAX_SPHERE_SUBDIVISIONS: u32 = 9;

/// The largest OBJ file read (bytes): parsing holds the text, the OBJ
/// library's index and position arrays and the mesh, at worst about eight
/// times the file's size (a polygon `f 1 1 1 …` is one triangle per two
/// bytes), so this bounds a mesh's memory to a few GB.
pub(crate) const MAX_OBJ_BYTES: u64 = 512 << 20;

/// The triangles a generated shape (sphere, quad, box) will have, known
/// before its mesh is built; 0 for an OBJ (counted once read) and for an
/// entry that [`object`] rejects.
pub(super) fn generated_triangles(d: &ShapeDef) -> u64 {
    match d.kind.as_ref().map(|k| *k.get_ref()) {
        Some(ShapeKind::Sphere) => match d.subdivisions.as_ref().map_or(4, |l| *l.get_ref()) {
            l if l <= MAX_SPHERE_SUBDIVISIONS => 20 * 4u64.pow(l),
            _ => 0,
        },
        Some(ShapeKind::Quad) => 2,
        Some(ShapeKind::Box) => 12,
        Some(ShapeKind::Obj) | None => 0,
    }
}

/// Shape `i` (entry `s`): its transformed mesh and its object. `materials`
/// maps material names to indices, `reads_textures` says per material
/// whether its meshes need texture coordinates (kept or generated there,
/// dropped elsewhere); OBJ paths are relative to `dir`.
pub(super) fn object(
    cx: &Cx,
    dir: &Path,
    i: usize,
    s: &Spanned<ShapeDef>,
    materials: &HashMap<&str, usize>,
    reads_textures: &[bool],
    units_per_mm: f32,
) -> Res<(Mesh, Object)> {
    let field = format!("shapes[{i}]");
    let sd = s.get_ref();
    let m = cx.required(&sd.material, Some(s.span()), &format!("{field}.material"))?;
    let Some(&mat) = materials.get(m.get_ref().as_str()) else {
        let mut known: Vec<String> = materials.keys().map(|k| key_segment(k)).collect();
        known.sort_unstable();
        let known = if known.is_empty() {
            "no materials are defined".to_string()
        } else {
            format!("defined: {}", known.join(", "))
        };
        return Err(cx.err(
            m.span(),
            &format!("{field}.material"),
            format!("unknown material {} ({known})", quoted(m.get_ref())),
        ));
    };
    let (mut mesh, source) = shape_mesh(cx, dir, &field, s)?;
    if reads_textures[mat] {
        texture_coordinates(cx, &field, s, &mut mesh, source.as_ref())?;
    } else {
        mesh.uvs = None;
    }
    let tf = transform(cx, &field, sd)?;
    tf.apply(&mut mesh);
    check_range(cx, &field, s, &mesh, &tf, source.as_ref())?;
    let emission = shape_emission(cx, &field, &sd.emission, &sd.power, &mesh, units_per_mm)?;
    let object = Object {
        name: sd.name.clone().unwrap_or(field),
        material: mat,
        emission,
        walk: false,
    };
    Ok((mesh, object))
}

/// Gives the untransformed `mesh` of shape `field` texture coordinates for
/// a material that reads a texture: generated for a built-in shape; an OBJ
/// file without them is refused.
fn texture_coordinates(
    cx: &Cx,
    field: &str,
    s: &Spanned<ShapeDef>,
    mesh: &mut Mesh,
    source: Option<&ObjSource>,
) -> Res<()> {
    if mesh.uvs.is_some() {
        return Ok(());
    }
    let d = s.get_ref();
    let material = d.material.as_ref().map_or("", |m| m.get_ref().as_str());
    match (source, d.kind.as_ref()) {
        (Some(src), _) => Err(InputError::new(
            &src.path,
            format!(
                "material {} of `{field}` in {} reads a texture, but this OBJ file has no \
                 texture coordinates on every face vertex (`vt`, faces `f v/vt ...`)",
                quoted(material),
                cx.file.display()
            ),
        )
        .in_field(format!("{field}.file"))),
        (None, Some(kind)) => {
            mesh.uvs = shape_uvs::generated_uvs(*kind.get_ref(), mesh);
            Ok(())
        }
        (None, None) => Ok(()),
    }
}

/// An OBJ file's path and text, kept to locate an out-of-range vertex.
pub(super) struct ObjSource {
    pub path: PathBuf,
    pub text: String,
}

/// Rejects a shape with a vertex beyond ±[`MAX_COORDINATE`] after its
/// transform, blaming what put it there: the `translate` if it is out of
/// range by itself, else the OBJ file's first `v` line that lands out of
/// range if it is out of range as written, else the `scale` (or the
/// `rotate`, with no scale).
pub(super) fn check_range(
    cx: &Cx,
    field: &str,
    s: &Spanned<ShapeDef>,
    mesh: &Mesh,
    tf: &Transform,
    source: Option<&ObjSource>,
) -> Res<()> {
    let lim = MAX_COORDINATE;
    let out = |p: Vec3| !(p.x.abs() <= lim && p.y.abs() <= lim && p.z.abs() <= lim);
    let Some(&p) = mesh.positions().iter().find(|&&p| out(p)) else {
        return Ok(());
    };
    let d = s.get_ref();
    let range = format!(
        "beyond ±{lim:e} scene units, the supported range (see \"Supported ranges\" in \
         docs/scene-format.md)"
    );
    let placed = format!(
        "a vertex of this shape lands at {} after the transform, {range}",
        show_point(p.to_array())
    );
    if let Some(t) = &d.translate {
        if t.get_ref().iter().any(|x| x.abs() > lim as f64) {
            return Err(cx.err(
                t.span(),
                &format!("{field}.translate"),
                format!(
                    "translate {} is {range}",
                    show_point(t.get_ref().map(|x| x as f32))
                ),
            ));
        }
    }
    if let Some(src) = source {
        match first_vertex_where(&src.text, |v| out(tf.point(v))) {
            Some((line, v)) if out(v) => {
                return Err(InputError::new(
                    &src.path,
                    format!(
                        "vertex {} is {range} (as written, and after the transform of `{field}` \
                         in {})",
                        show_point(v.to_array()),
                        cx.file.display()
                    ),
                )
                .at_line(line));
            }
            _ => {}
        }
    }
    let (span, key) = match (&d.scale, &d.rotate, &d.translate) {
        (Some(sc), _, _) => (sc.span(), "scale"),
        (None, Some(r), _) if !r.is_empty() => (r[0].span(), "rotate"),
        (None, _, Some(t)) => (t.span(), "translate"),
        _ => (s.span(), ""),
    };
    let f = if key.is_empty() {
        field.to_string()
    } else {
        format!("{field}.{key}")
    };
    Err(cx.err(span, &f, placed))
}

/// The mesh of shape `field` (entry `s`) before its transform, with the
/// OBJ file it came from; OBJ paths are relative to `dir`.
fn shape_mesh(
    cx: &Cx,
    dir: &Path,
    field: &str,
    s: &Spanned<ShapeDef>,
) -> Res<(Mesh, Option<ObjSource>)> {
    let d = s.get_ref();
    let kind = *cx
        .required(&d.kind, Some(s.span()), &format!("{field}.type"))?
        .get_ref();
    let allowed: &[&str] = match kind {
        ShapeKind::Obj => &["file", "smooth"],
        ShapeKind::Sphere => &["subdivisions"],
        ShapeKind::Quad | ShapeKind::Box => &[],
    };
    cx.only_keys(field, kind.name(), d.present_type_keys(), allowed)?;
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
            let text = read_regular_file(&path, MAX_OBJ_BYTES).map_err(|e| {
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
            Ok((mesh, Some(ObjSource { path, text })))
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
            Ok((shapes::sphere(level), None))
        }
        ShapeKind::Quad => Ok((shapes::quad(), None)),
        ShapeKind::Box => Ok((shapes::cuboid(), None)),
    }
}

/// The shape's scale, rotations and translation.
pub(super) fn transform(cx: &Cx, field: &str, d: &ShapeDef) -> Res<Transform> {
    let scale = match &d.scale {
        Some(s) => {
            let f = format!("{field}.scale");
            let v = cx.vec3(&Spanned::new(s.span(), Numbers(s.get_ref().0)), &f)?;
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
        let axis = cx.vec3(&Spanned::new(r.span(), Numbers(rot.axis)), &f)?;
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
