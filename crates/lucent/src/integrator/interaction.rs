//! The local geometry at a ray hit: position, geometric and shading normals
//! and which face the ray arrived at.

use glam::Vec2;

use crate::accel::Hit;
use crate::geometry::{Frame, Mesh, Ray, Vec3};

/// What [`Interaction::new`] reads of one mesh, laid out per triangle so a
/// hit costs one bounds-checked load of a contiguous record instead of an
/// index triple and three gathers each from the positions and the normals.
#[derive(Clone, Debug, Default)]
pub struct MeshShading {
    tris: Vec<TriGeometry>,
    /// The vertex normals of each triangle, when the mesh has them.
    normals: Option<Vec<[Vec3; 3]>>,
    /// The texture coordinates and tangent of each triangle, when the
    /// mesh has texture coordinates (only where its material reads a
    /// texture).
    uvs: Option<Vec<TriUv>>,
}

/// A triangle's texture coordinates (per corner), the ratio of its UV to
/// its world size, √(area in UV / area), and its unit tangent (the world
/// direction of increasing u) with the handedness of the bitangent
/// (increasing v): b = sign · n × t (MikkTSpace's per-pixel form).
#[derive(Clone, Copy, Debug)]
pub struct TriUv {
    pub uv: [Vec2; 3],
    pub uv_per_unit: f32,
    pub tangent: Vec3,
    pub sign: f32,
}

impl TriUv {
    /// The record of the triangle with corners `p` and texture coordinates
    /// `uv`; a triangle degenerate in UV gets a tangent perpendicular to
    /// its normal and scale 0.
    pub fn new(p: [Vec3; 3], uv: [Vec2; 3]) -> Self {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let n = e1.cross(e2);
        let det = d1.x * d2.y - d2.x * d1.y;
        let area = n.length();
        let t = (e1 * d2.y - e2 * d1.y) / det;
        let b = (e2 * d1.x - e1 * d2.x) / det;
        let ng = n.normalize_or_zero();
        let (tangent, sign) = match t.try_normalize() {
            Some(t) if det != 0.0 && b.is_finite() => {
                (t, if ng.cross(t).dot(b) < 0.0 { -1.0 } else { 1.0 })
            }
            _ => (
                Frame::from_normal(if ng == Vec3::ZERO { Vec3::Z } else { ng }).t,
                1.0,
            ),
        };
        let ratio = (det.abs() / area).sqrt();
        TriUv {
            uv,
            uv_per_unit: if ratio.is_finite() { ratio } else { 0.0 },
            tangent,
            sign,
        }
    }

    /// The texture coordinates at barycentrics (u, v).
    #[inline]
    pub fn at(&self, [u, v]: [f32; 2]) -> Vec2 {
        self.uv[0] * (1.0 - u - v) + self.uv[1] * u + self.uv[2] * v
    }
}

/// The vertex a and the edges b − a, c − a (the same f32 subtractions the
/// hit point would otherwise redo), and the unit front-face normal, zero
/// for a degenerate triangle.
#[derive(Clone, Copy, Debug)]
struct TriGeometry {
    a: Vec3,
    e1: Vec3,
    e2: Vec3,
    ng: Vec3,
}

impl MeshShading {
    /// The record of `mesh`, with its [`Mesh::face_normals`].
    pub fn new(mesh: &Mesh) -> Self {
        let tris = mesh
            .indices
            .iter()
            .zip(mesh.face_normals())
            .map(|(&idx, &ng)| {
                let [a, b, c] = mesh.vertices(idx);
                TriGeometry {
                    a,
                    e1: b - a,
                    e2: c - a,
                    ng,
                }
            })
            .collect();
        let normals = mesh.normals.as_ref().map(|ns| {
            mesh.indices
                .iter()
                .map(|idx| idx.map(|i| ns[i as usize]))
                .collect()
        });
        let uvs = mesh.uvs.as_ref().map(|uvs| {
            mesh.indices
                .iter()
                .zip(uvs)
                .map(|(&idx, &uv)| TriUv::new(mesh.vertices(idx), uv))
                .collect()
        });
        MeshShading { tris, normals, uvs }
    }

    /// Triangle `prim`'s texture coordinates and tangent, when the mesh
    /// has texture coordinates.
    #[inline]
    pub fn uv(&self, prim: u32) -> Option<&TriUv> {
        self.uvs.as_ref().map(|u| &u[prim as usize])
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    pub p: Vec3,
    /// Unit geometric normal of the front face (counter-clockwise winding).
    pub ng: Vec3,
    /// Unit shading normal (interpolated vertex normals when the mesh has
    /// them), flipped into the same hemisphere as `ng`.
    pub ns: Vec3,
    /// The ray arrived at the front face.
    pub front: bool,
    pub geom: u32,
    pub prim: u32,
}

impl Interaction {
    /// `shading` is the [`MeshShading`] of the mesh hit. Forced inline with
    /// [`Context::interaction`](super::Context::interaction) (see
    /// [`crate::kernels`]).
    #[inline(always)]
    pub fn new(shading: &MeshShading, ray: &Ray, hit: &Hit) -> Self {
        let t = &shading.tris[hit.prim as usize];
        let (u, v) = (hit.u, hit.v);
        let p = t.a + t.e1 * u + t.e2 * v;
        let ng = t.ng;
        // Degenerate triangles never hit in either backend, but keep a valid
        // normal if one does.
        let ng = if ng == Vec3::ZERO {
            -ray.d.normalize_or_zero()
        } else {
            ng
        };
        let ns = match &shading.normals {
            Some(ns) => {
                let [n0, n1, n2] = ns[hit.prim as usize];
                let n = n0 * (1.0 - u - v) + n1 * u + n2 * v;
                // normalize_or_zero's test without its zero vector: the
                // reciprocal length is finite and positive exactly when
                // 0 < |n|² < ∞ (the smallest subnormal |n|² still has a
                // finite 1/|n|), so this is the same normal bit for bit.
                let len2 = n.length_squared();
                if len2 > 0.0 && len2 < f32::INFINITY {
                    let n = n * (1.0 / len2.sqrt());
                    if n.dot(ng) < 0.0 {
                        -n
                    } else {
                        n
                    }
                } else {
                    ng
                }
            }
            None => ng,
        };
        Interaction {
            p,
            ng,
            ns,
            front: ray.d.dot(ng) < 0.0,
            geom: hit.geom,
            prim: hit.prim,
        }
    }

    /// This interaction with the unit shading normal `n` (flipped into
    /// the hemisphere of `ng`, as [`Interaction::new`] does).
    pub(crate) fn with_shading_normal(&self, n: Vec3) -> Interaction {
        let ns = if n.dot(self.ng) < 0.0 { -n } else { n };
        Interaction { ns, ..*self }
    }

    /// The shading frame oriented towards the side the ray came from.
    pub(crate) fn shading_frame_facing(&self, wo: Vec3) -> Frame {
        let n = if wo.dot(self.ng) >= 0.0 {
            self.ns
        } else {
            -self.ns
        };
        Frame::from_normal(n)
    }

    /// A ray leaving the surface in `dir`, its origin pushed off the
    /// surface along the geometric normal to the side `dir` goes, by an
    /// amount that grows with the magnitude of the coordinates (f32
    /// rounding of the hit point) and never falls below `eps`.
    pub fn spawn(&self, dir: Vec3, eps: f32) -> Ray {
        Ray::new(offset_origin(self.p, self.ng, dir, eps), dir)
    }
}

pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3, eps: f32) -> Vec3 {
    let n = if dir.dot(ng) >= 0.0 { ng } else { -ng };
    offset_along(p, n, eps)
}

/// [`offset_origin`] for callers that already know the ray leaves on the
/// side `n` faces (they tested `dir · n > 0` to cull the direction).
#[inline]
pub fn offset_along(p: Vec3, n: Vec3, eps: f32) -> Vec3 {
    let e = eps.max(p.abs().max_element() * 4e-6);
    p + n * e
}
