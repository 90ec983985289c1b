//! The probe estimator end to end on a brute-force accel: energy on planes
//! for every option, hit counting, empty and degenerate geometry, and on
//! curved geometry that entry points stay within Rmax of xo and are
//! distributed with the density the weights divide by (a χ² test).

// Tests index parallel per-channel arrays by channel number.
#![allow(clippy::needless_range_loop)]

use super::*;
use crate::accel::{Hit, MAX_PROBE_HITS};
use crate::bssrdf::{
    profile, ChannelStrategy, ProbeAxes, ProbeOptions, RadiusSampler, SubsurfaceParams,
    TableSpacing,
};
use crate::geometry::curvature::tests::uv_sphere;
use crate::geometry::curvature::{curvature, exit_curvature, MeshCurvature};
use crate::geometry::{Mesh, Ray};
use crate::sampling::Rng;
use glam::DVec3;

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
        // The curvature `Curvature` reads, drawn per probe with κ·Rmax
        // in [0, 40) (κ·d up to ~2: ε over its whole range, ε_min on a
        // quarter of the probes): each probe is unbiased for its own
        // axis probabilities, so the mean must be right for any mix.
        let kappa = (40.0 * rng.uniform_f64().powi(2) / s.rmax()) as f32;
        if let Some(ps) = sample_entry(s, xo, frame, kappa, &u, &target, &mut hits) {
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
    for axes in ProbeAxes::ALL {
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
                        profile: crate::bssrdf::ProfileShape::Burley,
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

/// The tabulated profile (`bssrdf::tabulated`) on an infinite plane: the
/// mean weight is A·CDF(Rmax) of the table's own CDF per channel, or A
/// renormalized, for every axis rule, both channel strategies and a tilted
/// shading normal, with Rmax the table's quantile (longer than the fit's:
/// the medium's transfer has the longer tail). A density that disagreed
/// with what is sampled, or Rd read from the fit, would miss it.
#[test]
fn a_tabulated_profile_reflects_a_times_its_cdf_on_a_plane() {
    let params = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight).unwrap();
    let accel = Brute {
        meshes: vec![planes(4000.0, &[0.0])],
    };
    let xo = Vec3::new(0.37, -0.21, 0.0);
    let fit = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
    for (i, axes) in ProbeAxes::ALL.into_iter().enumerate() {
        for (j, channel) in [ChannelStrategy::Single, ChannelStrategy::Mis]
            .into_iter()
            .enumerate()
        {
            for renormalize in [false, true] {
                let opts = ProbeOptions {
                    axes,
                    channel,
                    renormalize,
                    profile: crate::bssrdf::ProfileShape::Tabulated,
                    ..ProbeOptions::default()
                };
                let s = ProbeSampler::new(&params, &opts).unwrap();
                assert!(
                    s.rmax() > 1.5 * fit.rmax(),
                    "{} vs {}",
                    s.rmax(),
                    fit.rmax()
                );
                let truth = s.planar_reflectance();
                for c in 0..3 {
                    let mass = s.dist(c).unwrap().profile_mass();
                    let want = params.albedo[c] * if renormalize { 1.0 } else { mass };
                    assert!((truth[c] - want).abs() < 1e-12);
                }
                for (k, deg) in [0.0f32, 40.0].into_iter().enumerate() {
                    let key = (100 + i * 16 + j * 4 + k * 2 + renormalize as usize) as u64;
                    let st = run(&s, &accel, xo, &tilted(deg), 40_000, key);
                    assert_close(&st, truth, &format!("{opts:?} tilt {deg}°"));
                }
            }
        }
    }
}

/// The shape, not only the total: xo sits on the plane's extension a
/// distance D = one diffusion length (of marble's red) outside a
/// half-plane, so the estimator sees only the profile beyond D. Its mean
/// is A·∫ R(r)·2r·acos(D/r) dr over D … Rmax of the table's own R, more
/// than twice the fit's there; an estimator that weighed Rd from the fit
/// (or sampled the fit) would converge to the latter.
#[test]
fn a_tabulated_profile_reaches_a_half_plane_one_diffusion_length_away() {
    let params = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight).unwrap();
    let m = params.medium.unwrap();
    let dl = crate::bssrdf::params::diffuse_mfp(m.sigma_s[0] * (1.0 - m.g), m.sigma_a[0]);
    let mut mesh = planes(2000.0, &[0.0]);
    mesh.transform(|q| q + Vec3::new(dl as f32 + 2000.0, 0.0, 0.0), |n| n);
    let accel = Brute { meshes: vec![mesh] };
    let opts = ProbeOptions {
        profile: crate::bssrdf::ProfileShape::Tabulated,
        ..ProbeOptions::default()
    };
    let s = ProbeSampler::new(&params, &opts).unwrap();
    // ∫_D^Rmax f(r) 2r acos(D/r) dr by the midpoint rule in t, r = D + (Rmax − D) t²
    let beyond = |f: &dyn Fn(f64) -> f64, rmax: f64| -> f64 {
        let n = 200_000;
        (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) / n as f64;
                let r = dl + (rmax - dl) * t * t;
                f(r) * 2.0 * r * (dl / r).acos() * 2.0 * (rmax - dl) * t / n as f64
            })
            .sum()
    };
    let truth: [f64; 3] = std::array::from_fn(|c| beyond(&|r| s.rd(r)[c], s.rmax()));
    let fit = ProbeSampler::new(&params, &ProbeOptions::default()).unwrap();
    let fit_mean = beyond(&|r| fit.rd(r)[0], fit.rmax());
    let st = run(
        &s,
        &accel,
        Vec3::ZERO,
        &Frame::from_normal(Vec3::Z),
        100_000,
        11,
    );
    println!(
        "beyond one ld: {:?} ± {:?}, truth {truth:?}, fit {fit_mean}",
        st.mean, st.se
    );
    assert_close(&st, truth, "tabulated, half-plane beyond one ld");
    assert!(truth[0] > 2.0 * fit_mean && truth[0] - fit_mean > 20.0 * st.se[0]);
}

#[test]
fn ketchup_blue_is_exactly_zero() {
    // The Jensen table's A = 0 in blue (the albedo table gives ≈ 0.002).
    let params = SubsurfaceParams::from_preset_with(
        "Ketchup",
        1.0,
        profile::Fit::Searchlight,
        crate::bssrdf::AlbedoSource::Given,
        None,
    )
    .unwrap();
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
                0.0,
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
fn grazing_hits_are_bounded_by_mis3_and_curvature() {
    // The shading normal is tilted 88° from the plane's normal: probes
    // along N meet the plane at |V·N| = cos 88° ≈ 0.035. All three rules
    // are unbiased, but Normal's weights reach 1/0.035 × larger values,
    // while Mis3's are bounded by 4√3·n_active·A and Curvature's (ε from
    // ε_min to ¼, drawn per probe by `run_on`) by (√3/ε_min)·n_active·A
    // (module docs of bssrdf::probe, `ProbeAxes::weight_bound`).
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
    let bound = |axes: ProbeAxes| axes.weight_bound().map(|g| g * 3.0 * 0.8);
    let mis3_bound = bound(ProbeAxes::Mis3).unwrap();
    assert!((mis3_bound - 4.0 * 3f64.sqrt() * 3.0 * 0.8).abs() < 1e-12);
    let mut maxes = Vec::new();
    for axes in ProbeAxes::ALL {
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
                "grazing 88°, {axes:?} {radius:?}: max weight {:.2} (bound {:?}), mean {:.4}, rel. s.e. {:.2e}",
                st.max,
                bound(axes),
                st.mean[0],
                st.se[0] / st.mean[0]
            );
            if let Some(b) = bound(axes) {
                assert!(st.max <= b * (1.0 + 1e-4), "{axes:?}: {} > {b}", st.max);
            }
            if axes == ProbeAxes::Normal {
                maxes.push(st.max);
            }
        }
    }
    // the normal-only probe's maximum is far above mis3's bound
    assert!(
        maxes[0] > 2.0 * mis3_bound && maxes[1] > 2.0 * mis3_bound,
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
                        [0.0, 1e30][(r == top) as usize],
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

// Curved geometry. The flat planes above cannot tell whether a probe's
// chord stops at the sphere of radius Rmax around xo (every hit of a
// plane through xo along a chord of that sphere lies in it for any
// half-length up to the plane's size): a sphere, a wedge and a curved
// patch can.

#[test]
fn light_across_a_sharp_edge_is_found_by_one_probe_in_a_few() {
    // xo on a cube's side face, half a d below its top edge, lit only
    // through the top face (X = the probe's weight when it lands there:
    // the light that crosses the edge). The triangle's curvature is the
    // cube's 1/R floor (κd ≈ 0.02, ε = ε_min): tangent probes, the only
    // ones that reach the top face, are one in a hundred, so X's
    // relative variance is in the hundreds. The sharp edge at s = d/2
    // makes κ_axes = 1/s (ε = ¼): the same mean, a variance ~50× lower
    // (16.7 against 796 here).
    let opts = ProbeOptions::default();
    assert_eq!(opts.axes, ProbeAxes::Curvature);
    let params = params_for(&opts, 1.0);
    let s = ProbeSampler::new(&params, &opts).unwrap();
    let h = 30.0f32;
    let mut cube = crate::scene::shapes::cuboid();
    cube.transform(|p| p * h, |n| n);
    let prim = (0..12).find(|&p| cube.face_normal(p) == Vec3::X).unwrap();
    let cache = MeshCurvature::new(&cube, s.rmax() as f32);
    assert_eq!(cache.sharp_edge_count(), 12);
    let xo = Vec3::new(h, 0.3, h - 0.5);
    let k_tri = cache.exit(prim);
    let k_axes = cache.axes(prim, xo);
    assert_eq!(k_tri, exit_curvature(&cube, prim));
    assert!((k_tri * h * 3f32.sqrt() - 1.0).abs() < 1e-5);
    assert!((k_axes - 2.0).abs() < 1e-5, "{k_axes}");
    // the face's centre is h from every edge, beyond the reach: the
    // triangle's own
    let centre = Vec3::new(h, 0.0, 0.0);
    assert!(h > s.rmax() as f32);
    assert_eq!(cache.axes(prim, centre), k_tri);
    let accel = Brute {
        meshes: vec![cube.clone()],
    };
    let target = ProbeTarget {
        accel: &accel,
        geom: 0,
        mesh: &cube,
    };
    let frame = Frame::from_normal(Vec3::X);
    let across = |kappa: f32| {
        let mut rng = Rng::from_key(11);
        let mut hits = ProbeHits::new();
        let n = 40_000;
        let (mut s1, mut s2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let u = ProbeRandoms::from_rng(&mut rng);
            if let Some(ps) = sample_entry(&s, xo, &frame, kappa, &u, &target, &mut hits) {
                if ps.normal.z > 0.99 {
                    let w = ps.weight[0] as f64;
                    s1 += w;
                    s2 += w * w;
                }
            }
        }
        let mean = s1 / n as f64;
        let var = s2 / n as f64 - mean * mean;
        (mean, (var / n as f64).sqrt(), var / (mean * mean))
    };
    let (m_edge, se_edge, rel_edge) = across(k_axes);
    let (m_tri, se_tri, rel_tri) = across(k_tri);
    println!("edge rule: {m_edge:.4} ± {se_edge:.4}, relative variance {rel_edge:.1}");
    println!("triangle:  {m_tri:.4} ± {se_tri:.4}, relative variance {rel_tri:.1}");
    assert!(m_edge > 0.02, "the top face holds a share of the profile");
    assert!(
        (m_edge - m_tri).abs() < 5.0 * (se_edge.powi(2) + se_tri.powi(2)).sqrt(),
        "both unbiased"
    );
    assert!(rel_edge < 30.0, "{rel_edge}");
    assert!(rel_tri > 200.0, "{rel_tri}");
}

#[test]
fn the_bounded_edge_search_gives_the_axes_the_full_search_gives() {
    // Flat-shaded bodies with sharp edges everywhere (an icosahedron and
    // a box, κ(triangle) their 1/R floor), queried anywhere within reach
    // of them. `axes` looks no farther than 1/κ(triangle): it must equal
    // max(κ, 1/s) over the brute-force nearest edge s (a cut nearer than
    // 1/κ misses edges that raise κ). `axes_up_to` stops at the first
    // edge within the saturation distance: the axis probabilities must be
    // the same bit for bit (a stop beyond it picks a farther edge's
    // smaller κ).
    let opts = ProbeOptions::default();
    assert_eq!(opts.axes, ProbeAxes::Curvature);
    let s = ProbeSampler::new(&params_for(&opts, 1.0), &opts).unwrap();
    let (rmax, saturated) = (s.rmax() as f32, s.saturated_curvature());
    let flat = |m: Mesh| Mesh::new(m.positions()[..m.vertex_count()].to_vec(), m.indices, None);
    let mut ico = flat(crate::scene::shapes::sphere(0));
    ico.transform(|p| p * 2.5, |n| n);
    let mut slab = flat(crate::scene::shapes::cuboid());
    slab.transform(|p| p * Vec3::new(3.0, 0.4, 1.5), |n| n);
    let mut rng = Rng::from_key(5);
    let (mut saturating, mut beyond) = (0, 0);
    for mesh in [ico, slab] {
        let edges = crate::geometry::sharp_edges::sharp_edges(&mesh);
        assert!(edges.len() >= 12);
        let cache = MeshCurvature::new(&mesh, rmax);
        let extent = mesh.bounds().unwrap().1.abs().max_element() + rmax;
        for i in 0..4000 {
            let mut v3 = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
            // every other point within 2d of an edge, where the search may stop
            let p = if i % 2 == 0 {
                let [a, b] = edges[i / 2 % edges.len()];
                let t = v3().x * 0.5 + 0.5;
                a + t * (b - a) + v3().normalize_or_zero() * (v3().y + 1.0)
            } else {
                v3() * extent
            };
            let prim = ((rng.uniform() * mesh.triangle_count() as f32) as u32)
                .min(mesh.triangle_count() as u32 - 1);
            let brute = edges
                .iter()
                .map(|&[a, b]| {
                    let ab = b - a;
                    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                    (p - (a + t * ab)).length()
                })
                .fold(rmax, f32::min);
            let k = cache.exit(prim);
            let want = if brute < rmax { k.max(1.0 / brute) } else { k };
            let full = cache.axes(prim, p);
            assert_eq!(full, want, "p {p} prim {prim}: s {brute}");
            let bounded = cache.axes_up_to(prim, p, saturated);
            assert_eq!(
                s.axis_probs(bounded),
                s.axis_probs(full),
                "p {p} prim {prim}"
            );
            saturating += (full >= saturated) as usize;
            beyond += (full == k && brute < rmax) as usize;
        }
    }
    // both cuts are exercised: points where the search may stop early, and
    // points whose nearest edge lies beyond 1/κ(triangle) but within reach
    assert!(saturating > 1000 && beyond > 100, "{saturating} {beyond}");
}

/// A closed thin wedge (triangular prism): faces z = ±x·tan(angle/2)
/// for 0 ≤ x ≤ `len` meeting at the edge x = z = 0, |y| ≤ `half_width`.
fn wedge(angle_deg: f32, len: f32, half_width: f32) -> Mesh {
    let h = len * (angle_deg.to_radians() / 2.0).tan();
    let w = half_width;
    let p = vec![
        Vec3::new(0.0, -w, 0.0), // 0, 1: the edge
        Vec3::new(0.0, w, 0.0),
        Vec3::new(len, -w, h), // 2, 3: top face's far side
        Vec3::new(len, w, h),
        Vec3::new(len, -w, -h), // 4, 5: bottom face's far side
        Vec3::new(len, w, -h),
    ];
    let idx = vec![
        [0, 2, 3],
        [0, 3, 1],
        [0, 1, 5],
        [0, 5, 4],
        [2, 4, 5],
        [2, 5, 3],
        [0, 4, 2],
        [1, 3, 5],
    ];
    Mesh::new(p, idx, None)
}

/// The frame around unit normal `n` whose tangent is rotated by `turns`
/// of a full turn from [`Frame::from_normal`]'s.
fn rotated_frame(n: Vec3, turns: f32) -> Frame {
    let f = Frame::from_normal(n);
    let (sin, cos) = crate::sampling::sin_cos_turns(turns);
    Frame {
        t: f.t * cos + f.b * sin,
        b: f.b * cos - f.t * sin,
        n,
    }
}

#[test]
fn every_entry_point_lies_within_rmax_of_xo_on_curved_geometry() {
    // The probe segment is the chord of the sphere of radius Rmax
    // around xo at disk radius r, of half-length h = √(Rmax² − r²), so
    // every entry point it finds satisfies |xi − xo| ≤ Rmax; the
    // density p(xi) the estimator divides by is that of points inside
    // the sphere, and a hit outside it (a longer chord) would be scored
    // with a density it was not sampled with: bias. Checked on closed
    // spheres smaller than, equal to and larger than Rmax and on a thin
    // (6°) wedge, for random exit points on them, shading frames tilted
    // and rotated at random, every axis choice, every radius sampler,
    // two Rmax quantiles and random numbers including the extremes
    // (r = Rmax, h = 0; r → 0). Up to f32 rounding of the ray
    // (~1e-7 of the coordinates).
    use crate::sampling::{uniform_sphere, uniform_triangle};
    let params = SubsurfaceParams {
        albedo: [0.8, 0.5, 0.3],
        d: [1.0, 0.5, 0.25],
        eta: 1.3,
        medium: None,
    };
    let top = 1.0 - f64::EPSILON / 2.0;
    let mut rng = Rng::from_key(1919);
    let mut hits = ProbeHits::new();
    let mut worst = 0.0f64;
    for axes in ProbeAxes::ALL {
        for radius in [
            RadiusSampler::Uniform,
            RadiusSampler::table(64),
            RadiusSampler::Analytic,
            RadiusSampler::Mixture,
        ] {
            for rmax_quantile in [0.999, 0.9] {
                let opts = ProbeOptions {
                    axes,
                    channel: ChannelStrategy::Mis,
                    radius,
                    rmax_quantile,
                    renormalize: false,
                    profile: crate::bssrdf::ProfileShape::Burley,
                };
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let rm = s.rmax() as f32;
                let c = Vec3::new(0.3, -0.2, 0.1) * rm;
                let shapes = [
                    ("sphere 0.35 Rmax", uv_sphere(c, 0.35 * rm, 8)),
                    ("sphere Rmax", uv_sphere(c, rm, 12)),
                    ("sphere 3 Rmax", uv_sphere(c, 3.0 * rm, 12)),
                    ("wedge 6°", wedge(6.0, 3.0 * rm, 3.0 * rm)),
                ];
                for (name, mesh) in shapes {
                    let accel = Brute { meshes: vec![mesh] };
                    let mesh = &accel.meshes[0];
                    let n_tri = mesh.triangle_count() as u32;
                    let mut found = 0;
                    for _ in 0..8 {
                        let prim = rng.next_u32() % n_tri;
                        let [b1, b2] = uniform_triangle(rng.uniform2());
                        let [a, b, c] = mesh.triangle(prim);
                        let xo = a * (1.0 - b1 - b2) + b * b1 + c * b2;
                        let ng = mesh.face_normal(prim);
                        // a shading normal up to ~70° off the geometric
                        // one, or anywhere
                        let tilt = uniform_sphere(rng.uniform2()) * 1.5 * rng.uniform();
                        let n = if rng.uniform() < 0.2 {
                            uniform_sphere(rng.uniform2())
                        } else {
                            (ng + tilt).normalize()
                        };
                        let frame = rotated_frame(n, rng.uniform());
                        let tol = 1e-5 * (s.rmax() + xo.length() as f64);
                        for k in 0..250 {
                            let mut u = ProbeRandoms::from_rng(&mut rng);
                            match k % 16 {
                                0 => u.radius = top,
                                1 => u.radius = 0.0,
                                _ => {}
                            }
                            let target = target(&accel);
                            let kappa = curvature(mesh, prim);
                            let Some(ps) =
                                sample_entry(&s, xo, &frame, kappa, &u, &target, &mut hits)
                            else {
                                continue;
                            };
                            found += 1;
                            let dist = (ps.point.as_dvec3() - xo.as_dvec3()).length();
                            worst = worst.max(dist / s.rmax());
                            assert!(
                                dist <= s.rmax() + tol,
                                "{name}, {opts:?}: entry point {} is {dist} from xo {xo}, \
                                 beyond Rmax = {} (frame {frame:?}, {u:?})",
                                ps.point,
                                s.rmax()
                            );
                        }
                    }
                    assert!(found > 100, "{name}, {opts:?}: only {found} entry points");
                }
            }
        }
    }
    println!("largest |xi − xo| / Rmax: {worst:.6}");
}

/// The octant of the sphere of radius `rs` around `c` where the
/// outward normal has no negative T, B or N component in `frame`: the
/// directions of an `m`-step barycentric grid on the octant's spherical
/// triangle, times `rs`. It is a graph over each of the frame's
/// coordinate planes, so a line along T, B or N crosses it at most once:
/// every probe segment from this frame has at most one hit (the test
/// asserts it). (A flat cap on it, pushed radially, folds at the crease:
/// some segments then hit three times.) Returns the mesh and a function
/// giving the index of grid vertex (i, j), i + j ≤ m.
fn octant_patch(rs: f64, m: u32, frame: &Frame, c: DVec3) -> (Mesh, impl Fn(u32, u32) -> u32) {
    let mut p = Vec::new();
    let mut id = vec![vec![u32::MAX; (m + 1) as usize]; (m + 1) as usize];
    let (t, b, n) = (frame.t.as_dvec3(), frame.b.as_dvec3(), frame.n.as_dvec3());
    for i in 0..=m {
        for j in 0..=m - i {
            let k = m - i - j;
            let w = DVec3::new(i as f64, j as f64, k as f64).normalize();
            let l = w * rs;
            id[i as usize][j as usize] = p.len() as u32;
            p.push((c + t * l.x + b * l.y + n * l.z).as_vec3());
        }
    }
    let mut idx = Vec::new();
    for i in 0..m as usize {
        for j in 0..(m as usize - i) {
            idx.push([id[i][j], id[i + 1][j], id[i][j + 1]]);
            if i + j + 1 < m as usize {
                idx.push([id[i + 1][j], id[i + 1][j + 1], id[i][j + 1]]);
            }
        }
    }
    (Mesh::new(p, idx, None), move |i: u32, j: u32| {
        id[i as usize][j as usize]
    })
}

/// Gauss–Legendre nodes and weights on [0, 1] (Newton on P_n).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    use std::f64::consts::PI;
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            ((1.0 - x) / 2.0, 1.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// ∫ f dA over triangle `tri`, f zero beyond `rmax` from `xo`: Gauss–
/// Legendre in the Duffy square, or in polar coordinates around a
/// vertex that is a point of `sing` where f has a 1/r singularity (xo
/// = `sing[0]`, a vertex of the triangles around it, and `sing[1..]`,
/// where a line xo + sV_a pierces the surface, which the caller makes
/// a vertex of the pieces of the pierced triangle). A triangle the
/// sphere of radius `rmax` cuts, or for which `split` says f jumps
/// inside, or near a point of `sing[1..]` (f nearly singular on it), is
/// split in four, `depth` times.
#[allow(clippy::too_many_arguments)]
fn integrate_triangle(
    f: &dyn Fn(DVec3) -> f64,
    split: &dyn Fn(&[DVec3; 3]) -> bool,
    xo: DVec3,
    sing: &[DVec3],
    rmax: f64,
    tri: [DVec3; 3],
    depth: u32,
    gl: &[(f64, f64)],
) -> f64 {
    let dist = tri.map(|p| (p - xo).length());
    let to_sing = tri.map(|p| {
        sing.iter()
            .map(|q| (p - *q).length())
            .fold(f64::INFINITY, f64::min)
    });
    let cen = (tri[0] + tri[1] + tri[2]) / 3.0;
    let rad = tri.iter().map(|p| (*p - cen).length()).fold(0.0, f64::max);
    if (cen - xo).length() - rad > rmax {
        return 0.0;
    }
    // near a singular point that is not one of its vertices, f is
    // nearly singular on the triangle: refine toward the point
    let size = (0..3)
        .map(|k| (tri[k] - tri[(k + 1) % 3]).length())
        .fold(0.0, f64::max);
    let near = sing.len() > 1
        && to_sing.iter().all(|&r| r > 1e-6 * rmax)
        && tri
            .iter()
            .any(|p| sing[1..].iter().any(|q| (*p - *q).length() < size));
    if depth > 0 && (near || dist.iter().any(|&r| r > rmax) || split(&tri)) {
        let m = [0, 1, 2].map(|k| (tri[k] + tri[(k + 1) % 3]) / 2.0);
        return [
            [tri[0], m[0], m[2]],
            [m[0], tri[1], m[1]],
            [m[2], m[1], tri[2]],
            [m[0], m[1], m[2]],
        ]
        .into_iter()
        .map(|t| integrate_triangle(f, split, xo, sing, rmax, t, depth - 1, gl))
        .sum();
    }
    let k = (0..3)
        .min_by(|&x, &y| to_sing[x].total_cmp(&to_sing[y]))
        .unwrap();
    let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
    if to_sing[k] < 1e-6 * rmax {
        // a singular point at vertex a: polar coordinates around it,
        // the angle θ from b − a toward c − a, the distance r up to the
        // edge bc on geometrically graded pieces (f ~ e^(−r/d)/r, so
        // f·r is bounded; unlike Duffy's, the angular integrand stays
        // smooth when a is close to the edge bc)
        let e1 = (b - a).normalize();
        let e2 = ((c - a) - e1 * (c - a).dot(e1)).normalize();
        let theta = (c - a).dot(e2).atan2((c - a).dot(e1));
        let edge = (c - b).normalize();
        let mut n_edge = (b - a) - edge * (b - a).dot(edge);
        let h = n_edge.length();
        n_edge /= h;
        let graded = [
            (0.0, 1.0 / 27.0),
            (1.0 / 27.0, 1.0 / 9.0),
            (1.0 / 9.0, 1.0 / 3.0),
            (1.0 / 3.0, 1.0),
        ];
        let mut sum = 0.0;
        for &(t, wt) in gl {
            let th = t * theta;
            let u = e1 * th.cos() + e2 * th.sin();
            let rho = h / u.dot(n_edge);
            for (s0, s1) in graded {
                for &(s, ws) in gl {
                    let r = rho * (s0 + (s1 - s0) * s);
                    sum += wt * theta * ws * (s1 - s0) * rho * r * f(a + u * r);
                }
            }
        }
        return sum;
    }
    let area2 = (b - a).cross(c - a).length();
    let mut sum = 0.0;
    for &(s, ws) in gl {
        for &(t, wt) in gl {
            sum += ws * wt * s * f(a + ((b - a) + (c - b) * t) * s);
        }
    }
    sum * area2
}

/// Q(a, x) = Γ(a, x)/Γ(a), the regularized upper incomplete gamma
/// function (series for x < a + 1, Lentz's continued fraction beyond;
/// Numerical Recipes §6.2), with ln Γ from Lanczos (g = 7, n = 9).
fn gamma_q(a: f64, x: f64) -> f64 {
    fn ln_gamma(x: f64) -> f64 {
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.520_368_121_885_1,
            -1_259.139_216_722_402_8,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507_343_278_686_905,
            -0.138_571_095_265_720_12,
            9.984_369_578_019_572e-6,
            1.505_632_735_149_311_6e-7,
        ];
        let x = x - 1.0;
        let s = C[0] + (1..9).map(|i| C[i] / (x + i as f64)).sum::<f64>();
        let t = x + 7.5;
        0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + s.ln()
    }
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut ap, mut del) = (a, 1.0 / a);
        let mut sum = del;
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * front).max(0.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        front * h
    }
}

/// Pearson's χ² of observed against expected counts, consecutive bins
/// merged until each expects ≥ 5 (a remainder joins the last): χ², the
/// degrees of freedom (merged bins − 1) and the p-value Q(dof/2, χ²/2).
fn pearson(obs: &[f64], exp: &[f64]) -> (f64, usize, f64) {
    let (mut o, mut e) = (Vec::new(), Vec::new());
    let (mut ao, mut ae) = (0.0, 0.0);
    for (&x, &y) in obs.iter().zip(exp) {
        ao += x;
        ae += y;
        if ae >= 5.0 {
            o.push(ao);
            e.push(ae);
            (ao, ae) = (0.0, 0.0);
        }
    }
    if ao > 0.0 || ae > 0.0 {
        match (o.last_mut(), e.last_mut()) {
            (Some(lo), Some(le)) => {
                *lo += ao;
                *le += ae;
            }
            _ => {
                o.push(ao);
                e.push(ae);
            }
        }
    }
    let chi2: f64 = o.iter().zip(&e).map(|(o, e)| (o - e) * (o - e) / e).sum();
    let dof = o.len().saturating_sub(1).max(1);
    (chi2, dof, gamma_q(dof as f64 / 2.0, chi2 / 2.0))
}

#[test]
fn incomplete_gamma_matches_known_values() {
    // Q(1, x) = e^−x; Q(½, x) = erfc(√x); the χ² table: 18.307 is the
    // 5% point for 10 degrees of freedom, 3.841 for 1, 124.342 for 100.
    for x in [0.1, 1.0, 2.5, 7.0, 30.0] {
        assert!((gamma_q(1.0, x) - (-x).exp()).abs() < 1e-13);
    }
    assert!((gamma_q(0.5, 1.0) - 0.157_299_207_050_285_1).abs() < 1e-12);
    for (dof, x) in [(10.0, 18.307), (1.0, 3.841), (100.0, 124.342)] {
        let p = gamma_q(dof / 2.0, x / 2.0);
        assert!((p - 0.05).abs() < 1e-4, "dof {dof}: {p}");
    }
}

#[test]
fn sampled_entry_points_follow_the_density_the_estimator_divides_by() {
    // Pearson χ² of where probes land against p(xi), the surface-area
    // density the weight Rd/p divides by (summed over axes with their
    // probabilities and averaged over channels), on an octant of a
    // sphere (`octant_patch`) of radius 1.6 Rmax or Rmax, so the sphere
    // of radius Rmax around xo cuts it and the surface drops up to
    // 0.3–0.5 Rmax below its tangent plane within it. Every probe segment there has
    // at most one hit (asserted), so the hit is picked with probability 1
    // and the density of xi is p(xi) itself. Bins: the patch's
    // triangles grouped by the distance of their centroid from xo (in
    // Rmax/8 bands) and its direction around N (4 sectors), plus "no
    // entry point"; expected counts integrate p over each triangle by
    // quadrature (`integrate_triangle`), so the test also checks that p
    // integrates to the probability of a hit. Each sample's weight must
    // be Rd(|xi − xo|)/p(xi) (× its hit count, 1). For both axis
    // choices, every radius sampler, two exit points and frames.
    let params = SubsurfaceParams {
        albedo: [0.8, 0.5, 0.3],
        d: [1.0, 0.5, 0.25],
        eta: 1.3,
        medium: None,
    };
    let gl = gauss_legendre(8);
    let n_samples = 25_000;
    let (bands, sectors) = (8usize, 4usize);
    let mut rng = Rng::from_key(2024);
    let mut hits = ProbeHits::new();
    let mut p_min = 1.0f64;
    for (case, (rs, (i0, j0))) in [(1.6, (5, 4)), (1.0, (3, 9))].into_iter().enumerate() {
        for axes in ProbeAxes::ALL {
            for radius in [
                RadiusSampler::Uniform,
                RadiusSampler::table(64),
                RadiusSampler::Analytic,
                RadiusSampler::Mixture,
            ] {
                let opts = ProbeOptions {
                    axes,
                    channel: ChannelStrategy::Mis,
                    radius,
                    rmax_quantile: 0.99,
                    renormalize: false,
                    profile: crate::bssrdf::ProfileShape::Burley,
                };
                let s = ProbeSampler::new(&params, &opts).unwrap();
                let rm = s.rmax();
                let frame = rotated_frame(
                    crate::sampling::uniform_sphere(rng.uniform2()),
                    rng.uniform(),
                );
                let c = DVec3::new(0.3, -0.2, 0.1) * rm;
                let (mesh, vertex) = octant_patch(rs * rm, 16, &frame, c);
                let xo = mesh.positions()[vertex(i0, j0) as usize];
                let xo64 = xo.as_dvec3();
                // the patch's own curvature (ε near ε_min), and one
                // with κ·d = ½ (ε halfway to ¼)
                let kappa = [1.0 / (rs * rm), 0.5 / params.d[0]][case] as f32;
                let accel = Brute { meshes: vec![mesh] };
                let mesh = &accel.meshes[0];
                let n_tri = mesh.triangle_count();
                // bin 0: no entry point; then band-major, sector-minor
                let bin_of = |prim: u32| {
                    let [a, b, c] = mesh.triangle(prim);
                    let cen = ((a + b + c) / 3.0).as_dvec3() - xo64;
                    let band = ((cen.length() / rm * bands as f64) as usize).min(bands);
                    let (x, y) = (cen.dot(frame.t.as_dvec3()), cen.dot(frame.b.as_dvec3()));
                    let turn = (y.atan2(x) / std::f64::consts::TAU).rem_euclid(1.0);
                    let sector = ((turn * sectors as f64) as usize).min(sectors - 1);
                    1 + band * sectors + sector
                };
                let n_bins = 1 + (bands + 1) * sectors;
                let mut expected = vec![0.0; n_bins];
                let mut observed = vec![0.0; n_bins];
                for prim in 0..n_tri as u32 {
                    let n_hit = mesh.face_normal(prim).as_dvec3();
                    let pdf = |x: DVec3| s.pdf_area(x - xo64, &frame, kappa, n_hit);
                    let tri = mesh.triangle(prim).map(|p| p.as_dvec3());
                    expected[bin_of(prim)] +=
                        integrate_triangle(&pdf, &|_| false, xo64, &[xo64], rm, tri, 6, &gl);
                }
                let p_hit: f64 = expected.iter().sum();
                let what = format!("case {case}, {opts:?}");
                assert!(p_hit > 0.05 && p_hit < 1.0 + 1e-9, "{what}: P(hit) {p_hit}");
                expected[0] = 1.0 - p_hit;
                for e in &mut expected {
                    *e *= n_samples as f64;
                }
                for _ in 0..n_samples {
                    let u = ProbeRandoms::from_rng(&mut rng);
                    let target = target(&accel);
                    let Some(ps) = sample_entry(&s, xo, &frame, kappa, &u, &target, &mut hits)
                    else {
                        observed[0] += 1.0;
                        continue;
                    };
                    assert_eq!(hits.total(), 1, "{what}: a segment with several hits");
                    observed[bin_of(ps.hit.prim)] += 1.0;
                    let d = ps.point.as_dvec3() - xo64;
                    // the f32 point's rounding is relative to |xo|;
                    // p_a ∝ 1/r_a near a line xo + sV_a, which on a
                    // nearly flat surface passes close to many hits
                    let axes_v = [frame.t, frame.b, frame.n].map(|v| v.as_dvec3());
                    let r_min = axes_v
                        .map(|v| (d.length_squared() - d.dot(v).powi(2)).max(0.0).sqrt())
                        .into_iter()
                        .fold(f64::INFINITY, f64::min);
                    if r_min > 1e-3 * rm {
                        // A table's density is piecewise constant in r:
                        // within the point's rounding of a cell edge
                        // the weight may come from the other cell, so
                        // Rd/p is also taken a rounding step in and out
                        // (3e-4 r ≥ 3e-6 here, against ~2e-6).
                        let n_hit = ps.normal.as_dvec3();
                        let p = s.pdf_area(d, &frame, kappa, n_hit);
                        assert!(p > 0.0, "{what}: an entry point where p = 0, at {d}");
                        // (a step out of the sphere has p = 0: NaN, no match)
                        let want = |d: DVec3| {
                            let p = s.pdf_area(d, &frame, kappa, n_hit);
                            s.rd(d.length())
                                .map(|rd| if p > 0.0 { rd / p } else { f64::NAN })
                        };
                        let wants = [1.0, 1.0 - 3e-4, 1.0 + 3e-4].map(|k| want(d * k));
                        for c in 0..3 {
                            let got = ps.weight[c] as f64;
                            assert!(
                                wants.iter().any(|w| (got - w[c]).abs() <= 2e-3 * w[c]),
                                "{what} ch{c}: weight {got}, Rd/p = {} at {d}",
                                wants[0][c]
                            );
                        }
                    }
                }
                let (chi2, dof, p) = pearson(&observed, &expected);
                p_min = p_min.min(p);
                println!("{what}: P(hit) {p_hit:.3}, χ² {chi2:.1} / {dof}, p {p:.3}");
                assert!(
                    p > 1e-3,
                    "{what}: χ² = {chi2:.1} on {dof} degrees of freedom, p = {p:.2e}\n\
                     observed {observed:?}\nexpected {expected:?}"
                );
            }
        }
    }
    println!("smallest p-value: {p_min:.3}");
}

#[test]
fn a_chosen_entry_point_has_density_p_times_its_share_of_the_segments_weight() {
    // Two concentric octant patches (`octant_patch`, radii 1.6 Rmax and
    // 1.3 Rmax, xo on the outer one): a probe segment can cross both, and
    // the query then returns two hits of which one is kept in proportion
    // to its score s = Σ_c Rd_c/p (`pick_by_score`). The density of the
    // chosen xi is Σ_a p_a(xi) · s(xi) / Σ_j s(x_j), p_a the density of
    // reaching xi along axis a (`pdf_area_axes_mean`) and the x_j the
    // hits on the segment through xi along a (xi and, found here by
    // intersecting that segment with the other patch, the other one);
    // the weight must be Rd/p × Σ_j s(x_j) / s(xi), p = Σ_a p_a (× k
    // for a segment's only hit, k = 1). A uniform pick (density
    // p_a/k_a) fails the χ² here. Pearson χ² as in
    // `sampled_entry_points_follow_the_density_the_estimator_divides_by`,
    // the bins separating the two patches; triangles across which some
    // k_a changes are subdivided so the quadrature resolves the jump,
    // and where the line xo + sV_a pierces the inner patch (p_a ~ 1/r_a
    // there, as at xo) the quadrature is polar around that point.
    // Normal and Mis3 axes; more than half the segments hit twice.
    let params = SubsurfaceParams {
        albedo: [0.8, 0.5, 0.3],
        d: [1.0, 0.5, 0.25],
        eta: 1.3,
        medium: None,
    };
    let gl = gauss_legendre(8);
    let n_samples = 25_000;
    let (bands, sectors) = (8usize, 4usize);
    let mut rng = Rng::from_key(2025);
    let mut hits = ProbeHits::new();
    let mut p_min = 1.0f64;
    let mut two = 0usize;
    for (axes, radius) in [
        (ProbeAxes::Normal, RadiusSampler::Uniform),
        (ProbeAxes::Normal, RadiusSampler::Analytic),
        (ProbeAxes::Mis3, RadiusSampler::Mixture),
        (ProbeAxes::Curvature, RadiusSampler::Analytic),
    ] {
        let opts = ProbeOptions {
            axes,
            channel: ChannelStrategy::Mis,
            radius,
            rmax_quantile: 0.99,
            renormalize: false,
            profile: crate::bssrdf::ProfileShape::Burley,
        };
        let s = ProbeSampler::new(&params, &opts).unwrap();
        let rm = s.rmax();
        let frame = rotated_frame(
            crate::sampling::uniform_sphere(rng.uniform2()),
            rng.uniform(),
        );
        let c = DVec3::new(0.3, -0.2, 0.1) * rm;
        let (outer, vertex) = octant_patch(1.6 * rm, 12, &frame, c);
        // κ·d = ¼ for `Curvature` (the patch's own 1/(1.6 Rmax) gives
        // ε ≈ ε_min; this tests an ε in between)
        let kappa = (0.25 / params.d[0]) as f32;
        let xo = outer.positions()[vertex(4, 3) as usize];
        let xo64 = xo.as_dvec3();
        let (inner, _) = octant_patch(1.3 * rm, 12, &frame, c);
        // one mesh, triangles of the outer patch first
        let n_outer = outer.triangle_count() as u32;
        let tris: Vec<[Vec3; 3]> = (0..n_outer)
            .map(|p| outer.triangle(p))
            .chain((0..inner.triangle_count() as u32).map(|p| inner.triangle(p)))
            .collect();
        let mesh = Mesh::new(
            tris.iter().flatten().copied().collect(),
            (0..tris.len() as u32)
                .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
                .collect(),
            None,
        );
        let accel = Brute { meshes: vec![mesh] };
        let mesh = &accel.meshes[0];
        let n_tri = mesh.triangle_count() as u32;
        let axes_v = [frame.t, frame.b, frame.n].map(|v| v.as_dvec3());
        // k_a(x) for x on triangle `prim`: 1 + the hits of the
        // other patch on the segment along axis a through x
        // the triangles of each patch that reach into the sphere of
        // radius Rmax around xo (the others are beyond every chord)
        let near = |r: std::ops::Range<u32>| -> Vec<u32> {
            r.filter(|&q| {
                let t = mesh.triangle(q).map(|p| p.as_dvec3());
                let cen = (t[0] + t[1] + t[2]) / 3.0;
                let rad = t.iter().map(|p| (*p - cen).length()).fold(0.0, f64::max);
                (cen - xo64).length() - rad <= rm
            })
            .collect()
        };
        let (near_outer, near_inner) = (near(0..n_outer), near(n_outer..n_tri));
        // the hits of the other patch on the segment along axis a
        // through x on triangle `prim`, as (point, normal)
        let others = |x: DVec3, prim: u32, a: usize| -> Vec<(DVec3, DVec3)> {
            let v = axes_v[a];
            let d = x - xo64;
            let along = d.dot(v);
            let h = (rm * rm - (d.length_squared() - along * along))
                .max(0.0)
                .sqrt();
            let ray = Ray::new((x + v * (h - along)).as_vec3(), (-v).as_vec3());
            let others = if prim < n_outer {
                &near_inner
            } else {
                &near_outer
            };
            others
                .iter()
                .filter_map(|&q| {
                    let (t, _, _) = tri_hit(&ray, mesh.triangle(q), 0.0, (2.0 * h) as f32)?;
                    let at = ray.o.as_dvec3() + ray.d.as_dvec3() * t as f64;
                    Some((at, mesh.face_normal(q).as_dvec3()))
                })
                .collect()
        };
        // k_a(x): the hits on that segment
        let count = |x: DVec3, prim: u32, a: usize| 1 + others(x, prim, a).len();
        // s(x): Rd/p summed over channels, as `pick_by_score` reads it
        let score = |x: DVec3, n: DVec3| -> f64 {
            let p = s.pdf_area(x - xo64, &frame, kappa, n);
            s.rd((x - xo64).length()).iter().sum::<f64>() / p
        };
        let bin_of = |prim: u32| {
            let [a, b, c] = mesh.triangle(prim);
            let cen = ((a + b + c) / 3.0).as_dvec3() - xo64;
            let band = ((cen.length() / rm * bands as f64) as usize).min(bands);
            let (x, y) = (cen.dot(axes_v[0]), cen.dot(axes_v[1]));
            let turn = (y.atan2(x) / std::f64::consts::TAU).rem_euclid(1.0);
            let sector = ((turn * sectors as f64) as usize).min(sectors - 1);
            let patch = (prim >= n_outer) as usize;
            1 + (patch * (bands + 1) + band) * sectors + sector
        };
        let n_bins = 1 + 2 * (bands + 1) * sectors;
        let mut expected = vec![0.0; n_bins];
        let mut observed = vec![0.0; n_bins];
        // where the lines xo + sV_a pierce the mesh, p_a has a 1/r_a
        // singularity: the quadrature needs to know
        let mut sing = vec![xo64];
        let mut pierced = vec![None; n_tri as usize];
        for prim in 0..n_tri {
            let tri = mesh.triangle(prim);
            for v in axes_v {
                let ray = Ray::new((xo64 - v * 4.0 * rm).as_vec3(), v.as_vec3());
                if let Some((_, u, w)) = tri_hit(&ray, tri, 0.0, (8.0 * rm) as f32) {
                    let [a, b, c] = tri.map(|p| p.as_dvec3());
                    let (u, w) = (u as f64, w as f64);
                    let q = a * (1.0 - u - w) + b * u + c * w;
                    if (q - xo64).length() > 1e-6 * rm {
                        sing.push(q);
                        pierced[prim as usize] = Some(q);
                    }
                }
            }
        }
        for prim in 0..n_tri {
            let n_hit = mesh.face_normal(prim).as_dvec3();
            let pdf = |x: DVec3| {
                let pa = s.pdf_area_axes_mean(x - xo64, &frame, kappa, n_hit);
                (0..3)
                    .filter(|&a| pa[a] > 0.0)
                    .map(|a| {
                        let own = score(x, n_hit);
                        let rest: f64 = others(x, prim, a).iter().map(|&(y, m)| score(y, m)).sum();
                        pa[a] * own / (own + rest)
                    })
                    .sum::<f64>()
            };
            // k_a changes inside where it differs at the corners
            let split = |t: &[DVec3; 3]| {
                (0..3).any(|a| {
                    let k = t.map(|x| count(x, prim, a));
                    k[0] != k[1] || k[1] != k[2]
                })
            };
            // a pierce point becomes the common vertex of three pieces
            let [a, b, c] = mesh.triangle(prim).map(|p| p.as_dvec3());
            let pieces = match pierced[prim as usize] {
                Some(q) => vec![[q, b, c], [q, c, a], [q, a, b]],
                None => vec![[a, b, c]],
            };
            expected[bin_of(prim)] += pieces
                .into_iter()
                .map(|t| integrate_triangle(&pdf, &split, xo64, &sing, rm, t, 3, &gl))
                .sum::<f64>();
        }
        let p_hit: f64 = expected.iter().sum();
        let what = format!("{opts:?}");
        assert!(p_hit > 0.05 && p_hit < 1.0 + 1e-9, "{what}: P(hit) {p_hit}");
        expected[0] = 1.0 - p_hit;
        for e in &mut expected {
            *e *= n_samples as f64;
        }
        for _ in 0..n_samples {
            let u = ProbeRandoms::from_rng(&mut rng);
            let target = target(&accel);
            let Some(ps) = sample_entry(&s, xo, &frame, kappa, &u, &target, &mut hits) else {
                observed[0] += 1.0;
                continue;
            };
            let k = hits.total();
            assert!(k <= 2, "{what}: {k} hits on two single-hit patches");
            two += (k == 2) as usize;
            observed[bin_of(ps.hit.prim)] += 1.0;
            let d = ps.point.as_dvec3() - xo64;
            // the f32 point's rounding is relative to |xo|; p_a
            // ∝ 1/r_a near a line xo + sV_a
            let r_min = axes_v
                .map(|v| (d.length_squared() - d.dot(v).powi(2)).max(0.0).sqrt())
                .into_iter()
                .fold(f64::INFINITY, f64::min);
            if r_min > 1e-3 * rm {
                let p = s.pdf_area(d, &frame, kappa, ps.normal.as_dvec3());
                assert!(p > 0.0, "{what}: an entry point where p = 0, at {d}");
                let rd = s.rd(d.length());
                // Σ_j s(x_j) / s(xi) over the segment's hits (k for one)
                let scale = if k == 1 {
                    1.0
                } else {
                    let at = |h: &Hit| {
                        let [a, b, c] = mesh.triangle(h.prim).map(|p| p.as_dvec3());
                        let (u, v) = (h.u as f64, h.v as f64);
                        a * (1.0 - u - v) + b * u + c * v
                    };
                    let total: f64 = hits
                        .hits()
                        .iter()
                        .map(|h| score(at(h), mesh.face_normal(h.prim).as_dvec3()))
                        .sum();
                    total / score(ps.point.as_dvec3(), ps.normal.as_dvec3())
                };
                for c in 0..3 {
                    let want = rd[c] / p * scale;
                    let got = ps.weight[c] as f64;
                    assert!(
                        (got - want).abs() <= 2e-3 * want,
                        "{what} ch{c}: weight {got}, Rd/p × {scale} = {want} at {d}"
                    );
                }
            }
        }
        let (chi2, dof, p) = pearson(&observed, &expected);
        p_min = p_min.min(p);
        println!("{what}: P(hit) {p_hit:.3}, χ² {chi2:.1} / {dof}, p {p:.3}");
        assert!(
            p > 1e-3,
            "{what}: χ² = {chi2:.1} on {dof} degrees of freedom, p = {p:.2e}\n\
                 observed {observed:?}\nexpected {expected:?}"
        );
    }
    // the case this test is for happens often
    assert!(two > n_samples / 2, "{two} two-hit segments");
    println!("smallest p-value: {p_min:.3}, {two} two-hit segments");
}
