//! Our own BVH: the reference [`Accel`] backend.
//!
//! Two levels: one binned-SAH hierarchy per mesh, collapsed to 8-wide
//! nodes (`build.rs`), and a small top-level hierarchy over the meshes'
//! bounds. Nearest-hit and occlusion
//! queries walk the top level and descend into the meshes whose boxes the
//! ray meets; [`Accel::hits_on_segment`] asks about one mesh and so walks
//! only that mesh's tree. Triangles are tested with the watertight test of
//! Woop et al. 2013 ([`triangle`]), with inclusive edges, so a ray through a
//! shared edge or vertex is never lost. Their vertices are copied in leaf
//! order, four triangles to a [`Tri4`] packet tested at once with SSE, so
//! a leaf (one or two packets) is contiguous in memory; the SAH counts a
//! leaf's cost per packet.
//!
//! Triangles that can never be hit (non-finite coordinates, or zero area)
//! are left out of the hierarchy, which keeps NaN out of the SAH and box
//! arithmetic.

mod build;
mod mem;
mod traverse;
pub mod triangle;

use glam::Vec3;
use rayon::prelude::*;

use self::build::{PrimRef, Tree, PAD};
use self::traverse::{traverse, RayBox, Visit};
use self::triangle::{RayTri, Tri4};
use super::{valid_query, Accel, Hit, ProbeHits, RejectedRays};
use crate::geometry::{Mesh, Ray};

/// Most triangles per leaf (two packets); the SAH usually stops earlier.
const MAX_LEAF: usize = 8;

/// One mesh's hierarchy; leaves index `tris`, whose packets carry the
/// mesh's triangle ids (the tree's `order` is handed over to them).
#[derive(Clone, Debug, Default)]
struct MeshBvh {
    tree: Tree,
    tris: Vec<Tri4>,
}

/// Whether a triangle can ever be hit by [`RayTri::intersect`]: finite
/// coordinates and non-zero area. The area test is done in f64, where
/// exactly collinear (or repeated) vertices of similar magnitude give an
/// exactly zero cross product; `RayTri` alone would let rounding noise
/// through for some collinear triangles.
pub fn can_hit(p: [Vec3; 3]) -> bool {
    if !p.iter().all(|v| v.is_finite()) {
        return false;
    }
    let e1 = p[1].as_dvec3() - p[0].as_dvec3();
    let e2 = p[2].as_dvec3() - p[0].as_dvec3();
    e1.cross(e2) != glam::DVec3::ZERO
}

impl MeshBvh {
    fn build(mesh: &Mesh) -> Self {
        let prims: Vec<PrimRef> = (0..mesh.triangle_count() as u32)
            .into_par_iter()
            .filter_map(|id| {
                let p = mesh.triangle(id);
                can_hit(p).then(|| PrimRef {
                    lo: p[0].min(p[1]).min(p[2]),
                    hi: p[0].max(p[1]).max(p[2]),
                    id,
                })
            })
            .collect();
        let mut tree = build::build(prims, MAX_LEAF, 4);
        let order = std::mem::take(&mut tree.order);
        let mut tris = mem::with_huge_pages(order.len() / 4);
        tris.par_extend(order.par_chunks(4).map(|ids| {
            let mut t = Tri4::EMPTY;
            for (k, &id) in ids.iter().enumerate() {
                if id != PAD {
                    t.set(k, mesh.triangle(id), id);
                }
            }
            t
        }));
        MeshBvh { tree, tris }
    }
}

/// The BVH backend. See the module documentation.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Over mesh bounds; leaves hold one mesh each, `top.order` maps them
    /// to mesh indices.
    top: Tree,
    meshes: Vec<MeshBvh>,
    /// Queries refused by [`valid_query`].
    rejected: RejectedRays,
}

impl Bvh {
    /// Builds the hierarchies; mesh `i` is `geom` `i`.
    pub fn build(meshes: &[Mesh]) -> Self {
        // Meshes build one after another, each in parallel inside: a scene
        // is usually one big mesh and a few small ones.
        let built: Vec<MeshBvh> = meshes.iter().map(MeshBvh::build).collect();
        let prims: Vec<PrimRef> = built
            .iter()
            .enumerate()
            .filter(|(_, m)| !m.tree.is_empty())
            .map(|(i, m)| PrimRef {
                lo: Vec3::from(m.tree.bounds[0]),
                hi: Vec3::from(m.tree.bounds[1]),
                id: i as u32,
            })
            .collect();
        Bvh {
            top: build::build(prims, 1, 1),
            meshes: built,
            rejected: RejectedRays::default(),
        }
    }

    /// Wide-node count and depth of each mesh's tree, for logs and
    /// tuning.
    pub fn stats(&self) -> Vec<(usize, usize)> {
        self.meshes
            .iter()
            .map(|m| (m.tree.nodes.len(), m.tree.depth()))
            .collect()
    }
}

impl Accel for Bvh {
    fn name(&self) -> &'static str {
        "bvh"
    }

    fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        // NaN or huge components would make NaN slab distances, and every
        // box would look hit.
        if !valid_query(ray, tmin, tmax) {
            self.rejected.count();
            return None;
        }
        if tmin > tmax {
            return None;
        }
        let rb = RayBox::new(ray);
        let rt = RayTri::new(ray);
        // (geom, prim, u, v) of the nearest hit so far; its t is the
        // running tmax.
        let mut best: Option<(u32, u32, f32, f32)> = None;
        let mut t = tmax;
        traverse::<true, _>(&self.top, &[()], &rb, tmin, &mut t, |first, count, t| {
            for k in first..first + count {
                let g = self.top.order[k as usize];
                let m = &self.meshes[g as usize];
                traverse::<true, _>(&m.tree, &m.tris, &rb, tmin, t, |first, count, t| {
                    for i in first as usize..(first + count) as usize {
                        let h = rt.intersect4(&m.tris[i], tmin, *t);
                        if let Some(k) = h.nearest() {
                            *t = h.t[k];
                            best = Some((g, m.tris[i].id[k], h.u[k], h.v[k]));
                        }
                    }
                    Visit::Continue
                });
            }
            Visit::Continue
        });
        best.map(|(geom, prim, u, v)| Hit {
            t,
            geom,
            prim,
            u,
            v,
        })
    }

    fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        if !valid_query(ray, tmin, tmax) {
            self.rejected.count();
            return false;
        }
        if tmin > tmax {
            return false;
        }
        let rb = RayBox::new(ray);
        let rt = RayTri::new(ray);
        let mut t = tmax;
        traverse::<true, _>(&self.top, &[()], &rb, tmin, &mut t, |first, count, t| {
            for k in first..first + count {
                let m = &self.meshes[self.top.order[k as usize] as usize];
                let hit = traverse::<true, _>(&m.tree, &m.tris, &rb, tmin, t, |first, count, t| {
                    let any = m.tris[first as usize..(first + count) as usize]
                        .iter()
                        .any(|tri| rt.intersect4(tri, tmin, *t).mask != 0);
                    if any {
                        Visit::Stop
                    } else {
                        Visit::Continue
                    }
                });
                if hit {
                    return Visit::Stop;
                }
            }
            Visit::Continue
        })
    }

    fn hits_on_segment(&self, ray: &Ray, tmax: f32, geom: u32, seed: u32, out: &mut ProbeHits) {
        out.reset(seed);
        if !valid_query(ray, 0.0, tmax) {
            self.rejected.count();
            out.finish();
            return;
        }
        if let Some(m) = self.meshes.get(geom as usize) {
            if tmax >= 0.0 {
                let rb = RayBox::new(ray);
                let rt = RayTri::new(ray);
                let mut t = tmax;
                traverse::<false, _>(&m.tree, &m.tris, &rb, 0.0, &mut t, |first, count, t| {
                    for tri in &m.tris[first as usize..(first + count) as usize] {
                        let h = rt.intersect4(tri, 0.0, *t);
                        let mut lanes = h.mask;
                        while lanes != 0 {
                            let k = lanes.trailing_zeros() as usize;
                            lanes &= lanes - 1;
                            out.record(Hit {
                                t: h.t[k],
                                geom,
                                prim: tri.id[k],
                                u: h.u[k],
                                v: h.v[k],
                            });
                        }
                    }
                    Visit::Continue
                });
            }
        }
        out.finish();
    }

    fn rejected_rays(&self) -> u64 {
        self.rejected.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shapes;

    #[test]
    fn sphere_is_hit_from_outside_and_inside() {
        let bvh = Bvh::build(&[shapes::sphere(3)]);
        // Off the axes: the z axis meets the sphere at shared vertices,
        // where the inclusive edges hit every triangle around them.
        let r = Ray::new(Vec3::new(0.0123, 0.0456, -5.0), Vec3::Z);
        let h = bvh.intersect(&r, 0.0, f32::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 0.02, "t {}", h.t);
        let inside = Ray::new(Vec3::ZERO, Vec3::new(0.3, -0.2, 0.9).normalize());
        let h = bvh.intersect(&inside, 0.0, f32::INFINITY).unwrap();
        assert!((h.t - 1.0).abs() < 0.02);
        assert!(bvh.occluded(&inside, 0.0, 2.0));
        assert!(!bvh.occluded(&inside, 0.0, 0.9));
        let mut out = ProbeHits::new();
        bvh.hits_on_segment(&r, 10.0, 0, 1, &mut out);
        assert_eq!(out.total(), 2);
        assert!(out.hits()[0].t < out.hits()[1].t);
    }

    #[test]
    fn nearest_hit_picks_the_right_mesh() {
        let mut near = shapes::quad();
        near.transform(|p| p + Vec3::Z, |n| n);
        let far = shapes::quad();
        let bvh = Bvh::build(&[far, Mesh::default(), near]);
        let r = Ray::new(Vec3::new(0.1, 0.2, 3.0), -Vec3::Z);
        let h = bvh.intersect(&r, 0.0, 10.0).unwrap();
        assert_eq!(h.geom, 2);
        assert!((h.t - 2.0).abs() < 1e-6);
        // beyond the near quad: the far one
        let h = bvh.intersect(&r, 2.5, 10.0).unwrap();
        assert_eq!(h.geom, 0);
        let mut out = ProbeHits::new();
        bvh.hits_on_segment(&r, 10.0, 0, 0, &mut out);
        assert_eq!((out.total(), out.hits()[0].geom), (1, 0));
        bvh.hits_on_segment(&r, 10.0, 1, 0, &mut out);
        assert_eq!(out.total(), 0);
        bvh.hits_on_segment(&r, 10.0, 7, 0, &mut out);
        assert_eq!(out.total(), 0);
    }

    #[test]
    fn bad_rays_and_intervals_hit_nothing() {
        let bvh = Bvh::build(&[shapes::cuboid()]);
        let o = Vec3::new(0.0, 0.0, -5.0);
        for r in [
            Ray::new(o, Vec3::ZERO),
            Ray::new(o, Vec3::new(f32::NAN, 0.0, 1.0)),
            Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z),
            Ray::new(o, Vec3::new(0.0, 0.0, f32::INFINITY)),
        ] {
            assert!(bvh.intersect(&r, 0.0, f32::INFINITY).is_none());
            assert!(!bvh.occluded(&r, 0.0, f32::INFINITY));
        }
        let r = Ray::new(o, Vec3::Z);
        assert!(bvh.intersect(&r, 0.0, f32::INFINITY).is_some());
        assert!(bvh.intersect(&r, 5.0, 1.0).is_none());
        assert!(bvh.intersect(&r, f32::NAN, 10.0).is_none());
    }

    #[test]
    fn unhittable_triangles_are_left_out() {
        let nan = Vec3::new(f32::NAN, 0.0, 0.0);
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, nan, Vec3::new(2.0, 0.0, 0.0)];
        // good, NaN, repeated vertex, collinear
        let idx = vec![[0, 1, 2], [0, 3, 1], [0, 0, 2], [0, 1, 4]];
        let bvh = Bvh::build(&[Mesh::new(p, idx, None)]);
        assert_eq!(bvh.meshes[0].tris.len(), 1);
        assert_eq!(bvh.meshes[0].tris[0].id, [0, PAD, PAD, PAD]);
        let h = bvh
            .intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z), 0.0, 9.0)
            .unwrap();
        assert_eq!(h.prim, 0);
    }

    /// Every hit of `ray` in [tmin, tmax] by testing every triangle.
    fn brute(mesh: &Mesh, ray: &Ray, tmin: f32, tmax: f32) -> Vec<(f32, u32)> {
        let rt = RayTri::new(ray);
        let mut v: Vec<(f32, u32)> = (0..mesh.triangle_count() as u32)
            .filter_map(|i| {
                let [a, b, c] = mesh.triangle(i);
                rt.intersect(a, b, c, tmin, tmax).map(|h| (h.0, i))
            })
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        v
    }

    /// Triangles in the planes x = RATIO^i: geometric spacing makes the SAH
    /// peel off a few primitives per split, the deepest trees it builds
    /// (until the depth cap halves by count).
    const RATIO: f32 = 1.01;
    fn deep_mesh(n: u32) -> Mesh {
        let mut p = Vec::new();
        let mut idx = Vec::new();
        for i in 0..n {
            let x = RATIO.powi(i as i32);
            let k = p.len() as u32;
            p.extend([
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x, 2.0, 0.0),
                Vec3::new(x, 0.0, 2.0),
            ]);
            idx.push([k, k + 1, k + 2]);
        }
        Mesh::new(p, idx, None)
    }

    /// The deepest tree we can build, with rays that meet every box of it
    /// (so each level pushes all its siblings): every query agrees with
    /// brute force, and the traversal stack really gets deep.
    #[test]
    fn deepest_tree_fills_the_stack_and_loses_nothing() {
        // 1.01^8000 ≈ 4e34, near the top of the f32 range
        let n = 8000;
        let mesh = deep_mesh(n);
        let bvh = Bvh::build(std::slice::from_ref(&mesh));
        let depth = bvh.stats()[0].1;
        // Rays from the far end start at the largest origin a query accepts
        // (beyond it they are refused as misses, see `valid_query`); they
        // still cross the levels below it from the other side.
        let far = crate::accel::MAX_RAY_COMPONENT;
        assert!(far < RATIO.powi(n as i32));
        let mut rng = crate::sampling::Rng::from_key(3);
        let mut deepest = 0;
        for i in 0..300 {
            let (y, z) = (rng.uniform(), rng.uniform());
            let ray = match i % 3 {
                0 => Ray::new(Vec3::new(0.0, y, z), Vec3::X),
                1 => Ray::new(Vec3::new(far, y, z), -Vec3::X),
                // oblique: leaves the triangles' wedge somewhere along x
                _ => Ray::new(
                    Vec3::new(rng.uniform() * 100.0, y, z),
                    Vec3::new(1.0, rng.uniform() * 1e-3, rng.uniform() * 1e-3),
                ),
            };
            let all = brute(&mesh, &ray, 0.0, f32::INFINITY);
            let h = bvh.intersect(&ray, 0.0, f32::INFINITY);
            assert_eq!(h.map(|h| (h.t, h.prim)), all.first().copied(), "{ray:?}");
            deepest = deepest.max(traverse::stats::take().2);
            assert_eq!(bvh.occluded(&ray, 0.0, f32::INFINITY), !all.is_empty());
            let mut out = ProbeHits::new();
            bvh.hits_on_segment(&ray, f32::INFINITY, 0, i, &mut out);
            assert_eq!(out.total(), all.len(), "{ray:?}");
            deepest = deepest.max(traverse::stats::take().2);
        }
        // Each level pushes up to WIDTH - 1 siblings. (Measured: depth 27,
        // 185 stack entries; a 1.005 ratio over 16000 triangles gives 28.)
        assert!(depth >= 20, "tree depth {depth}");
        assert!(
            deepest >= 5 * depth,
            "stack depth {deepest} for tree depth {depth}"
        );
    }

    /// Mean (wide nodes tested, leaves visited) per query of `rays`.
    fn visits(bvh: &Bvh, rays: &[Ray]) -> (f64, f64) {
        traverse::stats::take();
        for r in rays {
            bvh.intersect(r, 0.0, f32::INFINITY);
        }
        let (n, l, _) = traverse::stats::take();
        (n as f64 / rays.len() as f64, l as f64 / rays.len() as f64)
    }

    /// A box test that accepts every box, or children visited farthest
    /// first, leave every answer right and only cost time; the number of
    /// nodes a nearest-hit query visits on fixed scenes makes them visible.
    /// The bounds are about twice what the traversal visits (measured:
    /// 2.00 / 2.00 on the layers, 4.69 / 2.62 on the sphere).
    #[test]
    fn nearest_hit_queries_visit_few_nodes() {
        let mut rng = crate::sampling::Rng::from_key(5);
        // 64 stacked layers, rays down through all of them: nearest first,
        // the layers below the first hit are skipped.
        let layer = shapes::quad();
        let mut p = Vec::new();
        let mut idx = Vec::new();
        for l in 0..64 {
            for t in 0..layer.triangle_count() as u32 {
                let k = p.len() as u32;
                p.extend(layer.triangle(t).map(|v| v + Vec3::Z * l as f32 * 0.1));
                idx.push([k, k + 1, k + 2]);
            }
        }
        let bvh = Bvh::build(&[Mesh::new(p, idx, None)]);
        let rays: Vec<Ray> = (0..2000)
            .map(|_| {
                let o = Vec3::new(rng.uniform() * 1.8 - 0.9, rng.uniform() * 1.8 - 0.9, 10.0);
                Ray::new(o, Vec3::new(0.01, 0.02, -1.0))
            })
            .collect();
        let (nodes, leaves) = visits(&bvh, &rays);
        assert!(
            nodes < 4.0 && leaves < 4.0,
            "layers: {nodes} nodes, {leaves} leaves per ray"
        );
        // A tessellated sphere, rays from outside aimed near it.
        let bvh = Bvh::build(&[shapes::sphere(4)]);
        let rays: Vec<Ray> = (0..2000)
            .map(|_| {
                let o = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 1.0).normalize() * 4.0;
                let t = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
                Ray::new(o, t - o)
            })
            .collect();
        let (nodes, leaves) = visits(&bvh, &rays);
        assert!(
            nodes < 9.0 && leaves < 5.0,
            "sphere: {nodes} nodes, {leaves} leaves per ray"
        );
        // A one-leaf mesh (the quad [-1, 1]² at z = 0): rays that miss its
        // box visit no leaf — beside it, past its corner (each slab is
        // crossed, but not at the same time), and pointing away from it.
        let bvh = Bvh::build(&[shapes::quad()]);
        let hit = Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z);
        assert!(bvh.intersect(&hit, 0.0, f32::INFINITY).is_some());
        for miss in [
            Ray::new(Vec3::new(1.5, 0.0, 1.0), -Vec3::Z),
            Ray::new(Vec3::new(3.0, 0.0, 1.0), Vec3::new(-1.0, 0.0, -1.0)),
            Ray::new(Vec3::new(0.5, 0.0, 1.0), Vec3::Z),
        ] {
            assert!(bvh.intersect(&miss, 0.0, f32::INFINITY).is_none());
            traverse::stats::take();
            bvh.intersect(&miss, 0.0, f32::INFINITY);
            assert_eq!(
                traverse::stats::take().1,
                0,
                "{miss:?}: a missed one-leaf mesh was visited"
            );
        }
    }
}
