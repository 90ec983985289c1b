//! Embree (3 and 4) and our BVH must answer the three ray queries alike.
//!
//! Each backend is first checked against an independent brute-force
//! reference (every triangle, Möller–Trumbore in f64 with closed edges), then
//! the two backends against each other. Where the exact answer is on a knife
//! edge (a hit within 1e-5 of a triangle edge in barycentrics, at a bound of
//! the t interval, or at a grazing angle) either answer is accepted as long
//! as it is consistent with the reference, and such rays are counted so a
//! test cannot pass by being all knife edges. On the integer grid meshes
//! every quantity is exact in f32, so there both backends must report
//! exactly the reference's hits, including every triangle around a shared
//! vertex or edge.
//!
//! Every check runs once on Embree 3 and once on Embree 4 (`on_embree3::*`,
//! `on_embree4::*`). Built only with the `embree` feature
//! (`#[cfg]` in tests/accel/main.rs).

mod embree_vs_bvh {
    use std::path::Path;
    use std::sync::Arc;

    use lucent::accel::{self, Accel, Backend, Hit, ProbeHits, Traversal, MAX_PROBE_HITS};
    use lucent::geometry::{Mesh, Ray, Vec3};
    use lucent::sampling::Rng;
    use lucent::scene::shapes;

    use crate::common::brute::{reference, RefHit};

    /// Relative tolerance on t between a backend and the reference.
    const T_TOL: f64 = 1e-4;

    fn t_close(a: f64, b: f64) -> bool {
        (a - b).abs() <= T_TOL * a.abs().max(b.abs()).max(1.0)
    }

    /// Whether a query's answer leaves no room for two correct backends to
    /// differ (no reference hit is a knife edge).
    fn unambiguous(r: &[RefHit]) -> bool {
        r.iter().all(|h| h.sure)
    }

    fn find<'a>(r: &'a [RefHit], h: &Hit) -> Option<&'a RefHit> {
        r.iter().find(|x| x.geom == h.geom && x.prim == h.prim)
    }

    fn check_hit_vs_ref(name: &str, h: &Hit, r: &[RefHit], ctx: &str) {
        let x = find(r, h).unwrap_or_else(|| {
            panic!(
                "{name}: reported ({}, {}) which the reference does not hit; {ctx}",
                h.geom, h.prim
            )
        });
        assert!(
            t_close(h.t as f64, x.t),
            "{name}: t {} vs reference {}; {ctx}",
            h.t,
            x.t
        );
        if x.sure {
            assert!(
                (h.u as f64 - x.u).abs() < 1e-3 && (h.v as f64 - x.v).abs() < 1e-3,
                "{name}: (u, v) = ({}, {}) vs reference ({}, {}); {ctx}",
                h.u,
                h.v,
                x.u,
                x.v
            );
        }
    }

    /// Checks `intersect` against the reference; returns the hit.
    /// `r` is `reference(.., tmin, tmax, None, ..)`.
    fn check_intersect(
        a: &dyn Accel,
        r: &[RefHit],
        ray: &Ray,
        tmin: f32,
        tmax: f32,
    ) -> (Option<Hit>, bool) {
        let ctx = format!("intersect {ray:?} [{tmin}, {tmax}]");
        let h = a.intersect(ray, tmin, tmax);
        let nearest_sure = r
            .iter()
            .filter(|x| x.sure)
            .map(|x| x.t)
            .fold(f64::INFINITY, f64::min);
        match &h {
            None => assert!(
                nearest_sure.is_infinite(),
                "{}: missed a sure hit at t = {nearest_sure}; {ctx}",
                a.name()
            ),
            Some(h) => {
                check_hit_vs_ref(a.name(), h, r, &ctx);
                assert!(
                    (h.t as f64) <= nearest_sure || t_close(h.t as f64, nearest_sure),
                    "{}: hit at t = {} but the nearest is at {nearest_sure}; {ctx}",
                    a.name(),
                    h.t
                );
            }
        }
        (h, unambiguous(r))
    }

    /// `r` is `reference(.., tmin, tmax, None, ..)`.
    fn check_occluded(
        a: &dyn Accel,
        r: &[RefHit],
        ray: &Ray,
        tmin: f32,
        tmax: f32,
    ) -> (bool, bool) {
        let occ = a.occluded(ray, tmin, tmax);
        if r.iter().any(|x| x.sure) {
            assert!(
                occ,
                "{}: not occluded but the reference hits: {ray:?} [{tmin}, {tmax}]",
                a.name()
            );
        }
        if r.is_empty() {
            assert!(
                !occ,
                "{}: occluded but the reference has no hit: {ray:?} [{tmin}, {tmax}]",
                a.name()
            );
        }
        (occ, unambiguous(r))
    }

    /// `r` is `reference(.., 0, tmax, Some(geom), ..)`.
    fn check_segment(
        a: &dyn Accel,
        r: &[RefHit],
        ray: &Ray,
        tmax: f32,
        geom: u32,
        seed: u32,
    ) -> (ProbeHits, bool) {
        let ctx = format!("hits_on_segment {ray:?} tmax {tmax} geom {geom}");
        let mut out = ProbeHits::new();
        a.hits_on_segment(ray, tmax, geom, seed, &mut out);
        let hits = out.hits();
        let sure = r.iter().filter(|x| x.sure).count();
        assert!(
            sure <= out.total() && out.total() <= r.len(),
            "{}: total {} outside [{sure}, {}]; {ctx}",
            a.name(),
            out.total(),
            r.len()
        );
        assert_eq!(
            hits.len(),
            out.total().min(MAX_PROBE_HITS),
            "{}: {ctx}",
            a.name()
        );
        for (i, h) in hits.iter().enumerate() {
            assert_eq!(h.geom, geom, "{}: hit on another mesh; {ctx}", a.name());
            check_hit_vs_ref(a.name(), h, r, &ctx);
            assert!(
                !hits[..i].iter().any(|x| x.prim == h.prim),
                "{}: duplicate prim {}; {ctx}",
                a.name(),
                h.prim
            );
            if i > 0 {
                assert!(hits[i - 1].t <= h.t, "{}: not sorted by t; {ctx}", a.name());
            }
        }
        if out.total() <= MAX_PROBE_HITS {
            for x in r.iter().filter(|x| x.sure) {
                assert!(
                    hits.iter().any(|h| h.prim == x.prim),
                    "{}: missed prim {} at t = {}; {ctx}",
                    a.name(),
                    x.prim,
                    x.t
                );
            }
        }
        (out, unambiguous(r))
    }

    fn prims(p: &ProbeHits) -> Vec<(u32, u32)> {
        let mut v: Vec<_> = p.hits().iter().map(|h| (h.geom, h.prim)).collect();
        v.sort_unstable();
        v
    }

    #[derive(Clone, Copy, Debug)]
    struct Query {
        ray: Ray,
        tmin: f32,
        tmax: f32,
        geom: u32,
        seed: u32,
    }

    /// Counts from one [`compare`] run.
    #[derive(Debug, Default)]
    struct Stats {
        queries: usize,
        /// Queries with a knife-edge reference hit (the backends may differ).
        ambiguous: usize,
        /// Of those, how many the backends actually answered differently.
        differed: usize,
        hits: usize,
    }

    fn embree(meshes: &Arc<Vec<Mesh>>, which: Backend) -> Box<dyn Accel> {
        accel::build(meshes, which).expect("Embree build")
    }
    fn bvh(meshes: &Arc<Vec<Mesh>>) -> Box<dyn Accel> {
        accel::build(meshes, Backend::Bvh).expect("BVH build")
    }

    /// Checks `a` against the reference on every query and, if `b` is
    /// given, `a` against `b` wherever the answer is unambiguous.
    fn compare(
        a: &dyn Accel,
        b: Option<&dyn Accel>,
        meshes: &[Mesh],
        qs: &[Query],
        eps: f64,
    ) -> Stats {
        let mut st = Stats::default();
        for q in qs {
            let ri = reference(meshes, &q.ray, q.tmin, q.tmax, None, eps);
            let rs = reference(meshes, &q.ray, 0.0, q.tmax, Some(q.geom), eps);
            let (ha, ua) = check_intersect(a, &ri, &q.ray, q.tmin, q.tmax);
            let (oa, uo) = check_occluded(a, &ri, &q.ray, q.tmin, q.tmax);
            let (pa, us) = check_segment(a, &rs, &q.ray, q.tmax, q.geom, q.seed);
            st.queries += 1;
            st.hits += pa.total();
            let clear = ua && uo && us;
            if !clear {
                st.ambiguous += 1;
            }
            let Some(b) = b else { continue };
            let (hb, _) = check_intersect(b, &ri, &q.ray, q.tmin, q.tmax);
            let (ob, _) = check_occluded(b, &ri, &q.ray, q.tmin, q.tmax);
            let (pb, _) = check_segment(b, &rs, &q.ray, q.tmax, q.geom, q.seed);
            let same_hit = match (ha, hb) {
                (None, None) => true,
                (Some(x), Some(y)) => {
                    // Two triangles at the same t (a shared edge, or
                    // overlapping soup triangles) may be reported either way.
                    (x.geom, x.prim) == (y.geom, y.prim) && t_close(x.t as f64, y.t as f64)
                        || t_close(x.t as f64, y.t as f64) && eps == 0.0
                }
                _ => false,
            };
            let same = same_hit
                && oa == ob
                && pa.total() == pb.total()
                && prims(&pa) == prims(&pb)
                && pa.hits().iter().all(|h| {
                    pb.hits()
                        .iter()
                        .any(|g| g.prim == h.prim && t_close(h.t as f64, g.t as f64))
                });
            if clear {
                assert!(
                    same,
                    "{} and {} differ on an unambiguous query {q:?}:\n intersect {ha:?} vs {hb:?}\n \
                     occluded {oa} vs {ob}\n segment total {} vs {}, prims {:?} vs {:?}",
                    a.name(),
                    b.name(),
                    pa.total(),
                    pb.total(),
                    prims(&pa),
                    prims(&pb)
                );
            } else if !same {
                st.differed += 1;
            }
        }
        st
    }

    /// Embree against the reference and against the BVH on `qs`, asserting
    /// that at most `max_ambiguous` of the queries were knife edges.
    fn run(
        which: Backend,
        name: &str,
        meshes: Vec<Mesh>,
        qs: &[Query],
        eps: f64,
        max_ambiguous: f64,
    ) {
        let meshes = Arc::new(meshes);
        let e = embree(&meshes, which);
        // Embree against the reference alone first, so a BVH failure below
        // cannot hide an Embree one.
        compare(&*e, None, &meshes, qs, eps);
        let b = bvh(&meshes);
        let st = compare(&*e, Some(&*b), &meshes, qs, eps);
        println!("{name}: {st:?}");
        assert!(st.hits > 0, "{name}: no query hit anything");
        assert!(
            st.ambiguous as f64 <= max_ambiguous * st.queries as f64,
            "{name}: {} of {} queries were knife edges: the test checks too little",
            st.ambiguous,
            st.queries
        );
        // Knife edges may differ, but rarely: a systematic difference means
        // different edge rules, not rounding.
        assert!(
            st.differed <= st.ambiguous / 4 + 2,
            "{name}: backends differed on {} of {} knife-edge queries",
            st.differed,
            st.ambiguous
        );
    }

    fn unit(rng: &mut Rng) -> Vec3 {
        loop {
            let v = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
            let l = v.length_squared();
            if l > 1e-4 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }

    /// Random rays through the box [-lim, lim]³ with unnormalized directions
    /// (lengths 0.25–2, so t is checked to be in units of |d|), random
    /// t intervals, a random target mesh among `ngeom`.
    fn random_queries(n: usize, lim: f32, ngeom: u32, seed: u64) -> Vec<Query> {
        let mut rng = Rng::from_key(seed);
        (0..n)
            .map(|i| {
                let o = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE)
                    * lim;
                let target = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0
                    - Vec3::ONE)
                    * lim
                    * 0.5;
                let len = 0.25 + 1.75 * rng.uniform();
                let d = (target - o).normalize() * len;
                let tmin = if i % 3 == 0 { 0.0 } else { 0.3 * rng.uniform() };
                let tmax = if i % 5 == 0 {
                    f32::INFINITY
                } else {
                    (0.5 + 4.0 * rng.uniform()) * lim / len
                };
                Query {
                    ray: Ray::new(o, d),
                    tmin,
                    tmax,
                    geom: (rng.uniform() * ngeom as f32) as u32 % ngeom,
                    seed: i as u32,
                }
            })
            .collect()
    }

    /// Probe-style segments: start inside a closed mesh around `center`
    /// (radius `r`) and leave it.
    fn inside_queries(n: usize, center: Vec3, r: f32, geom: u32, seed: u64) -> Vec<Query> {
        let mut rng = Rng::from_key(seed);
        (0..n)
            .map(|i| Query {
                ray: Ray::new(center + unit(&mut rng) * r * rng.uniform(), unit(&mut rng)),
                tmin: 0.0,
                tmax: 4.0 * r + 1.0,
                geom,
                seed: i as u32,
            })
            .collect()
    }

    /// Rays aimed (up to f32 rounding) at vertices and edge points of mesh
    /// `geom` from random directions, reaching them at t ≈ 2: knife edges
    /// on purpose, including rays that only touch the mesh there.
    fn grazing_queries(m: &Mesh, geom: u32, n: usize, seed: u64) -> Vec<Query> {
        let mut rng = Rng::from_key(seed);
        (0..n)
            .map(|i| {
                let prim =
                    (rng.uniform() * m.triangle_count() as f32) as u32 % m.triangle_count() as u32;
                let [a, b, _] = m.triangle(prim);
                let p = if i % 2 == 0 {
                    a
                } else {
                    a + (b - a) * rng.uniform()
                };
                let d = unit(&mut rng);
                Query {
                    ray: Ray::new(p - d * 2.0, d),
                    tmin: 0.0,
                    tmax: 10.0,
                    geom,
                    seed: i as u32,
                }
            })
            .collect()
    }

    /// Rays through a point of a shared edge of the closed mesh `m`, along
    /// -(n1 + n2) of the two faces meeting there: whether the edge is convex
    /// or concave, that direction goes from outside to inside, so the ray
    /// crosses the surface at t = 2 and a backend must report a hit there
    /// (on one face or both). A leaky triangle test fails this.
    fn crossing_queries(m: &Mesh, geom: u32, n: usize, seed: u64) -> Vec<Query> {
        let mut faces: std::collections::HashMap<(u32, u32), Vec<u32>> = Default::default();
        for (f, t) in m.indices.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                faces
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(f as u32);
            }
        }
        let normal = |f: u32| {
            let [a, b, c] = m.triangle(f);
            (b - a).cross(c - a).normalize()
        };
        let edges: Vec<_> = faces.iter().filter(|(_, f)| f.len() == 2).collect();
        assert!(!edges.is_empty(), "mesh has no shared edges");
        let mut rng = Rng::from_key(seed);
        let mut qs = Vec::new();
        while qs.len() < n {
            let (&(a, b), f) = edges[(rng.uniform() * edges.len() as f32) as usize % edges.len()];
            let (pa, pb) = (m.positions()[a as usize], m.positions()[b as usize]);
            let s = 0.1 + 0.8 * rng.uniform();
            let p = pa + (pb - pa) * s;
            let d = -(normal(f[0]) + normal(f[1]));
            if d.length() < 0.1 {
                continue; // a fold of almost 360°: too sharp to aim into
            }
            let d = d.normalize();
            qs.push(Query {
                ray: Ray::new(p - d * 2.0, d),
                tmin: 0.0,
                tmax: 10.0,
                geom,
                seed: qs.len() as u32,
            });
        }
        qs
    }

    /// Every crossing ray must hit near t = 2 in `intersect` (nothing
    /// farther) and `hits_on_segment`.
    fn check_watertight(a: &dyn Accel, qs: &[Query]) {
        for q in qs {
            let h = a.intersect(&q.ray, 0.0, q.tmax);
            assert!(
                h.is_some_and(|h| h.t <= 2.0 + 1e-3),
                "{}: ray through an edge leaked: {q:?} -> {h:?}",
                a.name()
            );
            let mut out = ProbeHits::new();
            a.hits_on_segment(&q.ray, q.tmax, q.geom, q.seed, &mut out);
            assert!(
                out.hits().iter().any(|h| (h.t - 2.0).abs() < 1e-3) || out.total() > MAX_PROBE_HITS,
                "{}: probe through an edge leaked: {q:?} -> {:?}",
                a.name(),
                out.hits()
            );
        }
    }

    // ---- meshes -------------------------------------------------------

    /// A `w` × `w` grid of unit cells in the plane z = `z`, each split along
    /// its (i, j)–(i+1, j+1) diagonal, shared vertices.
    fn grid(w: u32, z: f32) -> Mesh {
        let mut p = Vec::new();
        for j in 0..=w {
            for i in 0..=w {
                p.push(Vec3::new(i as f32, j as f32, z));
            }
        }
        let id = |i: u32, j: u32| j * (w + 1) + i;
        let mut idx = Vec::new();
        for j in 0..w {
            for i in 0..w {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                idx.push([a, b, c]);
                idx.push([a, c, d]);
            }
        }
        Mesh::new(p, idx, None)
    }

    fn merged(parts: &[Mesh]) -> Mesh {
        let mut p = Vec::new();
        let mut idx = Vec::new();
        for m in parts {
            let base = p.len() as u32;
            p.extend_from_slice(m.positions());
            idx.extend(m.indices.iter().map(|t| t.map(|i| i + base)));
        }
        Mesh::new(p, idx, None)
    }

    fn scaled(mut m: Mesh, s: f32, off: Vec3) -> Mesh {
        m.transform(|p| p * s + off, |n| n);
        m
    }

    /// Loads an OBJ as one mesh (all models merged).
    fn load_obj(path: &Path) -> Mesh {
        let (models, _) = tobj::load_obj(
            path,
            &tobj::LoadOptions {
                triangulate: true,
                single_index: true,
                ..Default::default()
            },
        )
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let parts: Vec<Mesh> = models
            .iter()
            .map(|m| {
                let p = m
                    .mesh
                    .positions
                    .chunks(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect();
                let idx = m
                    .mesh
                    .indices
                    .chunks(3)
                    .map(|c| [c[0], c[1], c[2]])
                    .collect();
                Mesh::new(p, idx, None)
            })
            .collect();
        merged(&parts)
    }

    // ---- tests --------------------------------------------------------

    fn random_soups(which: Backend) {
        for (seed, n, size) in [(1u64, 2000usize, 0.3f32), (2, 500, 1.0), (3, 20000, 0.05)] {
            let mesh = shapes::random_soup(n, size, seed);
            let qs = random_queries(1500, 1.5, 1, seed + 100);
            run(
                which,
                &format!("soup {n}/{size}"),
                vec![mesh],
                &qs,
                1e-5,
                0.02,
            );
        }
    }

    fn subdivided_sphere(which: Backend) {
        let mesh = shapes::sphere(5);
        let mut qs = random_queries(1500, 1.5, 1, 7);
        qs.extend(inside_queries(1000, Vec3::ZERO, 0.9, 0, 8));
        run(which, "sphere(5)", vec![mesh.clone()], &qs, 1e-5, 0.02);

        let meshes = Arc::new(vec![mesh.clone()]);
        let graze = grazing_queries(&mesh, 0, 600, 9);
        let cross = crossing_queries(&mesh, 0, 1000, 10);
        // Grazing queries are knife edges by construction: allow all of them.
        let e = embree(&meshes, which);
        check_watertight(&*e, &cross);
        compare(&*e, None, &meshes, &graze, 1e-5);
        let b = bvh(&meshes);
        let st = compare(&*e, Some(&*b), &meshes, &graze, 1e-5);
        println!("sphere(5) grazing: {st:?}");
        assert!(
            st.ambiguous > graze.len() / 2,
            "grazing rays were not grazing"
        );
        check_watertight(&*b, &cross);
    }

    fn several_meshes(which: Backend) {
        let meshes = vec![
            shapes::random_soup(800, 0.3, 11),
            scaled(shapes::sphere(3), 0.5, Vec3::new(0.4, 0.0, 0.0)),
            Mesh::default(), // an empty mesh keeps its id slot
            scaled(shapes::cuboid(), 0.3, Vec3::new(-0.5, 0.3, 0.2)),
            scaled(
                shapes::displaced_sphere(3, 0.1),
                0.4,
                Vec3::new(0.0, -0.5, -0.3),
            ),
        ];
        let mut qs = random_queries(2000, 1.5, 5, 12);
        qs.extend(inside_queries(500, Vec3::new(0.4, 0.0, 0.0), 0.4, 1, 13));
        qs.extend(inside_queries(500, Vec3::new(-0.5, 0.3, 0.2), 0.25, 3, 14));
        run(which, "several meshes", meshes, &qs, 1e-5, 0.02);
    }

    fn stanford_bunny(which: Backend) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/meshes/bunny.obj");
        assert!(
            path.is_file(),
            "{} is missing: it is part of the repository",
            path.display()
        );
        let (name, mesh) = ("bunny", load_obj(&path));
        assert!(mesh.triangle_count() > 3000);
        let lo = mesh
            .positions()
            .iter()
            .fold(Vec3::splat(f32::MAX), |a, &p| a.min(p));
        let hi = mesh
            .positions()
            .iter()
            .fold(Vec3::splat(f32::MIN), |a, &p| a.max(p));
        let c = (lo + hi) * 0.5;
        let r = (hi - lo).max_element() * 0.5;
        // Work in a frame where the mesh fills [-1, 1]³.
        let mesh = scaled(mesh, 1.0 / r, -c / r);
        let mut qs = random_queries(2000, 1.5, 1, 21);
        qs.extend(inside_queries(1000, Vec3::ZERO, 0.3, 0, 22));
        let graze = grazing_queries(&mesh, 0, 400, 23);
        run(which, name, vec![mesh.clone()], &qs, 1e-5, 0.03);

        let meshes = Arc::new(vec![mesh]);
        let cross = crossing_queries(&meshes[0], 0, 1000, 24);
        let e = embree(&meshes, which);
        check_watertight(&*e, &cross);
        compare(&*e, None, &meshes, &graze, 1e-5);
        let b = bvh(&meshes);
        let st = compare(&*e, Some(&*b), &meshes, &graze, 1e-5);
        println!("{name} grazing: {st:?}");
        check_watertight(&*b, &cross);
    }

    /// Axis-aligned rays through an integer grid: cell interiors, shared
    /// diagonal edges, and shared vertices and edges on grid lines. All
    /// arithmetic is exact, so the reference is exact and inclusive (every
    /// triangle touching the point).
    fn grid_queries() -> Vec<Query> {
        let mut qs = Vec::new();
        let mut seed = 0;
        for jy in 0..=8 {
            for ix in 0..=8 {
                // Half-integer steps: vertices, edge midpoints, cell centres
                // on the diagonal.
                let (x, y) = (ix as f32 * 0.5, jy as f32 * 0.5);
                for (o, d, tmax) in [
                    (Vec3::new(x, y, -0.5), Vec3::Z, 4.0),
                    (Vec3::new(x, y, 3.0), -Vec3::Z * 2.0, 2.0),
                    // Starts on the middle layer (t = 0 is a hit: inclusive).
                    (Vec3::new(x, y, 1.0), Vec3::Z, 1.0),
                ] {
                    for geom in 0..2 {
                        seed += 1;
                        qs.push(Query {
                            ray: Ray::new(o, d),
                            tmin: 0.0,
                            tmax,
                            geom,
                            seed,
                        });
                    }
                }
            }
        }
        // Ends exactly on a layer (t = tmax is a hit: inclusive).
        qs.push(Query {
            ray: Ray::new(Vec3::new(1.25, 2.5, -1.0), Vec3::Z),
            tmin: 0.0,
            tmax: 2.0,
            geom: 0,
            seed: 1,
        });
        qs
    }

    /// Layers z = 0, 1, 2 of a 4 × 4 grid as one mesh, and a second mesh at
    /// z = 1.5.
    fn grid_meshes() -> Vec<Mesh> {
        vec![
            merged(&[grid(4, 0.0), grid(4, 1.0), grid(4, 2.0)]),
            grid(4, 1.5),
        ]
    }

    /// Whether the query's ray runs inside a grid line's plane (x or y an
    /// integer), which is also where BVH node bounds lie.
    fn on_grid_plane(q: &Query) -> bool {
        q.ray.o.x.fract() == 0.0 || q.ray.o.y.fract() == 0.0
    }

    #[test]
    fn integer_grid_reference_is_inclusive() {
        let meshes = grid_meshes();
        // An interior vertex touches 6 triangles, an edge 2, a cell 1.
        let r = |x: f32, y: f32| {
            let ray = Ray::new(Vec3::new(x, y, -0.5), Vec3::Z);
            reference(&meshes, &ray, 0.0, 0.75, Some(0), 0.0).len()
        };
        assert_eq!(
            (
                r(2.0, 2.0),
                r(2.0, 2.5),
                r(2.5, 2.5),
                r(2.25, 2.75),
                r(4.0, 4.0)
            ),
            (6, 2, 2, 1, 2)
        );
    }

    /// Off the grid-line planes (cell interiors and shared diagonal edges),
    /// both backends report exactly the reference's hits.
    fn integer_grid_diagonal_edges_exact(which: Backend) {
        let meshes = Arc::new(grid_meshes());
        let qs: Vec<Query> = grid_queries()
            .into_iter()
            .filter(|q| !on_grid_plane(q))
            .collect();
        assert!(qs.len() > 90);
        let e = embree(&meshes, which);
        let st = compare(&*e, None, &meshes, &qs, 0.0);
        assert_eq!(st.ambiguous, 0);
        assert!(st.hits > 300, "{st:?}");
        let b = bvh(&meshes);
        let st = compare(&*e, Some(&*b), &meshes, &qs, 0.0);
        assert!(st.hits > 300, "{st:?}");
    }

    /// Our BVH is exact and inclusive on the grid-line planes too: every
    /// triangle around a shared vertex or axis edge.
    #[test]
    fn integer_grid_vertices_bvh_exact() {
        let meshes = Arc::new(grid_meshes());
        let qs: Vec<Query> = grid_queries().into_iter().filter(on_grid_plane).collect();
        let b = bvh(&meshes);
        let st = compare(&*b, None, &meshes, &qs, 0.0);
        assert_eq!(st.ambiguous, 0);
        assert!(st.hits > 1000, "{st:?}");
    }

    /// Embree on the grid-line planes. Embree's traversal replaces a zero
    /// direction component by +1e-18 (`rcp_safe`), so a ray lying exactly in
    /// a BVH node's bounding plane sees the boxes on the + side only: hits
    /// on triangles that touch the ray from the − side are dropped where a
    /// node boundary falls on the ray, and a ray in the scene's max-x or
    /// max-y bounding plane hits nothing. (Measure zero for the renderer:
    /// it needs a ray exactly inside an axis plane through the geometry.)
    /// What holds, and is checked: no false hits, exact t, and, except in
    /// the scene's max bounding planes, every layer is found (watertight).
    fn integer_grid_vertices_embree_watertight(which: Backend) {
        let meshes = Arc::new(grid_meshes());
        let qs: Vec<Query> = grid_queries().into_iter().filter(on_grid_plane).collect();
        let e = embree(&meshes, which);
        let (mut fewer, mut checked) = (0, 0);
        for q in &qs {
            let r = reference(&meshes, &q.ray, 0.0, q.tmax, Some(q.geom), 0.0);
            let mut out = ProbeHits::new();
            e.hits_on_segment(&q.ray, q.tmax, q.geom, q.seed, &mut out);
            for h in out.hits() {
                let x = find(&r, h).unwrap_or_else(|| panic!("false hit {h:?} on {q:?}"));
                assert!(t_close(h.t as f64, x.t), "{h:?} vs {x:?} on {q:?}");
            }
            fewer += (out.total() < r.len()) as usize;
            let on_max_plane = q.ray.o.x == 4.0 || q.ray.o.y == 4.0;
            if !on_max_plane {
                checked += 1;
                let mut want: Vec<f64> = r.iter().map(|x| x.t).collect();
                // Embree's t comes from a reciprocal and may be off by an
                // ulp: compare it through the reference hit it names.
                let mut got: Vec<f64> = out.hits().iter().map(|h| find(&r, h).unwrap().t).collect();
                for v in [&mut want, &mut got] {
                    v.sort_by(f64::total_cmp);
                    v.dedup();
                }
                assert_eq!(got, want, "layers missed by {q:?}");
                let all = reference(&meshes, &q.ray, q.tmin, q.tmax, None, 0.0);
                let n = e
                    .intersect(&q.ray, q.tmin, q.tmax)
                    .map(|h| find(&all, &h).unwrap().t);
                let rn = all.iter().map(|x| x.t).reduce(f64::min);
                assert_eq!(n, rn, "nearest hit of {q:?}");
                assert_eq!(e.occluded(&q.ray, q.tmin, q.tmax), rn.is_some(), "{q:?}");
            }
        }
        assert!(checked > 250, "{checked}");
        println!(
            "Embree on grid-line planes: {fewer} of {} probes found fewer triangles than the \
             inclusive reference",
            qs.len()
        );
    }

    /// More hits than `MAX_PROBE_HITS`: both backends keep the same subset.
    fn overflowing_probe_keeps_the_same_subset(which: Backend) {
        let stack: Vec<Mesh> = (0..150).map(|k| grid(2, k as f32 * 0.25)).collect();
        let meshes = vec![merged(&stack)];
        let mut qs = Vec::new();
        for (k, (x, y)) in [(0.3f32, 0.6f32), (0.25, 0.25), (0.5, 1.5), (1.75, 0.25)]
            .into_iter()
            .enumerate()
        {
            for seed in 0..8 {
                qs.push(Query {
                    ray: Ray::new(Vec3::new(x, y, -1.0), Vec3::Z),
                    tmin: 0.0,
                    tmax: 100.0,
                    geom: 0,
                    seed: seed * 31 + k as u32,
                });
            }
        }
        let meshes = Arc::new(meshes);
        let e = embree(&meshes, which);
        let b = bvh(&meshes);
        let mut subsets = std::collections::HashSet::new();
        for q in &qs {
            let r = reference(&meshes, &q.ray, 0.0, q.tmax, Some(0), 0.0);
            let (pe, _) = check_segment(&*e, &r, &q.ray, q.tmax, 0, q.seed);
            assert!(pe.total() > MAX_PROBE_HITS, "{}", pe.total());
            subsets.insert(prims(&pe));
        }
        // Different seeds keep different subsets.
        assert!(subsets.len() > qs.len() / 2);
        for q in &qs {
            let r = reference(&meshes, &q.ray, 0.0, q.tmax, Some(0), 0.0);
            let (pe, _) = check_segment(&*e, &r, &q.ray, q.tmax, 0, q.seed);
            let (pb, _) = check_segment(&*b, &r, &q.ray, q.tmax, 0, q.seed);
            assert_eq!(pe.total(), pb.total(), "{q:?}");
            assert_eq!(prims(&pe), prims(&pb), "{q:?}");
        }
    }

    /// Embree's build rejects meshes it would read out of bounds.
    fn embree_rejects_out_of_range_indices(which: Backend) {
        let mut m = shapes::quad();
        m.indices.push([0, 1, 4]);
        let err = accel::build(&Arc::new(vec![m]), which).err().unwrap();
        assert!(matches!(err, lucent::Error::Backend(_)), "{err}");
        assert!(err.to_string().contains("vertex index 4"), "{err}");
    }

    /// Embree's scene is committed with the traversal asked for (read back
    /// from its flags), `build` is watertight, and a fast scene still
    /// answers every ray that is not a knife edge as the reference does.
    fn each_traversal_is_what_embree_was_given(which: Backend) {
        let meshes = Arc::new(vec![shapes::sphere(5)]);
        assert_eq!(embree(&meshes, which).traversal(), Traversal::Watertight);
        for t in [Traversal::Watertight, Traversal::Fast] {
            let e = accel::build_with(&meshes, which, t).expect("Embree build");
            assert_eq!(e.traversal(), t);
            let mut qs = random_queries(1500, 1.5, 1, 7);
            qs.extend(inside_queries(1000, Vec3::ZERO, 0.9, 0, 8));
            let st = compare(&*e, None, &meshes, &qs, 1e-5);
            assert!(st.hits > 1000, "{t:?}: {st:?}");
        }
        // our BVH ignores the choice: it is watertight
        let b = accel::build_with(&meshes, Backend::Bvh, Traversal::Fast).unwrap();
        assert_eq!(b.traversal(), Traversal::Watertight);
    }

    /// Each check above as one test per Embree this build has: Embree 3
    /// (the `embree` feature; these tests need it) and Embree 4 (the
    /// `embree4` feature and a library: see [`embree4`]).
    macro_rules! on_each_embree {
        ($($body:ident),* $(,)?) => {
            mod on_embree3 {
                use lucent::accel::Backend;
                $( #[test] fn $body() { super::$body(Backend::Embree3) } )*
            }
            #[cfg(feature = "embree4")]
            mod on_embree4 {
                $( #[test] fn $body() { if let Some(b) = super::embree4() { super::$body(b) } } )*
            }
        };
    }

    on_each_embree!(
        random_soups,
        subdivided_sphere,
        several_meshes,
        stanford_bunny,
        integer_grid_diagonal_edges_exact,
        integer_grid_vertices_embree_watertight,
        overflowing_probe_keeps_the_same_subset,
        embree_rejects_out_of_range_indices,
        each_traversal_is_what_embree_was_given,
    );

    /// Embree 4 if this process can load it; else `None` (the test is
    /// skipped, saying so), unless `LUCENT_REQUIRE_EMBREE4` is set (as
    /// scripts/test.sh does), where a missing Embree 4 fails the test.
    #[cfg(feature = "embree4")]
    fn embree4() -> Option<Backend> {
        match Backend::Embree4.resolve() {
            Ok(b) => Some(b),
            Err(e) if std::env::var_os("LUCENT_REQUIRE_EMBREE4").is_none() => {
                eprintln!("Embree 4 not tested: {e}");
                None
            }
            Err(e) => panic!("LUCENT_REQUIRE_EMBREE4 is set but {e}"),
        }
    }
}
