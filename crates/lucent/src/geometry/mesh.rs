//! An indexed triangle mesh in world space: positions (padded for
//! Embree), optional shading normals, optional texture coordinates (kept
//! only where a material reads a texture), and face normals and bounds
//! computed on first use.

use std::sync::OnceLock;

use glam::Vec2;

use super::Vec3;

/// An indexed triangle mesh in world space.
///
/// `positions` carries one hidden padding element past `vertex_count()`,
/// because Embree reads vertices with 16-byte loads and requires the buffer
/// to be readable 4 bytes past the last vertex; keeping it here lets Embree
/// share our buffer instead of copying it.
///
/// The unit face normals are computed on first use ([`Mesh::face_normal`])
/// and kept: the shading records and the probe estimator both read them, and
/// meshes that are only traced (benchmarks) never pay for them.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    positions: Vec<Vec3>,
    /// Triangles as vertex index triples. Edit them before the face normals
    /// are first read (or through [`Mesh::flip_winding`]), or the cached
    /// normals go stale.
    pub indices: Vec<[u32; 3]>,
    /// Optional per-vertex shading normals (unit length), same count as vertices.
    pub normals: Option<Vec<Vec3>>,
    /// Optional texture coordinates of each triangle's three corners, in
    /// the order of its indices (per triangle, so a seam needs no split
    /// vertices). Kept only for meshes whose material reads a texture.
    pub uvs: Option<Vec<[Vec2; 3]>>,
    face_normals: OnceLock<Vec<Vec3>>,
    bounding_radius: OnceLock<f32>,
}

impl Mesh {
    /// Builds a mesh; the caller guarantees indices are in range (the scene
    /// loader validates user data before calling this).
    pub fn new(positions: Vec<Vec3>, indices: Vec<[u32; 3]>, normals: Option<Vec<Vec3>>) -> Self {
        let mut p = Vec::with_capacity(positions.len() + 1);
        p.extend_from_slice(&positions);
        p.push(Vec3::ZERO);
        debug_assert!(indices
            .iter()
            .flatten()
            .all(|&i| (i as usize) < positions.len()));
        Mesh {
            positions: p,
            indices,
            normals,
            uvs: None,
            face_normals: OnceLock::new(),
            bounding_radius: OnceLock::new(),
        }
    }
    /// Vertex positions (without the padding element).
    pub fn positions(&self) -> &[Vec3] {
        &self.positions[..self.positions.len().saturating_sub(1)]
    }
    /// Vertex positions including one trailing padding element (for FFI sharing).
    pub fn padded_positions(&self) -> &[Vec3] {
        &self.positions
    }
    pub fn vertex_count(&self) -> usize {
        self.positions().len()
    }
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }
    pub fn triangle(&self, prim: u32) -> [Vec3; 3] {
        self.vertices(self.indices[prim as usize])
    }
    /// The positions of the vertices with indices `[a, b, c]`.
    #[inline]
    pub fn vertices(&self, [a, b, c]: [u32; 3]) -> [Vec3; 3] {
        let p = &self.positions;
        [p[a as usize], p[b as usize], p[c as usize]]
    }
    /// Applies `f` to every vertex position (and `g` to every normal).
    pub fn transform(&mut self, f: impl Fn(Vec3) -> Vec3, g: impl Fn(Vec3) -> Vec3) {
        self.face_normals = OnceLock::new();
        self.bounding_radius = OnceLock::new();
        let n = self.vertex_count();
        for p in &mut self.positions[..n] {
            *p = f(*p);
        }
        if let Some(ns) = &mut self.normals {
            for v in ns.iter_mut() {
                *v = g(*v).normalize_or_zero();
            }
        }
    }
    /// Flips the winding of every triangle (and normals), used when a
    /// transform has negative determinant.
    pub fn flip_winding(&mut self) {
        self.face_normals = OnceLock::new();
        for t in &mut self.indices {
            t.swap(1, 2);
        }
        for t in self.uvs.iter_mut().flatten() {
            t.swap(1, 2);
        }
    }
    /// Sets per-vertex normals to the area-weighted average of the normals
    /// of the triangles around each vertex (the cross product's length is
    /// twice the area, so summing unnormalized cross products weights by
    /// area). Vertices of only degenerate triangles get +z.
    pub(crate) fn compute_smooth_normals(&mut self) {
        let mut n = vec![Vec3::ZERO; self.vertex_count()];
        for &[a, b, c] in &self.indices {
            let p = &self.positions;
            let face = (p[b as usize] - p[a as usize]).cross(p[c as usize] - p[a as usize]);
            if face.is_finite() {
                for i in [a, b, c] {
                    n[i as usize] += face;
                }
            }
        }
        self.normals = Some(
            n.into_iter()
                .map(|v| v.try_normalize().unwrap_or(Vec3::Z))
                .collect(),
        );
    }

    /// The unit geometric normal of triangle `prim`, front face by
    /// counter-clockwise winding (outward for a consistently wound closed
    /// mesh); zero for a degenerate triangle.
    #[inline]
    pub fn face_normal(&self, prim: u32) -> Vec3 {
        self.face_normals()[prim as usize]
    }

    /// Half the diagonal of the vertices' axis-aligned bounding box: the
    /// radius of a ball around the box's centre that holds the mesh (at
    /// most √3 times the smallest such ball's). 0 for an empty mesh;
    /// computed once, on the first call.
    pub fn bounding_radius(&self) -> f32 {
        *self.bounding_radius.get_or_init(|| {
            self.bounds()
                .map_or(0.0, |(lo, hi)| 0.5 * (hi - lo).length())
        })
    }

    /// The vertices' axis-aligned bounding box (lo, hi); None without
    /// vertices.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let p = self.positions();
        let first = *p.first()?;
        Some(
            p.iter()
                .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))),
        )
    }

    /// [`face_normal`](Self::face_normal) of every triangle, in order;
    /// computed once, on the first call.
    pub fn face_normals(&self) -> &[Vec3] {
        self.face_normals.get_or_init(|| {
            self.indices
                .iter()
                .map(|&idx| {
                    let [a, b, c] = self.vertices(idx);
                    (b - a).cross(c - a).normalize_or_zero()
                })
                .collect()
        })
    }

    pub fn area(&self, prim: u32) -> f32 {
        let [a, b, c] = self.triangle(prim);
        0.5 * (b - a).cross(c - a).length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_padding_is_hidden() {
        let m = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]], None);
        assert_eq!(m.vertex_count(), 3);
        assert_eq!(m.padded_positions().len(), 4);
        assert!((m.area(0) - 0.5).abs() < 1e-7);
    }

    #[test]
    fn face_normals_follow_winding_and_edits() {
        let mut m = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(2.0, 0.0, 0.0)],
            vec![[0, 1, 2], [0, 1, 3]],
            None,
        );
        assert_eq!(m.face_normal(0), Vec3::Z);
        // collinear vertices: a degenerate triangle has no normal
        assert_eq!(m.face_normal(1), Vec3::ZERO);
        m.flip_winding();
        assert_eq!(m.face_normal(0), -Vec3::Z);
        m.transform(|p| Vec3::new(p.x, p.z, p.y), |n| n);
        assert_eq!(m.face_normals(), &[Vec3::Y, Vec3::ZERO]);
    }

    #[test]
    fn smooth_normals_average_adjacent_faces_by_area() {
        // two triangles folded along the x axis: one in the xy plane (area
        // 1/2, normal +z), one in the xz plane (area 1, normal +y)
        let mut m = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.0, 0.0, 2.0)],
            vec![[0, 1, 2], [0, 3, 1]],
            None,
        );
        m.compute_smooth_normals();
        let n = m.normals.unwrap();
        assert!(n[2].abs_diff_eq(Vec3::Z, 1e-6));
        assert!(n[3].abs_diff_eq(Vec3::Y, 1e-6));
        assert!(n[0].abs_diff_eq(Vec3::new(0.0, 2.0, 1.0).normalize(), 1e-6));
    }
}
