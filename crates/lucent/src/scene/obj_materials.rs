//! An OBJ shape without a scene `material`: its faces take the materials of
//! the OBJ's `mtllib` (`super::mtl`), one object per material used, each
//! with the triangles whose `usemtl` names it (`docs/scene-format.md`,
//! "OBJ materials"). A scene `[materials.NAME]` of the same name overrides
//! an MTL material. Textures are read once per file and colour space.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec2;

use super::checked::{Cx, Res};
use super::format::{ShapeDef, ShapeKind, Spanned};
use super::key_path::quoted;
use super::lights::shape_emission;
use super::mtl::{self, MtlMaterial};
use super::obj::load_obj_parts;
use super::objects::{check_range, transform, ObjSource, MAX_OBJ_BYTES};
use super::regular_file::read_regular_file;
use super::{textures, Object};
use crate::error::InputError;
use crate::geometry::{Mesh, Vec3};
use crate::materials::{Bump, Material, Plastic, TextureUse, Textured};
use crate::texture::{ColorSpace, Texture, TextureRef, Wrap};

/// The albedo of an MTL material without `Kd` or `map_Kd`.
pub(super) const DEFAULT_KD: f32 = 0.8;

/// The materials the scene's MTL files add after its own, and what their
/// reading noted for the user.
#[derive(Default)]
pub(super) struct MtlMaterials {
    /// Added materials, numbered after the scene's own.
    pub materials: Vec<Material>,
    pub names: Vec<String>,
    /// By MTL file, material name and whether its `map_Bump` is a normal
    /// map: the index in `materials`.
    by_key: HashMap<(PathBuf, String, bool), usize>,
    textures: HashMap<(PathBuf, bool), Arc<Texture>>,
    /// What was read past or approximated, one line each.
    pub notes: Vec<String>,
}

/// Whether shape `s` takes its materials from its OBJ's `mtllib`: an OBJ
/// shape without `material`.
pub(super) fn from_mtl(s: &ShapeDef) -> bool {
    s.material.is_none()
        && s.kind
            .as_ref()
            .is_some_and(|k| *k.get_ref() == ShapeKind::Obj)
}

/// The scene's own materials: indices by name (an MTL material of the same
/// name is overridden), whether each reads textures, and their count (the
/// first index of an added material).
pub(super) type Known<'a> = (&'a HashMap<&'a str, usize>, &'a [bool], usize);

/// The objects of shape `i` (entry `s`, an OBJ without `material`): one per
/// MTL material its faces use.
pub(super) fn objects(
    cx: &Cx,
    dir: &Path,
    i: usize,
    s: &Spanned<ShapeDef>,
    (scene, reads_textures, scene_count): Known,
    units_per_mm: f32,
    out: &mut MtlMaterials,
) -> Res<Vec<(Mesh, Object)>> {
    let field = format!("shapes[{i}]");
    let d = s.get_ref();
    cx.only_keys(
        &field,
        "obj",
        d.present_type_keys(),
        &["file", "smooth", "map_bump"],
    )?;
    let bump_is_normal = bump_is_normal(cx, &field, d)?;
    let f = cx.required(&d.file, Some(s.span()), &format!("{field}.file"))?;
    let path = dir.join(f.get_ref());
    let text = read_regular_file(&path, MAX_OBJ_BYTES).map_err(|e| {
        cx.err(
            f.span(),
            &format!("{field}.file"),
            format!("cannot read OBJ file {}: {e}", path.display()),
        )
    })?;
    let Some((mtl_name, mtl_line)) = mtllib(&text, &path)? else {
        return Err(cx.err(
            s.span(),
            &format!("{field}.material"),
            format!(
                "missing field `material`: give one, or an OBJ file with an `mtllib` ({} has none)",
                path.display()
            ),
        ));
    };
    let mtl_path = path.parent().unwrap_or(Path::new("")).join(&mtl_name);
    let mtl_text = read_regular_file(&mtl_path, MAX_OBJ_BYTES).map_err(|e| {
        InputError::new(
            &path,
            format!("cannot read MTL file {}: {e}", mtl_path.display()),
        )
        .at_line(mtl_line)
    })?;
    let lib = mtl::parse(&mtl_text, &mtl_path)?;
    if !lib.ignored.is_empty() {
        let keys: Vec<String> = lib
            .ignored
            .iter()
            .map(|(k, l)| format!("{k} (line {l})"))
            .collect();
        out.notes.push(format!(
            "{}: ignored MTL keys: {}",
            mtl_path.display(),
            keys.join(", ")
        ));
    }
    let names: Vec<String> = lib.materials.iter().map(|m| m.name.clone()).collect();
    let (mut mesh, tri_material) = load_obj_parts(&text, &path, &names)?;
    if d.smooth.as_ref().is_some_and(|b| *b.get_ref()) && mesh.normals.is_none() {
        mesh.compute_smooth_normals();
    }
    let missing = tri_material.iter().position(Option::is_none);
    if missing.is_some() {
        return Err(unassigned(&text, &path, &names));
    }
    let tf = transform(cx, &field, d)?;
    // `power` spreads over the whole mesh's area: every part emits the
    // same radiance
    let emission = if d.power.is_some() {
        let mut whole = mesh.clone();
        tf.apply(&mut whole);
        shape_emission(cx, &field, &d.emission, &d.power, &whole, units_per_mm)?
    } else {
        shape_emission(cx, &field, &d.emission, &None, &mesh, units_per_mm)?
    };
    let source = ObjSource {
        path: path.clone(),
        text,
    };
    let mut parts = Vec::new();
    for k in first_uses(&tri_material) {
        let m = &lib.materials[k as usize];
        let (material, textured) = match scene.get(m.name.as_str()) {
            Some(&idx) => (idx, reads_textures[idx]),
            None => {
                let idx = added(&mtl_path, m, bump_is_normal, out)?;
                (scene_count + idx, out.materials[idx].reads_textures())
            }
        };
        let mut part = sub_mesh(&mesh, &tri_material, k);
        if !textured {
            part.uvs = None;
        } else if part.uvs.is_none() {
            return Err(InputError::new(
                &path,
                format!(
                    "material {} reads a texture, but this OBJ file has no texture coordinates \
                     on every face vertex (`vt`, faces `f v/vt ...`)",
                    quoted(&m.name)
                ),
            )
            .in_field(format!("{field}.file")));
        }
        tf.apply(&mut part);
        check_range(cx, &field, s, &part, &tf, Some(&source))?;
        let name = format!("{}/{}", d.name.clone().unwrap_or(field.clone()), m.name);
        parts.push((
            part,
            Object {
                name,
                material,
                emission,
                walk: false,
            },
        ));
    }
    Ok(parts)
}

/// The OBJ's `mtllib` file name and line; None without one. Two are refused.
fn mtllib(text: &str, path: &Path) -> Result<Option<(String, usize)>, InputError> {
    let mut found = None;
    for (ln, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("mtllib") {
            continue;
        }
        let name: Vec<&str> = words.collect();
        if name.is_empty() {
            return Err(InputError::new(path, "`mtllib` needs a file name").at_line(ln + 1));
        }
        if found.is_some() {
            return Err(InputError::new(
                path,
                "a second `mtllib`: lucent reads one material library per OBJ file",
            )
            .at_line(ln + 1));
        }
        found = Some((name.join(" "), ln + 1));
    }
    Ok(found)
}

/// The error for faces without a material: the first `usemtl` naming no
/// material of the library, or faces before any `usemtl`.
fn unassigned(text: &str, path: &Path, names: &[String]) -> InputError {
    for (ln, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() == Some("usemtl") {
            let name = words.collect::<Vec<_>>().join(" ");
            if !names.contains(&name) {
                return InputError::new(
                    path,
                    format!("`usemtl {name}` names no `newmtl` of the material library"),
                )
                .at_line(ln + 1);
            }
        }
    }
    InputError::new(
        path,
        "faces before the first `usemtl` have no material: add a `usemtl`, or give the shape a \
         `material` in the scene",
    )
}

/// The materials of `tri_material` (all Some), in order of first use.
fn first_uses(tri_material: &[Option<u32>]) -> Vec<u32> {
    let mut seen = Vec::new();
    for k in tri_material.iter().flatten() {
        if !seen.contains(k) {
            seen.push(*k);
        }
    }
    seen
}

/// The triangles of `mesh` whose material is `k`, with only their vertices.
fn sub_mesh(mesh: &Mesh, tri_material: &[Option<u32>], k: u32) -> Mesh {
    let mut remap = vec![u32::MAX; mesh.vertex_count()];
    let (mut positions, mut normals) = (Vec::new(), Vec::new());
    let mut indices = Vec::new();
    let mut uvs: Vec<[Vec2; 3]> = Vec::new();
    for (t, tri) in mesh.indices.iter().enumerate() {
        if tri_material[t] != Some(k) {
            continue;
        }
        indices.push(tri.map(|v| {
            if remap[v as usize] == u32::MAX {
                remap[v as usize] = positions.len() as u32;
                positions.push(mesh.positions()[v as usize]);
                if let Some(n) = &mesh.normals {
                    normals.push(n[v as usize]);
                }
            }
            remap[v as usize]
        }));
        if let Some(u) = &mesh.uvs {
            uvs.push(u[t]);
        }
    }
    let normals = mesh.normals.is_some().then_some(normals);
    let mut part = Mesh::new(positions, indices, normals);
    part.uvs = mesh.uvs.is_some().then_some(uvs);
    part
}

/// Whether the OBJ shape `d` reads its MTL's `map_Bump` / `bump` images
/// as normal maps: its `map_bump`, `"height"` (the default) or
/// `"normal"`.
fn bump_is_normal(cx: &Cx, field: &str, d: &ShapeDef) -> Res<bool> {
    let Some(v) = &d.map_bump else {
        return Ok(false);
    };
    match v.get_ref().as_str() {
        "height" => Ok(false),
        "normal" => Ok(true),
        other => Err(cx.err(
            v.span(),
            &format!("{field}.map_bump"),
            format!("expected \"height\" or \"normal\", found {}", quoted(other)),
        )),
    }
}

/// The index in `out.materials` of MTL material `m` of `mtl_path`, made on
/// its first use (`bump_is_normal`: its `map_Bump` read as a normal map).
fn added(
    mtl_path: &Path,
    m: &MtlMaterial,
    bump_is_normal: bool,
    out: &mut MtlMaterials,
) -> Result<usize, InputError> {
    let key = (mtl_path.to_path_buf(), m.name.clone(), bump_is_normal);
    if let Some(&i) = out.by_key.get(&key) {
        return Ok(i);
    }
    let material = material(mtl_path, m, bump_is_normal, out)?;
    out.materials.push(material);
    out.names.push(m.name.clone());
    out.by_key.insert(key, out.materials.len() - 1);
    Ok(out.materials.len() - 1)
}

/// The lucent material of MTL material `m`: diffuse (albedo `Kd`, or
/// `map_Kd`), or plastic of roughness `Pr` / `Ns` when untextured; a
/// normal map from `norm`, a height map from `map_Bump` / `bump` (its
/// `-bm` the `bump_scale`), or a normal map from them where
/// `bump_is_normal`.
fn material(
    mtl_path: &Path,
    m: &MtlMaterial,
    bump_is_normal: bool,
    out: &mut MtlMaterials,
) -> Result<Material, InputError> {
    let kd = m.kd.unwrap_or(Vec3::splat(DEFAULT_KD));
    let mut texture = |(file, line): &(String, usize), linear: bool| {
        let path = mtl_path.parent().unwrap_or(Path::new("")).join(file);
        let key = (path.clone(), linear);
        if let Some(t) = out.textures.get(&key) {
            return Ok(t.clone());
        }
        let space = if linear {
            ColorSpace::Linear
        } else {
            ColorSpace::Srgb
        };
        let t = textures::load(&path, space, Wrap::Repeat).map_err(|e| {
            InputError::new(mtl_path, format!("texture image {}: {e}", path.display()))
                .at_line(*line)
        })?;
        out.textures.insert(key, t.clone());
        Ok::<_, InputError>(t)
    };
    let albedo = m.map_kd.as_ref().map(|f| texture(f, false)).transpose()?;
    let mut notes = Vec::new();
    let mut note = |what: &str| {
        notes.push(format!(
            "{}: material {}: {what}",
            mtl_path.display(),
            quoted(&m.name)
        ))
    };
    // (the normal map's file and key, the height map's file and scale)
    let (normal_file, bump_file) = match (&m.normal, &m.bump) {
        (Some(n), b) => {
            if b.is_some() {
                note("`map_Bump` ignored: `norm` gives the normal");
            }
            (Some((n.clone(), "norm")), None)
        }
        (None, Some((f, line, bm))) if bump_is_normal => {
            if *bm != 1.0 {
                note("`-bm` ignored: `map_Bump` is read as a normal map");
            }
            (Some(((f.clone(), *line), "map_Bump")), None)
        }
        (None, Some((f, line, bm))) => (None, Some(((f.clone(), *line), *bm))),
        (None, None) => (None, None),
    };
    let normal = normal_file
        .as_ref()
        .map(|(f, _)| texture(f, true))
        .transpose()?;
    let bump = match &bump_file {
        Some((f, scale)) => Some(Bump {
            texture: texture(f, true)?,
            scale: *scale,
        }),
        None => None,
    };
    out.notes.append(&mut notes);
    let base = match (m.roughness, &albedo) {
        (Some(r), None) => Material::Plastic(Arc::new(Plastic::new(kd, 1.5, r))),
        (r, Some(_)) => {
            if r.is_some() {
                out.notes.push(format!(
                    "{}: material {}: `Ns`/`Pr` ignored: a textured albedo is diffuse",
                    mtl_path.display(),
                    quoted(&m.name)
                ));
            }
            if m.kd.is_some() {
                out.notes.push(format!(
                    "{}: material {}: `Kd` ignored: `map_Kd` gives the albedo",
                    mtl_path.display(),
                    quoted(&m.name)
                ));
            }
            Material::Diffuse { albedo: Vec3::ONE }
        }
        (None, None) => Material::Diffuse { albedo: kd },
    };
    if albedo.is_none() && normal.is_none() && bump.is_none() {
        return Ok(base);
    }
    let albedo = albedo.map(|texture| TextureRef {
        texture,
        scale: Vec3::ONE,
    });
    let names = [
        m.map_kd.as_ref().map(|(f, _)| ("map_Kd", f)),
        normal_file.as_ref().map(|((f, _), key)| (*key, f)),
        bump_file.as_ref().map(|((f, _), _)| ("map_Bump", f)),
    ]
    .into_iter()
    .flatten()
    .map(|(key, f)| TextureUse {
        key,
        texture: f.clone(),
    })
    .collect();
    let mut t = Textured::new(base, albedo, normal).named(names);
    t.bump = bump;
    Ok(Material::Textured(Arc::new(t)))
}
