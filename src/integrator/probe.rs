//! The probe query of the BSSRDF's area integral (pbrt-v4 §15.4's split
//! between `SubsurfaceMaterial`'s BSSRDF and the integrator): the BSSRDF
//! samples a probe segment ([`ProbeSampler::sample_probe`]), the integrator
//! asks the accel for every hit of the segment on the exit point's object
//! ([`Accel::hits_on_segment`]), keeps one ([`pick_hit`]) and the BSSRDF
//! weighs it ([`ProbeSampler::weigh`]). The tests here check the whole
//! estimator end to end on a brute-force accel: energy on planes for every
//! option, hit counting, empty and degenerate geometry.

use crate::accel::{Accel, Hit, ProbeHits};
use crate::bssrdf::{pick_hit, ProbeRandoms, ProbeSampler};
use crate::geometry::{Frame, Mesh, Vec3};

/// The object a probe searches: mesh `geom` of `accel`, and that mesh (for
/// its face normals).
#[derive(Clone, Copy)]
pub struct ProbeTarget<'a> {
    pub accel: &'a dyn Accel,
    pub geom: u32,
    pub mesh: &'a Mesh,
}

/// One sampled entry point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSample {
    /// The accel hit (mesh `geom`, triangle `prim`, barycentrics).
    pub hit: Hit,
    /// xi, reconstructed along the probe ray.
    pub point: Vec3,
    /// Unit geometric normal of the hit triangle, oriented by its winding
    /// (outward for a consistently wound closed mesh); not flipped toward xo.
    pub normal: Vec3,
    /// Rd(|xo − xi|) / p(xi) × (hits on the segment), per channel.
    pub weight: Vec3,
}

/// Samples an entry point xi for exit point `xo` (shading frame `frame`) on
/// `target` with one probe: sample the segment, query all its hits on the
/// object into the scratch buffer `hits` (no allocation), pick one, weigh
/// it. None when the material samples nothing, the probe finds nothing, or
/// the picked hit has zero density; the estimate is then 0.
pub fn sample_entry(
    sampler: &ProbeSampler,
    xo: Vec3,
    frame: &Frame,
    u: &ProbeRandoms,
    target: &ProbeTarget,
    hits: &mut ProbeHits,
) -> Option<ProbeSample> {
    // docs/bssrdf.md §5: steps 1–2 in the BSSRDF, step 3 here (every hit
    // on the object, one picked uniformly), step 4 in the BSSRDF.
    let seg = sampler.sample_probe(xo, frame, u)?;
    target
        .accel
        .hits_on_segment(&seg.ray, seg.t_max, target.geom, u.seed, hits);
    let kept = hits.hits();
    if kept.is_empty() {
        return None;
    }
    let hit = kept[pick_hit(u, kept.len())];
    let normal = target.mesh.face_normal(hit.prim);
    let entry = sampler.weigh(&seg, hit.t, normal, hits.total())?;
    Some(ProbeSample {
        hit,
        point: entry.point,
        normal,
        weight: entry.weight,
    })
}

#[cfg(test)]
// Tests index parallel per-channel arrays by channel number.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::accel::{Hit, MAX_PROBE_HITS};
    use crate::bssrdf::{
        profile, ChannelStrategy, ProbeAxes, ProbeOptions, RadiusSampler, SubsurfaceParams,
        TableSpacing,
    };
    use crate::geometry::{Mesh, Ray};
    use crate::sampling::Rng;

    /// A brute-force [`Accel`]: every query loops over every triangle with a
    /// Möller–Trumbore test in f64. Slow, obviously right, and independent of
    /// the BVH and Embree backends.
    struct Brute {
        meshes: Vec<Mesh>,
    }

    fn tri_hit(ray: &Ray, [a, b, c]: [Vec3; 3], tmin: f32, tmax: f32) -> Option<(f32, f32, f32)> {
        let (o, d) = (ray.o.as_dvec3(), ray.d.as_dvec3());
        let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-300 {
            return None;
        }
        let inv = 1.0 / det;
        let s = o - a;
        let u = s.dot(p) * inv;
        let q = s.cross(e1);
        let v = d.dot(q) * inv;
        let t = e2.dot(q) * inv;
        if u < 0.0 || v < 0.0 || u + v > 1.0 || t < tmin as f64 || t > tmax as f64 {
            return None;
        }
        Some((t as f32, u as f32, v as f32))
    }

    impl Accel for Brute {
        fn name(&self) -> &'static str {
            "brute"
        }
        fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
            let mut best: Option<Hit> = None;
            for (g, m) in self.meshes.iter().enumerate() {
                for prim in 0..m.triangle_count() as u32 {
                    if let Some((t, u, v)) = tri_hit(ray, m.triangle(prim), tmin, tmax) {
                        if best.is_none_or(|b| t < b.t) {
                            best = Some(Hit {
                                t,
                                geom: g as u32,
                                prim,
                                u,
                                v,
                            });
                        }
                    }
                }
            }
            best
        }
        fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
            self.intersect(ray, tmin, tmax).is_some()
        }
        fn rejected_rays(&self) -> u64 {
            0
        }
        fn hits_on_segment(&self, ray: &Ray, tmax: f32, geom: u32, seed: u32, out: &mut ProbeHits) {
            out.reset(seed);
            let m = &self.meshes[geom as usize];
            for prim in 0..m.triangle_count() as u32 {
                if let Some((t, u, v)) = tri_hit(ray, m.triangle(prim), 0.0, tmax) {
                    out.record(Hit {
                        t,
                        geom,
                        prim,
                        u,
                        v,
                    });
                }
            }
            out.finish();
        }
    }

    /// Square planes of half-size `l` at heights `zs` (normal +z), one mesh.
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

    struct Stats {
        mean: [f64; 3],
        se: [f64; 3],
        max: f64,
        found: usize,
    }

    /// Mesh 0 of `accel`.
    fn target(accel: &Brute) -> ProbeTarget<'_> {
        ProbeTarget {
            accel,
            geom: 0,
            mesh: &accel.meshes[0],
        }
    }

    /// Runs n probes at xo and averages the weights (None counts as 0).
    fn run(s: &ProbeSampler, accel: &Brute, xo: Vec3, frame: &Frame, n: usize, key: u64) -> Stats {
        run_on(s, accel, &accel.meshes[0], xo, frame, n, key)
    }

    fn run_on(
        s: &ProbeSampler,
        accel: &dyn Accel,
        mesh: &Mesh,
        xo: Vec3,
        frame: &Frame,
        n: usize,
        key: u64,
    ) -> Stats {
        let mut rng = Rng::from_key(key);
        let mut hits = ProbeHits::new();
        let (mut s1, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
        let (mut max, mut found) = (0.0f64, 0);
        let target = ProbeTarget {
            accel,
            geom: 0,
            mesh,
        };
        for _ in 0..n {
            let u = ProbeRandoms::from_rng(&mut rng);
            if let Some(ps) = sample_entry(s, xo, frame, &u, &target, &mut hits) {
                found += 1;
                assert!(ps.normal.is_finite() && (ps.normal.length() - 1.0).abs() < 1e-5);
                assert!(ps.point.is_finite());
                for c in 0..3 {
                    let w = ps.weight[c] as f64;
                    assert!(w.is_finite() && w >= 0.0, "weight {:?}", ps.weight);
                    s1[c] += w;
                    s2[c] += w * w;
                    max = max.max(w);
                }
            }
        }
        let nf = n as f64;
        let mean = s1.map(|x| x / nf);
        let se = std::array::from_fn(|c| ((s2[c] / nf - mean[c] * mean[c]).max(0.0) / nf).sqrt());
        Stats {
            mean,
            se,
            max,
            found,
        }
    }

    fn all_options() -> Vec<ProbeOptions> {
        let mut v = Vec::new();
        for axes in [ProbeAxes::Normal, ProbeAxes::Mis3] {
            for channel in [ChannelStrategy::Single, ChannelStrategy::Mis] {
                for radius in [
                    RadiusSampler::Uniform,
                    RadiusSampler::table(64),
                    RadiusSampler::Table {
                        size: 64,
                        spacing: TableSpacing::Uniform,
                    },
                    RadiusSampler::Analytic,
                    RadiusSampler::Mixture,
                ] {
                    for renormalize in [false, true] {
                        v.push(ProbeOptions {
                            axes,
                            channel,
                            radius,
                            rmax_quantile: 0.999,
                            renormalize,
                        });
                    }
                }
            }
        }
        v
    }

    /// A frame whose normal is tilted by `deg` degrees from +z (a shading
    /// normal that differs from the geometric one), so that T and B probes
    /// hit the plane too and the axis MIS is exercised.
    fn tilted(deg: f32) -> Frame {
        let a = deg.to_radians();
        Frame::from_normal(Vec3::new(a.sin() * 0.6, a.sin() * 0.8, a.cos()).normalize())
    }

    /// Test materials with channels 10× apart, except for the Uniform
    /// sampler: its weight A·R(r)·πRmax² has a log-divergent second moment
    /// at r → 0 (cut only by RHO_MIN), so a channel with d ≪ Rmax gives a
    /// sample mean that is unreliable at any test budget. That is the
    /// baseline's known weakness, not an error.
    fn params_for(opts: &ProbeOptions, scale: f64) -> SubsurfaceParams {
        let d = if opts.radius == RadiusSampler::Uniform {
            [1.0, 0.8, 0.6]
        } else {
            [1.0, 0.35, 0.1]
        };
        SubsurfaceParams {
            albedo: [0.8, 0.5, 0.3],
            d: d.map(|d| d * scale),
            eta: 1.3,
            medium: None,
        }
    }

    fn assert_close(st: &Stats, truth: [f64; 3], what: &str) {
        for c in 0..3 {
            let tol = 5.0 * st.se[c] + 1e-9;
            assert!(
                (st.mean[c] - truth[c]).abs() < tol,
                "{what} ch{c}: {} ± {} vs {}",
                st.mean[c],
                st.se[c],
                truth[c]
            );
        }
    }

    #[test]
    fn flat_plane_reflects_a_times_cdf_rmax_for_every_option() {
        // The plane (half-size 100 d_max) covers the probe sphere (19.9 d_max),
        // so it is infinite for the estimator: the mean weight must be
        // A·CDF(Rmax) per channel, or A renormalized, for every axis choice,
        // channel strategy, radius sampler, and for a shading normal tilted
        // against the plane (all three axes then hit it obliquely).
        let accel = Brute {
            meshes: vec![planes(100.0, &[0.0])],
        };
        let xo = Vec3::new(0.37, -0.21, 0.0); // off the quad's diagonal
        for (i, opts) in all_options().iter().enumerate() {
            let params = params_for(opts, 1.0);
            let s = ProbeSampler::new(&params, opts).unwrap();
            let truth = s.planar_reflectance();
            for c in 0..3 {
                let mass = profile::cdf(s.rmax(), params.d[c]);
                let want = params.albedo[c] * if opts.renormalize { 1.0 } else { mass };
                assert!((truth[c] - want).abs() < 1e-12);
            }
            for (j, deg) in [0.0f32, 40.0].into_iter().enumerate() {
                let what = format!("{opts:?} tilt {deg}°");
                if opts.radius == RadiusSampler::Uniform {
                    // P(weight > w) ~ w⁻² (see params_for): the sample
                    // variance underestimates the error, so allow 10% too.
                    let st = run(&s, &accel, xo, &tilted(deg), 300_000, (i * 8 + j) as u64);
                    for c in 0..3 {
                        let err = (st.mean[c] - truth[c]).abs();
                        assert!(
                            err < 5.0 * st.se[c] + 0.1 * truth[c],
                            "{what} ch{c}: {} vs {}",
                            st.mean[c],
                            truth[c]
                        );
                    }
                } else {
                    let st = run(&s, &accel, xo, &tilted(deg), 60_000, (i * 8 + j) as u64);
                    assert_close(&st, truth, &what);
                }
            }
        }
    }

    #[test]
    fn ketchup_blue_is_exactly_zero() {
        let params =
            SubsurfaceParams::from_preset("Ketchup", 1.0, profile::Fit::Searchlight).unwrap();
        let accel = Brute {
            meshes: vec![planes(2000.0, &[0.0])],
        };
        for (i, opts) in all_options().iter().enumerate() {
            let s = ProbeSampler::new(&params, opts).unwrap();
            let mut rng = Rng::from_key(i as u64);
            let mut hits = ProbeHits::new();
            let mut found = 0;
            for _ in 0..5_000 {
                let u = ProbeRandoms::from_rng(&mut rng);
                if let Some(ps) = sample_entry(
                    &s,
                    Vec3::new(0.3, 0.1, 0.0),
                    &tilted(20.0),
                    &u,
                    &target(&accel),
                    &mut hits,
                ) {
                    found += 1;
                    assert_eq!(ps.weight.z.to_bits(), 0f32.to_bits(), "{opts:?}");
                    assert!(ps.weight.x.is_finite() && ps.weight.y.is_finite());
                }
            }
            assert!(found > 1000, "{opts:?}: {found}");
        }
        let s = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
        assert_eq!(s.planar_reflectance()[2], 0.0);
        assert_eq!(s.rd(0.5)[2], 0.0);
    }

    #[test]
    fn spectralon_renders_finite_white_and_not_above_a() {
        // σa = 0: d comes from the absorption floor (params.rs); a flat slab
        // reflects A·CDF(Rmax) = 0.999 ≤ A = 1, and exactly A renormalized.
        let params =
            SubsurfaceParams::from_preset("spectralon", 1.0, profile::Fit::Searchlight).unwrap();
        let accel = Brute {
            meshes: vec![planes(1000.0, &[0.0])],
        };
        for renormalize in [false, true] {
            let opts = ProbeOptions {
                renormalize,
                ..ProbeOptions::default()
            };
            let s = ProbeSampler::new(&params, &opts).unwrap();
            assert!(s.rmax().is_finite() && s.rmax() < 100.0, "{}", s.rmax());
            let st = run(
                &s,
                &accel,
                Vec3::new(0.37, -0.21, 0.0),
                &tilted(20.0),
                40_000,
                5,
            );
            assert_close(&st, s.planar_reflectance(), "spectralon");
            for c in 0..3 {
                assert!(st.mean[c] > 0.95 && s.planar_reflectance()[c] <= 1.0 + 1e-12);
            }
        }
    }

    #[test]
    fn several_hits_pick_one_and_multiply_by_the_count() {
        // Parallel planes at depths k·δ inside the probe sphere. Along N the
        // probe crosses all of them; one hit is kept with weight × total.
        // ∫_{plane at depth z, within the sphere} R dA = CDF(Rmax) − CDF(|z|).
        let params = SubsurfaceParams {
            albedo: [0.9, 0.6, 0.4],
            d: [1.0, 0.8, 0.5],
            eta: 1.3,
            medium: None,
        };
        // 3 planes, then 100 (more than MAX_PROBE_HITS = 64: the query keeps a
        // random 64 and counts them all)
        for (count, delta) in [(3usize, 0.7f32), (100, 0.15)] {
            assert!(count <= 3 || count > MAX_PROBE_HITS);
            let zs: Vec<f32> = (0..count).map(|k| -(k as f32) * delta).collect();
            let accel = Brute {
                meshes: vec![planes(60.0, &zs)],
            };
            for opts in [
                ProbeOptions::default(),
                ProbeOptions::seed_document(RadiusSampler::Analytic),
                ProbeOptions {
                    radius: RadiusSampler::Mixture,
                    ..ProbeOptions::default()
                },
            ] {
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let truth: [f64; 3] = std::array::from_fn(|c| {
                    let d = params.d[c];
                    let rm = s.rmax();
                    params.albedo[c]
                        * zs.iter()
                            .map(|&z| {
                                (profile::cdf(rm, d) - profile::cdf((z.abs() as f64).min(rm), d))
                                    .max(0.0)
                            })
                            .sum::<f64>()
                });
                let st = run(
                    &s,
                    &accel,
                    Vec3::new(0.31, -0.17, 0.0),
                    &Frame::from_normal(Vec3::Z),
                    40_000,
                    count as u64,
                );
                assert_close(&st, truth, &format!("{count} planes {opts:?}"));
                // and ignoring the count would be far off
                assert!(truth[0] > 1.8 * s.planar_reflectance()[0]);
            }
        }
    }

    #[test]
    fn tiny_and_huge_d() {
        // d = 1e-6 on a unit plane (f32 positions near the origin) still
        // gives A·CDF(Rmax); d = 1e6 on the same plane: the profile mass on
        // the plane is ~1e-6, probes almost never hit, nothing is NaN.
        let accel = Brute {
            meshes: vec![planes(1.0, &[0.0])],
        };
        for (k, opts) in all_options().iter().enumerate() {
            let tiny = params_for(opts, 1e-6);
            let s = ProbeSampler::new(&tiny, opts).unwrap();
            let xo = Vec3::new(3.1e-7, -1.3e-7, 0.0);
            let st = run(&s, &accel, xo, &tilted(30.0), 20_000, 100 + k as u64);
            for c in 0..3 {
                let t = s.planar_reflectance()[c];
                // f32 quantization of xo and hits (~1e-13 here) is 1e-7 d.
                assert!(
                    (st.mean[c] - t).abs() < 5.0 * st.se[c] + 1e-3 * t,
                    "{opts:?} ch{c}: {} ± {} vs {t}",
                    st.mean[c],
                    st.se[c]
                );
            }
            let huge = tiny.scaled(1e12);
            let s = ProbeSampler::new(&huge, opts).unwrap();
            let st = run(
                &s,
                &accel,
                Vec3::new(0.1, 0.2, 0.0),
                &tilted(30.0),
                20_000,
                200 + k as u64,
            );
            assert!(st.found < 20_000 / 10, "{opts:?}: {}", st.found);
            // the whole plane holds about ∫∫ A/(4π d r) dA = A·8L asinh(1)/(4π d) ≈ 4e-7 A
            for c in 0..3 {
                assert!(st.mean[c] < 1e-3, "{opts:?}: {:?}", st.mean);
            }
        }
    }

    #[test]
    fn grazing_hits_are_bounded_by_mis3() {
        // The shading normal is tilted 88° from the plane's normal: probes
        // along N meet the plane at |V·N| = cos 88° ≈ 0.035. Both estimators
        // are unbiased, but Normal's weights reach 1/0.035 × larger values,
        // while Mis3's are bounded by 4√3·n_active·A (module docs).
        let params = SubsurfaceParams {
            albedo: [0.8, 0.8, 0.8],
            d: [1.0, 0.7, 0.4],
            eta: 1.3,
            medium: None,
        };
        let accel = Brute {
            meshes: vec![planes(100.0, &[0.0])],
        };
        let frame = tilted(88.0);
        let xo = Vec3::new(0.37, -0.21, 0.0);
        let bound = 4.0 * 3f64.sqrt() * 3.0 * 0.8;
        let mut maxes = Vec::new();
        for axes in [ProbeAxes::Normal, ProbeAxes::Mis3] {
            for radius in [RadiusSampler::Analytic, RadiusSampler::Mixture] {
                let opts = ProbeOptions {
                    axes,
                    radius,
                    ..ProbeOptions::default()
                };
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let st = run(&s, &accel, xo, &frame, 100_000, 7);
                assert_close(&st, s.planar_reflectance(), &format!("{opts:?}"));
                println!(
                    "grazing 88°, {axes:?} {radius:?}: max weight {:.2} (Mis3 bound {bound:.2}), mean {:.4}, rel. s.e. {:.2e}",
                    st.max,
                    st.mean[0],
                    st.se[0] / st.mean[0]
                );
                if axes == ProbeAxes::Mis3 {
                    assert!(st.max <= bound * (1.0 + 1e-4), "{}", st.max);
                }
                maxes.push(st.max);
            }
        }
        // the normal-only probe's maximum is far above the bound
        assert!(
            maxes[0] > 2.0 * bound && maxes[1] > 2.0 * bound,
            "{maxes:?}"
        );
    }

    #[test]
    fn probes_that_find_nothing_return_none() {
        let params = SubsurfaceParams {
            albedo: [0.8, 0.5, 0.3],
            d: [1.0, 0.35, 0.1],
            eta: 1.3,
            medium: None,
        };
        // the only surface is far beyond Rmax
        let accel = Brute {
            meshes: vec![planes(10.0, &[-1000.0])],
        };
        for opts in all_options() {
            let s = ProbeSampler::new(&params, &opts).unwrap();
            let st = run(
                &s,
                &accel,
                Vec3::ZERO,
                &Frame::from_normal(Vec3::Z),
                2_000,
                1,
            );
            assert_eq!(st.found, 0);
        }
        // an empty mesh
        let empty = Brute {
            meshes: vec![Mesh::new(vec![], vec![], None)],
        };
        let s = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
        assert_eq!(
            run(&s, &empty, Vec3::ZERO, &Frame::from_normal(Vec3::Z), 100, 2).found,
            0
        );
        // no active channel: valid material, never samples
        let black = SubsurfaceParams {
            albedo: [0.0; 3],
            d: [1.0; 3],
            eta: 1.3,
            medium: None,
        };
        let s = ProbeSampler::new(&black, &ProbeOptions::default()).unwrap();
        assert_eq!(s.rmax(), 0.0);
        let plane = Brute {
            meshes: vec![planes(10.0, &[0.0])],
        };
        assert_eq!(
            run(&s, &plane, Vec3::ZERO, &Frame::from_normal(Vec3::Z), 100, 3).found,
            0
        );
        // and a degenerate (zero-area) triangle is skipped, not divided by
        let degenerate = Brute {
            meshes: vec![Mesh::new(
                vec![
                    Vec3::new(-1.0, 0.0, 0.0),
                    Vec3::new(1.0, 0.0, 0.0),
                    Vec3::new(0.0, 0.0, 0.0),
                ],
                vec![[0, 1, 2]],
                None,
            )],
        };
        let s = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
        assert_eq!(
            run(
                &s,
                &degenerate,
                Vec3::ZERO,
                &Frame::from_normal(Vec3::Z),
                1000,
                4
            )
            .found,
            0
        );
    }

    #[test]
    fn extreme_random_numbers_are_finite() {
        let params = SubsurfaceParams {
            albedo: [0.8, 0.5, 0.3],
            d: [1.0, 0.35, 0.1],
            eta: 1.3,
            medium: None,
        };
        let accel = Brute {
            meshes: vec![planes(100.0, &[0.0])],
        };
        let top = 1.0 - f64::EPSILON / 2.0;
        let mut hits = ProbeHits::new();
        for opts in all_options() {
            let s = ProbeSampler::new(&params, &opts).unwrap();
            for &a in &[0.0, top] {
                for &b in &[0.0, top] {
                    for &r in &[0.0, 1e-300, top] {
                        let u = ProbeRandoms {
                            axis: a,
                            channel: b,
                            radius: r,
                            angle: a,
                            hit: b,
                            seed: 0,
                        };
                        let frame = tilted(35.0);
                        if let Some(ps) = sample_entry(
                            &s,
                            Vec3::new(0.37, -0.21, 0.0),
                            &frame,
                            &u,
                            &target(&accel),
                            &mut hits,
                        ) {
                            assert!(
                                ps.weight.is_finite() && ps.weight.min_element() >= 0.0,
                                "{opts:?} {u:?}: {:?}",
                                ps.weight
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn real_bvh_backend_gives_the_same_energy() {
        // The same ground truths through lucent's BVH (watertight test,
        // two-level tree) instead of the brute-force loop: a tilted-frame
        // plane, and 100 stacked planes (probe-hit overflow).
        use crate::accel::{build, Backend};
        use std::sync::Arc;
        let params = SubsurfaceParams {
            albedo: [0.9, 0.6, 0.4],
            d: [1.0, 0.35, 0.1],
            eta: 1.3,
            medium: None,
        };
        let xo = Vec3::new(0.31, -0.17, 0.0);
        let zs: Vec<f32> = (0..100).map(|k| -(k as f32) * 0.15).collect();
        for (mesh, stacked) in [(planes(100.0, &[0.0]), false), (planes(60.0, &zs), true)] {
            let meshes = Arc::new(vec![mesh]);
            let bvh = build(&meshes, Backend::Bvh).unwrap();
            for opts in [
                ProbeOptions::default(),
                ProbeOptions::seed_document(RadiusSampler::table(256)),
                ProbeOptions {
                    channel: ChannelStrategy::Single,
                    radius: RadiusSampler::Mixture,
                    renormalize: true,
                    ..ProbeOptions::default()
                },
            ] {
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let rm = s.rmax();
                let truth: [f64; 3] = if stacked {
                    std::array::from_fn(|c| {
                        let d = params.d[c];
                        let k = s.planar_reflectance()[c] / profile::cdf(rm, d);
                        k * zs
                            .iter()
                            .map(|&z| {
                                (profile::cdf(rm, d) - profile::cdf((z.abs() as f64).min(rm), d))
                                    .max(0.0)
                            })
                            .sum::<f64>()
                    })
                } else {
                    s.planar_reflectance()
                };
                let frame = if stacked {
                    Frame::from_normal(Vec3::Z)
                } else {
                    tilted(40.0)
                };
                let st = run_on(&s, bvh.as_ref(), &meshes[0], xo, &frame, 40_000, 77);
                assert_close(&st, truth, &format!("bvh stacked={stacked} {opts:?}"));
            }
        }
    }
}
