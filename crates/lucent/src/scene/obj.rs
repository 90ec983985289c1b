//! OBJ meshes: a line-by-line check of the statements the OBJ parser
//! (`tobj`) would trust, then the parse into one [`Mesh`].
//!
//! `tobj` can index out of bounds or overflow on bad face indices, so every
//! number and index is checked first (errors name the OBJ file and line),
//! and the `tobj` call is additionally fenced with `catch_unwind`.

use std::borrow::Cow;
use std::path::Path;

use glam::Vec2;

use crate::error::InputError;
use crate::geometry::{Mesh, Vec3};

/// Loads an OBJ file's faces (all objects and groups) as one mesh. Shading
/// normals and texture coordinates (`vt`) are kept only if every vertex
/// has them; materials (`mtllib`) are ignored — the scene file assigns the
/// material.
pub fn load_obj(text: &str, path: &Path) -> Result<Mesh, InputError> {
    load_obj_parts(text, path, &[]).map(|(mesh, _)| mesh)
}

/// [`load_obj`], and each triangle's material: the index in
/// `material_names` of the `usemtl` its face came under (None before any
/// `usemtl`, or under a name not in the list).
pub(super) fn load_obj_parts(
    text: &str,
    path: &Path,
    material_names: &[String],
) -> Result<(Mesh, Vec<Option<u32>>), InputError> {
    check_obj(text).map_err(|(line, msg)| InputError::new(path, msg).at_line(line))?;
    let text = &*without_vertex_colours(text);
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj is given the names alone (the MTL file was read by `super::mtl`),
    // so it only numbers the `usemtl` statements.
    let names: String = material_names
        .iter()
        .map(|n| format!("newmtl {n}\n"))
        .collect();
    let result = std::panic::catch_unwind(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| {
            if material_names.is_empty() {
                Err(tobj::LoadError::GenericFailure)
            } else {
                tobj::load_mtl_buf(&mut names.as_bytes())
            }
        })
    });
    let models = match result {
        Ok(Ok((models, _materials))) => models,
        Ok(Err(e)) => return Err(InputError::new(path, format!("invalid OBJ data: {e}"))),
        Err(_) => {
            return Err(InputError::new(
                path,
                "invalid OBJ data (the OBJ parser failed on this file)",
            ))
        }
    };

    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut all_normals = true;
    let mut texcoords: Vec<Vec2> = Vec::new();
    let mut all_texcoords = true;
    let mut indices = Vec::new();
    let mut tri_material = Vec::new();
    for m in &models {
        let m = &m.mesh;
        let id = m
            .material_id
            .and_then(|i| u32::try_from(i).ok())
            .filter(|&i| (i as usize) < material_names.len());
        let base = positions.len();
        let nv = m.positions.len() / 3;
        if m.positions.len() % 3 != 0 || m.indices.len() % 3 != 0 {
            return Err(InputError::new(
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
        if m.texcoords.len() == 2 * nv {
            texcoords.extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
        } else {
            all_texcoords = false;
        }
        for t in m.indices.chunks_exact(3) {
            if t.iter().any(|&i| i as usize >= nv) {
                return Err(InputError::new(
                    path,
                    "invalid OBJ data: face index out of range",
                ));
            }
            let off = |i: u32| u32::try_from(base + i as usize);
            match (off(t[0]), off(t[1]), off(t[2])) {
                (Ok(a), Ok(b), Ok(c)) => {
                    indices.push([a, b, c]);
                    tri_material.push(id);
                }
                _ => return Err(InputError::new(path, "OBJ file has too many vertices")),
            }
        }
    }
    if indices.is_empty() {
        return Err(InputError::new(
            path,
            "OBJ file contains no triangles (no `f` lines with 3 or more vertices)",
        ));
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(InputError::new(
            path,
            "OBJ file has non-finite vertex positions",
        ));
    }
    let normals = (all_normals && normals.iter().all(|n| n.is_finite() && n.length() > 0.0))
        .then(|| normals.into_iter().map(Vec3::normalize).collect());
    let uvs = (all_texcoords && texcoords.iter().all(|t| t.is_finite()))
        .then(|| corner_uvs(&texcoords, &indices));
    let mut mesh = Mesh::new(positions, indices, normals);
    mesh.uvs = uvs;
    Ok((mesh, tri_material))
}

/// Each triangle's corner texture coordinates, from per-vertex ones.
fn corner_uvs(texcoords: &[Vec2], indices: &[[u32; 3]]) -> Vec<[Vec2; 3]> {
    indices
        .iter()
        .map(|t| t.map(|i| texcoords[i as usize]))
        .collect()
}

/// The first `v` line of `text` (1-based) whose vertex (after the division
/// by w) satisfies `pred`, with that vertex. The file must have passed
/// [`load_obj`]'s checks.
pub(super) fn first_vertex_where(text: &str, pred: impl Fn(Vec3) -> bool) -> Option<(usize, Vec3)> {
    for (ln, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let v: Vec<f32> = words.filter_map(|w| w.parse().ok()).collect();
        if v.len() < 3 {
            continue;
        }
        let w = if v.len() == 4 { v[3] } else { 1.0 };
        let p = Vec3::new(v[0] / w, v[1] / w, v[2] / w);
        if pred(p) {
            return Some((ln + 1, p));
        }
    }
    None
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
                    check_vertex_ref(r, [nv, nt, nn]).map_err(|e| (ln, e.to_string()))?;
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The text with the colours of `v x y z r g b` lines dropped (`v x y z`),
/// other lines as they are. Colours are ignored anyway, and `tobj` rejects
/// a file where only some vertices carry them. Runs after [`check_obj`].
fn without_vertex_colours(text: &str) -> Cow<'_, str> {
    let coloured = |line: &str| {
        let mut w = line.split_whitespace();
        w.next() == Some("v") && w.count() == 6
    };
    if !text.lines().any(coloured) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        if coloured(line) {
            let xyz: Vec<&str> = line.split_whitespace().skip(1).take(3).collect();
            out.push_str("v ");
            out.push_str(&xyz.join(" "));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    Cow::Owned(out)
}

/// What is wrong with a face/line/point vertex reference.
#[derive(Debug, thiserror::Error)]
enum VertexRefError {
    #[error("malformed face vertex `{r}` (expected v, v/vt, v//vn or v/vt/vn)")]
    Malformed { r: String },
    #[error("malformed face vertex `{r}`: `{part}` is not an integer index")]
    NotAnIndex { r: String, part: String },
    #[error(
        "face {what} index {i} out of range: {count} defined before this line (indices start at 1; negative ones count back)"
    )]
    OutOfRange {
        what: &'static str,
        i: i64,
        count: usize,
    },
}

/// Checks one face/line/point vertex reference `v`, `v/vt`, `v//vn` or
/// `v/vt/vn` against the `[vertices, texture coordinates, normals]` defined
/// so far: each index non-zero and in range (negative ones count back).
fn check_vertex_ref(r: &str, counts: [usize; 3]) -> Result<(), VertexRefError> {
    let parts: Vec<&str> = r.split('/').collect();
    if parts.len() > 3 || parts[0].is_empty() {
        return Err(VertexRefError::Malformed { r: r.to_string() });
    }
    let what = ["vertex", "texture coordinate", "normal"];
    for (k, p) in parts.iter().enumerate() {
        if k > 0 && p.is_empty() {
            continue;
        }
        let (count, what) = (counts[k], what[k]);
        let i: i64 = p.parse().map_err(|_| VertexRefError::NotAnIndex {
            r: r.to_string(),
            part: p.to_string(),
        })?;
        let ok = if i > 0 {
            (i as u64) <= count as u64
        } else {
            i != 0 && i.unsigned_abs() <= count as u64
        };
        if !ok {
            return Err(VertexRefError::OutOfRange { what, i, count });
        }
    }
    Ok(())
}
