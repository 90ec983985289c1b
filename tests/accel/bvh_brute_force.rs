//! The BVH against a brute-force loop over every triangle with the same
//! triangle test: nearest hit, occlusion and probe-segment hit lists must
//! agree exactly on random soups, multi-mesh scenes, exact grids (rays
//! through shared vertices and edges), degenerate input and overflowing
//! probe segments.

use lucent::accel::bvh::{can_hit, Bvh};
use lucent::accel::{Accel, ProbeHits, MAX_PROBE_HITS};
use lucent::geometry::{Mesh, Ray, Vec3};
use lucent::sampling::Rng;
use lucent::scene::shapes;

use crate::common::brute::{probe, Brute};

/// Checks all three queries of `bvh` against brute force on one ray.
fn compare(bvh: &Bvh, brute: &Brute, ray: &Ray, tmin: f32, tmax: f32, seed: u32) {
    let want = brute.nearest(ray, tmin, tmax);
    let got = bvh.intersect(ray, tmin, tmax);
    match (want, got) {
        (None, None) => {}
        (Some(w), Some(g)) => {
            assert_eq!(
                w.t.to_bits(),
                g.t.to_bits(),
                "t differs: {ray:?} {w:?} {g:?}"
            );
            if (w.geom, w.prim) == (g.geom, g.prim) {
                assert_eq!((w.u, w.v), (g.u, g.v));
            } else {
                // An exact tie: the BVH's triangle must really hit at w.t.
                let p = brute.meshes[g.geom as usize].triangle(g.prim);
                let again = brute.test(ray, p, tmin, tmax).map(|h| h.0);
                assert_eq!(again, Some(w.t), "not a tie: {ray:?} {w:?} {g:?}");
            }
        }
        _ => panic!("nearest differs on {ray:?} [{tmin}, {tmax}]: want {want:?}, got {got:?}"),
    }
    assert_eq!(
        bvh.occluded(ray, tmin, tmax),
        want.is_some(),
        "occluded differs on {ray:?} [{tmin}, {tmax}]"
    );
    let mut out = ProbeHits::new();
    let all = brute.all(ray, 0.0, tmax);
    for geom in 0..brute.meshes.len() as u32 {
        bvh.hits_on_segment(ray, tmax, geom, seed, &mut out);
        let w = probe(&all, geom, seed);
        assert_eq!(
            out.total(),
            w.total(),
            "segment total on {ray:?} geom {geom}"
        );
        assert_eq!(out.hits(), w.hits(), "segment hits on {ray:?} geom {geom}");
    }
}

fn r3(rng: &mut Rng) -> Vec3 {
    Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE
}

/// A random ray: origin inside or outside the unit cube, random direction
/// and length, sometimes with zeroed components; a random interval.
fn random_query(rng: &mut Rng) -> (Ray, f32, f32) {
    let o = if rng.uniform() < 0.5 {
        r3(rng) * 1.2
    } else {
        r3(rng).normalize_or(Vec3::X) * 3.0
    };
    // Aim near the geometry half of the time, anywhere otherwise.
    let mut d = if rng.uniform() < 0.5 {
        r3(rng) * 0.8 - o
    } else {
        r3(rng)
    };
    match (rng.uniform() * 8.0) as u32 {
        0 => d.x = 0.0,
        1 => {
            d.y = 0.0;
            d.z = -0.0;
        }
        2 => {
            d.x = 0.0;
            d.z = 0.0;
        }
        _ => {}
    }
    if d == Vec3::ZERO {
        d = Vec3::Y;
    }
    d *= 0.1 + 10.0 * rng.uniform();
    let len = 4.0 / d.length();
    let (tmin, tmax) = match (rng.uniform() * 4.0) as u32 {
        0 => (0.0, f32::INFINITY),
        1 => (0.0, rng.uniform() * len),
        2 => {
            let a = rng.uniform() * len;
            (a, a + rng.uniform() * len)
        }
        _ => (rng.uniform() * 0.5 * len, f32::INFINITY),
    };
    (Ray::new(o, d), tmin, tmax)
}

fn run_random(meshes: &[Mesh], rays: usize, seed: u64) {
    let bvh = Bvh::build(meshes);
    let brute = Brute::new(meshes);
    let mut rng = Rng::from_key(seed);
    let mut hits = 0;
    for i in 0..rays {
        let (ray, tmin, tmax) = random_query(&mut rng);
        compare(&bvh, &brute, &ray, tmin, tmax, i as u32);
        hits += bvh.intersect(&ray, tmin, tmax).is_some() as usize;
    }
    // The comparison means little if nothing (or everything) was hit.
    if meshes.iter().map(Mesh::triangle_count).sum::<usize>() >= 100 {
        assert!(hits > rays / 10 && hits < rays, "{hits} of {rays} rays hit");
    }
}

#[test]
fn random_soups_of_several_sizes() {
    for (n, size, rays) in [
        (1, 1.0, 2000),
        (5, 0.8, 2000),
        (100, 0.5, 3000),
        (1000, 0.3, 3000),
        (20_000, 0.1, 2000),
    ] {
        run_random(
            &[shapes::random_soup(n, size, n as u64)],
            rays,
            7 + n as u64,
        );
    }
}

#[test]
fn multiple_meshes() {
    let mut moved = shapes::sphere(3);
    moved.transform(|p| p * 0.5 + Vec3::new(0.3, 0.0, 0.2), |n| n);
    let meshes = vec![
        shapes::random_soup(500, 0.4, 1),
        Mesh::default(),
        shapes::random_soup(2000, 0.2, 2),
        moved,
        shapes::cuboid(),
        shapes::random_soup(3, 2.0, 3),
    ];
    run_random(&meshes, 3000, 99);
}

#[test]
fn closed_surfaces_are_hit_twice_along_through_segments() {
    // A big tessellated surface also exercises the parallel build.
    let meshes = vec![shapes::displaced_sphere(5, 0.1)];
    run_random(&meshes, 1000, 5);
}

/// An n×n grid of unit squares in the plane `axis` = `level`, with exact
/// integer coordinates offset by `base`, two triangles per square.
fn grid(n: u32, axis: usize, level: f32, base: f32) -> Mesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let mut v = Vec3::splat(level);
            v[(axis + 1) % 3] = base + i as f32;
            v[(axis + 2) % 3] = base + j as f32;
            p.push(v);
        }
    }
    let mut idx = Vec::new();
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            // alternate the diagonal so vertices have 4, 6 or 8 triangles
            if (i + j) % 2 == 0 {
                idx.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                idx.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            } else {
                idx.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
                idx.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    Mesh::new(p, idx, None)
}

#[test]
fn rays_through_shared_vertices_and_edges_of_a_grid_hit() {
    let n = 16u32;
    for (axis, base) in [(2usize, 0.0f32), (0, -8.0), (1, 1000.0)] {
        let meshes = vec![grid(n, axis, 0.5, base)];
        let bvh = Bvh::build(&meshes);
        let brute = Brute::new(&meshes);
        let mut checked = 0;
        // every vertex, edge midpoint and square centre, including the border
        for j2 in 0..=2 * n {
            for i2 in 0..=2 * n {
                let mut target = Vec3::splat(0.5);
                target[(axis + 1) % 3] = base + i2 as f32 * 0.5;
                target[(axis + 2) % 3] = base + j2 as f32 * 0.5;
                for s in [1.0f32, -1.0] {
                    let mut d = Vec3::ZERO;
                    d[axis] = s;
                    let ray = Ray::new(target - d * 2.0, d);
                    let h = bvh.intersect(&ray, 0.0, f32::INFINITY);
                    assert_eq!(h.map(|h| h.t), Some(2.0), "lost {ray:?}");
                    assert!(bvh.occluded(&ray, 0.0, 2.0));
                    assert!(!bvh.occluded(&ray, 0.0, 1.999));
                    let mut out = ProbeHits::new();
                    bvh.hits_on_segment(&ray, 4.0, 0, 3, &mut out);
                    // every triangle touching the point, and nothing else
                    let touching = brute.all(&ray, 0.0, 4.0);
                    assert!(!touching.is_empty());
                    assert_eq!(out.hits(), &touching[..], "{ray:?}");
                    if i2 % 2 == 0 && j2 % 2 == 0 && i2 > 0 && j2 > 0 && i2 < 2 * n && j2 < 2 * n {
                        assert!(out.total() >= 4, "inner vertex: {} hits", out.total());
                    }
                    compare(&bvh, &brute, &ray, 0.0, f32::INFINITY, 1);
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 2 * (2 * n + 1) * (2 * n + 1));
    }
}

#[test]
fn oblique_rays_through_grid_vertices_are_not_lost() {
    let meshes = vec![grid(9, 2, 0.0, 0.0)];
    let bvh = Bvh::build(&meshes);
    let brute = Brute::new(&meshes);
    let mut rng = Rng::from_key(4);
    for _ in 0..4000 {
        // Inner vertices only: a ray through a border vertex may
        // legitimately pass just outside the mesh after rounding.
        let target = Vec3::new(
            1.0 + (rng.uniform() * 7.0).floor(),
            1.0 + (rng.uniform() * 7.0).floor(),
            0.0,
        );
        let mut o = r3(&mut rng) * 6.0;
        o.z = if o.z.abs() < 0.1 { 1.0 } else { o.z };
        let ray = Ray::new(o, target - o);
        let h = bvh.intersect(&ray, 0.0, f32::INFINITY);
        assert!(h.is_some(), "lost {ray:?} -> {target:?}");
        compare(&bvh, &brute, &ray, 0.0, f32::INFINITY, 2);
    }
}

#[test]
fn empty_scenes_hit_nothing() {
    for meshes in [vec![], vec![Mesh::default(), Mesh::default()]] {
        let bvh = Bvh::build(&meshes);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert!(bvh.intersect(&ray, 0.0, f32::INFINITY).is_none());
        assert!(!bvh.occluded(&ray, 0.0, f32::INFINITY));
        let mut out = ProbeHits::new();
        for geom in 0..3 {
            bvh.hits_on_segment(&ray, 10.0, geom, 0, &mut out);
            assert_eq!((out.total(), out.hits().len()), (0, 0));
        }
    }
}

#[test]
fn degenerate_triangles_never_hit() {
    // A good triangle plus, along the same rays, degenerate ones: repeated
    // vertices, collinear vertices (exact integers, so exactly collinear),
    // a point, and NaN and infinite coordinates.
    let p = vec![
        Vec3::new(-4.0, -4.0, 0.0),
        Vec3::new(4.0, -4.0, 0.0),
        Vec3::new(0.0, 4.0, 0.0),
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(3.0, 3.0, 1.0),
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(f32::NAN, 0.0, 3.0),
        Vec3::new(1.0, f32::INFINITY, 3.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(3.0, -3.0, -1.0),
    ];
    let idx = vec![
        [0, 1, 2],
        [3, 4, 5],
        [3, 3, 4],
        [6, 6, 6],
        [7, 0, 1],
        [8, 1, 2],
        [9, 10, 11],
        [4, 5, 4],
        [7, 7, 7],
    ];
    let meshes = vec![Mesh::new(p, idx, None)];
    let bvh = Bvh::build(&meshes);
    let brute = Brute::new(&meshes);
    let mut rng = Rng::from_key(8);
    let mut out = ProbeHits::new();
    for _ in 0..5000 {
        // aim at points on the degenerate triangles, from anywhere
        let target = match (rng.uniform() * 3.0) as u32 {
            0 => Vec3::new(-1.0, -1.0, 1.0) + Vec3::new(1.0, 1.0, 0.0) * 4.0 * rng.uniform(),
            1 => Vec3::new(0.0, 0.0, 2.0),
            _ => Vec3::new(-1.0, 1.0, -1.0) + Vec3::new(1.0, -1.0, 0.0) * 4.0 * rng.uniform(),
        };
        let o = r3(&mut rng) * 10.0;
        let ray = Ray::new(o, target - o);
        if let Some(h) = bvh.intersect(&ray, 0.0, f32::INFINITY) {
            assert_eq!(h.prim, 0, "{ray:?}");
        }
        bvh.hits_on_segment(&ray, 100.0, 0, 0, &mut out);
        assert!(out.hits().iter().all(|h| h.prim == 0) && out.total() <= 1);
        compare(&bvh, &brute, &ray, 0.0, f32::INFINITY, 0);
    }
    // The degenerate ones really are degenerate for the triangle test too.
    let m = &meshes[0];
    for prim in 1..m.triangle_count() as u32 {
        assert!(!can_hit(m.triangle(prim)), "prim {prim}");
    }
}

#[test]
fn probe_segment_through_200_quads_overflows_like_brute_force() {
    let mut p = Vec::new();
    let mut idx = Vec::new();
    for k in 0..200u32 {
        let z = k as f32 * 0.01;
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            p.push(Vec3::new(x, y, z));
        }
        let b = 4 * k;
        idx.push([b, b + 1, b + 2]);
        idx.push([b, b + 2, b + 3]);
    }
    // A second mesh on the same segment must not be counted.
    let meshes = vec![Mesh::new(p, idx, None), shapes::quad()];
    let bvh = Bvh::build(&meshes);
    let brute = Brute::new(&meshes);
    // off the quads' diagonals: one triangle per quad
    let ray = Ray::new(Vec3::new(0.3, -0.5, -1.0), Vec3::Z);
    let mut out = ProbeHits::new();
    let mut kept_sets = Vec::new();
    for seed in 0..8 {
        bvh.hits_on_segment(&ray, 4.0, 0, seed, &mut out);
        assert_eq!(out.total(), 200);
        assert_eq!(out.hits().len(), MAX_PROBE_HITS);
        assert_eq!(out.hits(), brute.segment(&ray, 4.0, 0, seed).hits());
        for w in out.hits().windows(2) {
            assert!(w[0].t <= w[1].t);
        }
        for h in out.hits() {
            assert_eq!(h.geom, 0);
            let q = meshes[0].triangle(h.prim);
            let again = brute.test(&ray, q, 0.0, 4.0).unwrap();
            assert_eq!(again, (h.t, h.u, h.v));
            assert!((h.t - (1.0 + (h.prim / 2) as f32 * 0.01)).abs() < 1e-5);
        }
        kept_sets.push(out.hits().iter().map(|h| h.prim).collect::<Vec<_>>());
    }
    // The seed selects the subset.
    kept_sets.dedup();
    assert!(kept_sets.len() > 1);
    // Shorter segments count only what they cross.
    bvh.hits_on_segment(&ray, 1.5, 0, 0, &mut out);
    assert_eq!(out.total(), 51);
    assert_eq!(out.hits().len(), 51);
}

/// A mesh of `n` random triangles with vertices on the grid of quarters in
/// [−1, 1]³ (all in the plane z = 1/4 when `flat`): every vertex, edge
/// midpoint and box corner is exact, and so is the direction of a ray
/// from a grid point to it.
fn tiny_mesh(n: u32, flat: bool, rng: &mut Rng) -> Mesh {
    let mut q = || ((rng.uniform() * 9.0).floor() - 4.0) * 0.25;
    let mut p = Vec::new();
    for _ in 0..3 * n {
        let v = Vec3::new(q(), q(), q());
        p.push(if flat { Vec3::new(v.x, v.y, 0.25) } else { v });
    }
    let idx = (0..n).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    Mesh::new(p, idx, None)
}

/// Rays aimed exactly at the vertices, edge midpoints and bounding-box
/// corners, edge midpoints and face centres of meshes of one to a few
/// triangles (one-leaf trees, where the traversal tests the whole box
/// before the leaf), from outside and from points on the box's faces, with
/// intervals that end exactly at the target. Such rays graze the boxes:
/// the slab test's entry and exit distances coincide at a corner or edge,
/// so any box test stricter than the triangle test loses a hit.
#[test]
fn rays_at_vertices_edges_and_box_corners_of_tiny_meshes() {
    let mut rng = Rng::from_key(21);
    let (mut rays, mut hits) = (0usize, 0usize);
    for n in [1u32, 1, 2, 3, 5, 8, 9, 17] {
        for flat in [false, true] {
            let mesh = tiny_mesh(n, flat, &mut rng);
            let meshes = [mesh];
            let bvh = Bvh::build(&meshes);
            let brute = Brute::new(&meshes);
            let mesh = &meshes[0];
            let Some((lo, hi)) = (0..mesh.triangle_count() as u32)
                .map(|i| mesh.triangle(i))
                .filter(|&p| can_hit(p))
                .map(|p| (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2])))
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
            else {
                continue;
            };
            let mut targets = Vec::new();
            for i in 0..mesh.triangle_count() as u32 {
                let p = mesh.triangle(i);
                for k in 0..3 {
                    targets.push(p[k]);
                    targets.push((p[k] + p[(k + 1) % 3]) * 0.5);
                }
            }
            // box corners (0, 2), edge midpoints and face centres (1) and centre
            for c in 0..27u32 {
                let pick = |a: u32, axis: usize| match a {
                    0 => lo[axis],
                    1 => 0.5 * (lo[axis] + hi[axis]),
                    _ => hi[axis],
                };
                targets.push(Vec3::new(
                    pick(c % 3, 0),
                    pick(c / 3 % 3, 1),
                    pick(c / 9, 2),
                ));
            }
            let origins = [
                Vec3::new(3.0, 2.5, 1.75),
                Vec3::new(-2.25, 3.0, -2.5),
                Vec3::new(0.5, -3.0, 2.0),
                Vec3::new(-3.0, -1.5, -0.75),
                Vec3::new(0.0, 0.0, 3.0),
            ];
            for &t in &targets {
                // from outside, and from the box's faces along them
                let mut from = origins.to_vec();
                for axis in 0..3 {
                    for plane in [lo[axis], hi[axis]] {
                        let mut o = t + Vec3::splat(2.0);
                        o[axis] = plane;
                        from.push(o);
                        let mut o = t - Vec3::new(1.5, 2.0, 2.5);
                        o[axis] = plane;
                        from.push(o);
                    }
                }
                for o in from {
                    let d = t - o;
                    if d == Vec3::ZERO {
                        continue;
                    }
                    let ray = Ray::new(o, d);
                    // An origin on a triangle is a hit at t = ±0, whose
                    // sign depends on the triangle: not what this is about.
                    if !brute.all(&ray, 0.0, 0.0).is_empty() {
                        continue;
                    }
                    for (tmin, tmax) in [
                        (0.0, f32::INFINITY),
                        (0.0, 1.0),
                        (1.0, f32::INFINITY),
                        (0.5, 1.0),
                    ] {
                        compare(&bvh, &brute, &ray, tmin, tmax, rays as u32);
                    }
                    hits += brute.nearest(&ray, 0.0, 1.0).is_some() as usize;
                    rays += 1;
                }
            }
        }
    }
    // The targets on triangles are hit at t = 1 exactly (inclusive edges).
    assert!(rays > 5000 && hits > rays / 5, "{hits} of {rays} rays hit");
}
