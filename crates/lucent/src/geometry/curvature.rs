//! The curvature of a triangle mesh, estimated per triangle from its
//! vertex positions and shading normals, and the per-mesh cache of those
//! estimates a subsurface render reads at every hit.
//!
//! [`curvature`] (the largest rate at which the normal turns along an edge)
//! and [`exit_curvature`] (that, floored at 1/bounding radius) feed the
//! probe-axis rule (`docs/bssrdf.md` §5); [`mean_curvature`] feeds the
//! curvature correction and the control variate's model surface
//! (`docs/bssrdf.md` §10, which derives it). [`MeshCurvature`] holds both
//! per triangle with the mesh's [`SharpEdges`].

use super::sharp_edges::SharpEdges;
use super::{Mesh, Vec3};

/// The curvature of `mesh` at triangle `prim`, from its shading normals:
/// the largest |n_i − n_j| / |p_i − p_j| over its edges (1/scene units),
/// the rate at which the normal turns along the surface. Exact (1/ρ) on a
/// triangle of a sphere of radius ρ whose vertex normals are radial; 0 on
/// a mesh without shading normals (flat-shaded: nothing tells its facets
/// from a flat surface), and for a degenerate edge. A deterministic
/// function of the exit point's triangle, as the probe axes' probabilities
/// built on it must be (`ProbeAxes::Curvature`).
pub fn curvature(mesh: &Mesh, prim: u32) -> f32 {
    let Some(normals) = &mesh.normals else {
        return 0.0;
    };
    let idx = mesh.indices[prim as usize];
    let p = mesh.vertices(idx);
    let n = idx.map(|i| normals[i as usize]);
    let mut k = 0.0f32;
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let len = (p[i] - p[j]).length();
        let turn = (n[i] - n[j]).length();
        if len > 0.0 {
            let e = turn / len;
            if e.is_finite() {
                k = k.max(e);
            }
        }
    }
    k
}

/// The curvature the probe-axis rule reads at an exit point on triangle
/// `prim` of `mesh`: [`curvature`], but at least 1/R for the mesh's
/// [`bounding radius`](Mesh::bounding_radius) R.
///
/// Why the floor: a closed surface inside a ball of radius R turns at
/// least as fast as 1/R somewhere (at its point farthest from the centre
/// every normal curvature is ≥ 1/R), so an object no larger than the
/// profile cannot look flat to it. On a smooth-shaded mesh the vertex
/// normals already show that turning (a sphere of radius ρ reads 1/ρ ≥
/// 1/R); on a flat-shaded one — the `box` shape, an OBJ without normals —
/// the turning sits in edges the normals do not see, and [`curvature`]
/// reads 0 everywhere. With the floor, an object smaller than the
/// profile's reach (κ·d ≥ 1) gets mis3's tangent probabilities; a large
/// flat-shaded object keeps ε near ε_min away from everything but its
/// edges, where the weight bound of `ProbeAxes::weight_bound` still holds.
/// An open mesh (a quad) gets the same floor; it only raises ε.
pub fn exit_curvature(mesh: &Mesh, prim: u32) -> f32 {
    let r = mesh.bounding_radius();
    let floor = if r > 0.0 { 1.0 / r } else { 0.0 };
    curvature(mesh, prim).max(floor)
}

/// The convex mean curvature of triangle `prim` of `mesh` (1/scene units)
/// from its shading normals (`docs/bssrdf.md` §10: the mean over its three
/// edges of the normal curvature along each, (n_i − n_j)·(p_i − p_j) /
/// |p_i − p_j|²); 0 without shading normals, on
/// flat or concave triangles, and for degenerate edges.
pub fn mean_curvature(mesh: &Mesh, prim: u32) -> f32 {
    let Some(normals) = &mesh.normals else {
        return 0.0;
    };
    let idx = mesh.indices[prim as usize];
    let p = mesh.vertices(idx);
    let n = idx.map(|i| normals[i as usize]);
    let (mut sum, mut edges) = (0.0f32, 0);
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let e = p[i] - p[j];
        let len2 = e.length_squared();
        if len2 > 0.0 {
            let k = (n[i] - n[j]).dot(e) / len2;
            if k.is_finite() {
                sum += k;
                edges += 1;
            }
        }
    }
    if edges == 0 {
        0.0
    } else {
        (sum / edges as f32).max(0.0)
    }
}

/// The two curvatures a subsurface hit reads of its triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TriangleCurvature {
    /// [`exit_curvature`]: what the probe-axis rule reads.
    pub exit: f32,
    /// [`mean_curvature`]: what the curvature correction and the control
    /// variate's model surface read.
    pub mean: f32,
}

impl TriangleCurvature {
    /// Both curvatures of triangle `prim` of `mesh`, computed from its
    /// vertex normals.
    #[inline]
    pub fn of(mesh: &Mesh, prim: u32) -> Self {
        TriangleCurvature {
            exit: exit_curvature(mesh, prim),
            mean: mean_curvature(mesh, prim),
        }
    }
}

/// Per triangle of one mesh, its [`TriangleCurvature`], computed once when
/// the render starts (`crate::integrator::Context`, for meshes with a
/// subsurface material) instead of at every hit: each is a deterministic
/// function of the triangle, so the values, and the pixels, are the same
/// bit for bit (tested). With them, the mesh's sharp edges
/// ([`SharpEdges`]), which the probe axes also read
/// ([`MeshCurvature::axes`]).
#[derive(Clone, Debug, Default)]
pub struct MeshCurvature {
    per_prim: Vec<TriangleCurvature>,
    /// The sharp edges, None when the mesh has none.
    edges: Option<SharpEdges>,
    /// How far a sharp edge is looked for: the material's Rmax.
    reach: f32,
}

impl MeshCurvature {
    /// The cache for `mesh`, its sharp edges looked for within `reach`
    /// (the material's Rmax, scene units) of an exit point; `reach` = 0
    /// (a material whose axis rule reads no curvature) skips finding them.
    pub fn new(mesh: &Mesh, reach: f32) -> Self {
        MeshCurvature {
            per_prim: (0..mesh.triangle_count() as u32)
                .map(|prim| TriangleCurvature::of(mesh, prim))
                .collect(),
            edges: if reach > 0.0 {
                SharpEdges::new(mesh)
            } else {
                None
            },
            reach,
        }
    }

    /// Both curvatures of triangle `prim`.
    #[inline]
    pub fn triangle(&self, prim: u32) -> TriangleCurvature {
        self.per_prim[prim as usize]
    }

    /// Every triangle's curvatures, in order.
    pub fn triangles(&self) -> &[TriangleCurvature] {
        &self.per_prim
    }

    /// [`exit_curvature`] of triangle `prim`.
    #[inline]
    pub fn exit(&self, prim: u32) -> f32 {
        self.per_prim[prim as usize].exit
    }

    /// [`mean_curvature`] of triangle `prim`.
    #[inline]
    pub fn mean(&self, prim: u32) -> f32 {
        self.per_prim[prim as usize].mean
    }

    /// The curvature the probe axes read at exit point `xo` on triangle
    /// `prim`: [`exit_curvature`], or 1/s where a sharp edge lies at a
    /// distance s < reach and that is larger ([`super::sharp_edges`]).
    #[inline]
    pub fn axes(&self, prim: u32, xo: Vec3) -> f32 {
        self.axes_up_to(prim, xo, f32::INFINITY)
    }

    /// [`axes`](Self::axes) for a reader to which every curvature ≥
    /// `saturated` is the same (the axis rule's ¼ beyond
    /// `ProbeSampler::saturated_curvature`): the value itself where it is
    /// below `saturated`, some value ≥ `saturated` otherwise. The edge
    /// search then looks no farther than 1/κ(triangle), beyond which an
    /// edge cannot raise κ, and stops at the first edge within
    /// 1/`saturated`; none is made when the triangle's own κ saturates.
    #[inline]
    pub fn axes_up_to(&self, prim: u32, xo: Vec3, saturated: f32) -> f32 {
        let k = self.exit(prim);
        if k >= saturated {
            return k;
        }
        // (a NaN κ goes on to the search, as in `axes`)
        let Some(edges) = self.edges.as_ref() else {
            return k;
        };
        // An edge at s ≥ (1/k)(1 + 2⁻²⁰) has fl(1/s) < k: the margin
        // covers the roundings of 1/k and 1/s (each ≤ 2⁻²⁴ relative).
        let reach = if k > 0.0 {
            self.reach.min(k.recip() * (1.0 + 2f32.powi(-20)))
        } else {
            self.reach
        };
        // 1/s > `saturated` for s ≤ enough, by the same margin.
        let enough = saturated.recip() * (1.0 - 2f32.powi(-20));
        let s = edges.nearest(xo, reach, enough).0;
        if s < reach {
            k.max(1.0 / s)
        } else {
            k
        }
    }

    /// How many sharp edges the mesh has.
    pub fn sharp_edge_count(&self) -> usize {
        self.edges.as_ref().map_or(0, SharpEdges::count)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A closed UV sphere of radius `rs` around `c`: `rings` rings of
    /// 2·`rings` segments, one vertex at each pole, radial shading normals.
    pub(crate) fn uv_sphere(c: Vec3, rs: f32, rings: u32) -> Mesh {
        use std::f32::consts::{PI, TAU};
        let segs = 2 * rings;
        let mut p = vec![c + Vec3::Z * rs];
        for i in 1..rings {
            let th = PI * i as f32 / rings as f32;
            for j in 0..segs {
                let ph = TAU * j as f32 / segs as f32;
                p.push(c + rs * Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
            }
        }
        p.push(c - Vec3::Z * rs);
        let south = p.len() as u32 - 1;
        let v = |i: u32, j: u32| 1 + (i - 1) * segs + j % segs;
        let mut idx = Vec::new();
        for j in 0..segs {
            idx.push([0, v(1, j), v(1, j + 1)]);
            idx.push([south, v(rings - 1, j + 1), v(rings - 1, j)]);
        }
        for i in 1..rings - 1 {
            for j in 0..segs {
                idx.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                idx.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
        // radial shading normals: `curvature` reads 1/rs
        let normals = p.iter().map(|&q| (q - c).normalize()).collect();
        Mesh::new(p, idx, Some(normals))
    }

    /// Square planes of half-size `l` at heights `zs` (normal +z), one
    /// mesh without shading normals.
    fn planes(l: f32, zs: &[f32]) -> Mesh {
        let mut p = Vec::new();
        let mut idx = Vec::new();
        for &z in zs {
            let k = p.len() as u32;
            p.extend([
                Vec3::new(-l, -l, z),
                Vec3::new(l, -l, z),
                Vec3::new(l, l, z),
                Vec3::new(-l, l, z),
            ]);
            idx.extend([[k, k + 1, k + 2], [k, k + 2, k + 3]]);
        }
        Mesh::new(p, idx, None)
    }

    #[test]
    fn curvature_is_one_over_the_radius_of_a_sphere_and_zero_when_flat() {
        // radial shading normals on a UV sphere of radius 2.5: every
        // triangle reads 1/2.5 (|n_i − n_j| = |p_i − p_j|/ρ exactly)
        let rs = 2.5f32;
        let sphere = uv_sphere(Vec3::new(1.0, -2.0, 0.5), rs, 10);
        for prim in 0..sphere.triangle_count() as u32 {
            let k = curvature(&sphere, prim);
            assert!((k * rs - 1.0).abs() < 1e-4, "triangle {prim}: {k}");
        }
        // no shading normals: nothing says the surface turns
        let flat = planes(3.0, &[0.0, -1.0]);
        assert!((0..flat.triangle_count() as u32).all(|p| curvature(&flat, p) == 0.0));
        // equal normals (a flat patch with normals) and a degenerate edge
        let mut m = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::X, Vec3::Y],
            vec![[0, 1, 3], [0, 1, 2]],
            Some(vec![Vec3::Z; 4]),
        );
        assert_eq!(curvature(&m, 0), 0.0);
        m.normals = Some(vec![Vec3::Z, Vec3::Z, Vec3::X, Vec3::Z]);
        let k = curvature(&m, 1);
        assert!(k.is_finite() && (k - 2f32.sqrt()).abs() < 1e-6, "{k}");
    }

    #[test]
    fn exit_curvature_floors_flat_shaded_objects_at_their_size() {
        use crate::bssrdf::probe::tangent_probability;
        // a flat-shaded cube of half-side h: no shading normals, so
        // `curvature` reads 0, and the floor is 1/(h√3)
        let h = 0.5f32;
        let c = [-h, h];
        let pos: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new(c[i & 1], c[(i >> 1) & 1], c[(i >> 2) & 1]))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let idx = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let cube = Mesh::new(pos, idx, None);
        let floor = 1.0 / (h * 3f32.sqrt());
        for prim in 0..cube.triangle_count() as u32 {
            assert_eq!(curvature(&cube, prim), 0.0);
            assert!((exit_curvature(&cube, prim) - floor).abs() < 1e-6);
        }
        // a profile as wide as the cube gets mis3's tangent probabilities;
        // without the floor it would get ε_min
        let d = 2.0 * h;
        assert_eq!(
            tangent_probability((exit_curvature(&cube, 0) * d) as f64),
            0.25
        );
        assert!(tangent_probability((curvature(&cube, 0) * d) as f64) < 0.03);
        // a smooth sphere's own curvature 1/ρ is above its floor 1/(ρ√3)
        let rs = 2.5f32;
        let sphere = uv_sphere(Vec3::new(1.0, -2.0, 0.5), rs, 10);
        for prim in 0..sphere.triangle_count() as u32 {
            assert_eq!(exit_curvature(&sphere, prim), curvature(&sphere, prim));
        }
        // the floor follows the mesh through transforms
        let mut big = cube.clone();
        big.transform(|p| p * 10.0, |n| n);
        assert!((exit_curvature(&big, 0) - floor / 10.0).abs() < 1e-7);
    }

    #[test]
    fn the_curvature_cache_is_the_functions_bit_for_bit() {
        // A smooth sphere (both curvatures > 0), the same sphere turned
        // inside out (mean curvature 0: concave) and a flat quad.
        let sphere = uv_sphere(Vec3::new(1.0, -2.0, 0.5), 2.5, 10);
        let mut inside = sphere.clone();
        inside.transform(|p| p, |n| -n);
        let flat = planes(3.0, &[0.5]);
        for (what, m) in [("sphere", &sphere), ("inside", &inside), ("flat", &flat)] {
            let cache = MeshCurvature::new(m, 1.0);
            for prim in 0..m.triangle_count() as u32 {
                assert_eq!(
                    cache.exit(prim).to_bits(),
                    exit_curvature(m, prim).to_bits()
                );
                assert_eq!(
                    cache.mean(prim).to_bits(),
                    mean_curvature(m, prim).to_bits()
                );
            }
            let (k_exit, k_mean) = (cache.exit(0), cache.mean(0));
            match what {
                "sphere" => assert!(k_exit > 0.0 && k_mean > 0.0),
                "inside" => assert!(k_exit > 0.0 && k_mean == 0.0),
                _ => assert!(k_exit > 0.0 && k_mean == 0.0),
            }
        }
    }

    #[test]
    fn mean_curvature_of_a_sphere_and_a_flat_mesh() {
        let r = 2.5f32;
        // one triangle of a sphere of radius r, radial normals
        let dirs = [
            Vec3::new(1.0, 0.1, 0.0).normalize(),
            Vec3::new(0.9, 0.3, 0.2).normalize(),
            Vec3::new(0.95, 0.0, 0.3).normalize(),
        ];
        let mesh = Mesh::new(
            dirs.map(|d| d * r).to_vec(),
            vec![[0, 1, 2]],
            Some(dirs.to_vec()),
        );
        assert!((mean_curvature(&mesh, 0) * r - 1.0).abs() < 1e-4);
        // the same triangle seen from inside (normals flipped): concave, 0
        let inside = Mesh::new(
            dirs.map(|d| d * r).to_vec(),
            vec![[0, 1, 2]],
            Some(dirs.map(|d| -d).to_vec()),
        );
        assert_eq!(mean_curvature(&inside, 0), 0.0);
        let flat = Mesh::new(dirs.map(|d| d * r).to_vec(), vec![[0, 1, 2]], None);
        assert_eq!(mean_curvature(&flat, 0), 0.0);
    }
}
