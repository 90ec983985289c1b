//! Unit tests of the probe sampler, its weights against the f64 oracle,
//! and the pick among several hits.

// Tests index parallel per-channel arrays by channel number.
#![allow(clippy::needless_range_loop)]

use super::*;
use crate::bssrdf::radius::RadiusSampler;
use crate::sampling::Rng;

#[test]
fn weights_match_the_f64_oracle() {
    // ProbeDensity's f32 lanes against the f64 transcription on entry
    // points spread over the probe sphere, many nearly on an axis (disk
    // radius down to 1e-12 Rmax, below the RHO_MIN clamp), for every
    // radius sampler and materials whose channels span r/d up to 240
    // within Rmax, in scene units from 1e-6 to 1e6, and one (`far`) up
    // to 397, past exp4's range (module docs of `density`).
    use crate::sampling::uniform_sphere;
    let marble = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight);
    let skin = SubsurfaceParams::from_preset("skin1", 1.0, profile::Fit::Searchlight);
    let wide = SubsurfaceParams {
        albedo: [0.9, 0.0, 0.3],
        d: [1.0, 0.7, 0.0835],
        eta: 1.3,
        medium: None,
    };
    let mut far = wide;
    far.d[2] = 0.05;
    let mut materials = vec![marble.unwrap(), skin.unwrap(), wide, far];
    materials.push(materials[0].scaled(1e-6));
    materials.push(materials[1].scaled(1e6));
    // beyond this r/d, exp4's lane may be 0 (e^{−ρ/3} < e^{−87})
    let rho_lanes = 255.0;
    let mut rng = Rng::from_key(99);
    let mut kappa_rng = Rng::from_key(100);
    let mut curv_rng = Rng::from_key(101);
    let mut worst = 0.0f64;
    for params in &materials {
        for axes in ProbeAxes::ALL {
            for channel in [ChannelStrategy::Single, ChannelStrategy::Mis] {
                for radius in [
                    RadiusSampler::Uniform,
                    RadiusSampler::table(64),
                    RadiusSampler::Analytic,
                    RadiusSampler::Mixture,
                ] {
                    for renormalize in [false, true] {
                        let opts = ProbeOptions {
                            axes,
                            channel,
                            radius,
                            rmax_quantile: 0.999,
                            renormalize,
                            profile: crate::bssrdf::ProfileShape::Burley,
                        };
                        let s = ProbeSampler::new(params, &opts).unwrap();
                        // the curvature rule draws its own cases, so the
                        // others see the points they always did
                        let rng = if axes == ProbeAxes::Curvature {
                            &mut curv_rng
                        } else {
                            &mut rng
                        };
                        for _ in 0..2_000 {
                            let frame = Frame::from_normal(uniform_sphere(rng.uniform2()));
                            let mut local = [0.0f64; 3];
                            let a = (rng.uniform() * 3.0) as usize % 3;
                            let rm = s.rmax();
                            let perp = rm * 10f64.powf(-12.0 * rng.uniform_f64());
                            let phi = std::f64::consts::TAU * rng.uniform_f64();
                            local[(a + 1) % 3] = perp * phi.cos();
                            local[(a + 2) % 3] = perp * phi.sin();
                            // along the axis, inside the sphere
                            local[a] = (rm * rm - perp * perp).max(0.0).sqrt()
                                * (2.0 * rng.uniform_f64() - 1.0);
                            let local = if rng.uniform() < 0.5 {
                                local
                            } else {
                                // anywhere in the sphere
                                let u = uniform_sphere(rng.uniform2()).as_dvec3();
                                (u * rng.uniform_f64().cbrt() * rm).to_array()
                            };
                            let (t, b, n) =
                                (frame.t.as_dvec3(), frame.b.as_dvec3(), frame.n.as_dvec3());
                            let d = t * local[0] + b * local[1] + n * local[2];
                            let n_hit = uniform_sphere(rng.uniform2()).as_dvec3().normalize();
                            let ch =
                                s.active[(rng.uniform() * s.n_active as f32) as usize % s.n_active];
                            // curvature from flat to ~100/Rmax: ε over
                            // its whole range under `Curvature`
                            // (its own stream: the cases above are the
                            // ones this test always drew)
                            let kappa = (100.0 * kappa_rng.uniform_f64().powi(2) / rm) as f32;
                            let probs = s.axis_probs(kappa);
                            let f = s.weights(d, &frame, n_hit, probs, ch);
                            let r = s.weights_f64(d, &frame, kappa, n_hit, ch);
                            // a single channel's density beyond ρ ≈ 240
                            // underflows f32 (probability of such a
                            // sample < 1e-34)
                            let single_out = channel == ChannelStrategy::Single
                                && d.length() / params.d[ch] > 240.0;
                            if let Some(f) = f {
                                assert!(
                                    f.iter().all(|w| w.is_finite() && *w >= 0.0),
                                    "{params:?} {opts:?} {f:?} {r:?} {d} {ch}"
                                );
                            }
                            let (Some(f), Some(r)) = (f, r) else {
                                assert!(
                                    f.is_some() == r.is_some() || (f.is_none() && single_out),
                                    "{opts:?} {d} {n_hit}"
                                );
                                continue;
                            };
                            for c in 0..3 {
                                if single_out || d.length() / params.d[c] > rho_lanes {
                                    continue;
                                }
                                // relative, but not among subnormal weights
                                let e = ((f[c] - r[c]) as f64).abs() / (r[c] as f64).max(1e-35);
                                // exp(−ρ/3) inherits the f32 rounding of its
                                // argument times ρ/3 (a few ulp, 6e-8 each),
                                // in Rd and in the density: the bound grows
                                // with r/d.
                                let rho = d.length() / params.d[c];
                                let tol = 1e-6 + 3.6e-7 * rho / 3.0;
                                assert!(
                                    e < tol,
                                    "{params:?} {opts:?} ch{c}: {} vs {} at {local:?}",
                                    f[c],
                                    r[c]
                                );
                                worst = worst.max(e / tol);
                            }
                        }
                    }
                }
            }
        }
    }
    println!("f32 weights: worst relative error {worst:.3} of the bound");
}

#[test]
fn hits_are_kept_in_proportion_to_their_score_and_scaled_back() {
    let u = |hit: f64| ProbeRandoms {
        axis: 0.0,
        channel: 0.0,
        radius: 0.5,
        angle: 0.0,
        hit,
        seed: 0,
    };
    // scores 1, 0, 3: the zero is never kept; P = ¼, ¾
    let scores = [1.0f32, 0.0, 3.0];
    let n = 10_000;
    let mut kept = [0usize; 3];
    let mut mean = 0.0f64;
    for i in 0..n {
        let (k, f) = pick_by_score(&u((i as f64 + 0.5) / n as f64), &scores, 3).unwrap();
        kept[k] += 1;
        // E[score × factor] = Σ scores × total/kept = 4 (all kept here)
        mean += (scores[k] * f) as f64 / n as f64;
        assert!(f > 0.0 && f.is_finite());
    }
    assert_eq!(kept, [2_500, 0, 7_500]);
    assert!((mean - 4.0).abs() < 1e-4, "{mean}");
    // the query kept 3 of 12 hits: × 12/3
    let (k, f) = pick_by_score(&u(0.1), &scores, 12).unwrap();
    assert_eq!((k, f), (0, 4.0 * 4.0));
    // u at the top of [0, 1) still picks a hit with a score
    assert_eq!(pick_by_score(&u(1.0 - 1e-12), &[2.0, 0.0], 2).unwrap().0, 0);
    // nothing to scatter from, or a broken score: no pick
    assert!(pick_by_score(&u(0.3), &[0.0, 0.0], 2).is_none());
    assert!(pick_by_score(&u(0.3), &[1.0, f32::NAN], 2).is_none());
    assert!(pick_by_score(&u(0.3), &[1.0, f32::INFINITY], 2).is_none());
}

#[test]
fn uniform_indices_cover_every_slot_and_stay_in_range_at_both_ends() {
    let below_one = 1.0 - f64::EPSILON / 2.0;
    for n in [1usize, 2, 3, 5, 7, 1 << 20, (1 << 20) + 3] {
        assert_eq!(uniform_index(0.0, n), 0);
        assert_eq!(uniform_index(below_one, n), n - 1, "n = {n}");
        assert_eq!(uniform_index(1.0, n), n - 1, "n = {n}");
        for k in 0..n.min(64) {
            // the middle of slot k maps to k
            assert_eq!(uniform_index((k as f64 + 0.5) / n as f64, n), k);
        }
    }
}

#[test]
fn tangent_probability_runs_from_eps_min_to_a_quarter() {
    // ε_min on a flat surface, ¼ (mis3) from κd = 1 on, continuous and
    // nondecreasing in between; what is not a curvature gives ¼.
    assert_eq!(tangent_probability(0.0), TANGENT_PROB_MIN);
    assert_eq!(tangent_probability(-1.0), TANGENT_PROB_MIN);
    assert_eq!(tangent_probability(TANGENT_PROB_FULL_AT), 0.25);
    assert_eq!(tangent_probability(f64::INFINITY), 0.25);
    assert_eq!(tangent_probability(f64::NAN), 0.25);
    let below = tangent_probability(TANGENT_PROB_FULL_AT * (1.0 - 1e-9));
    assert!((below - 0.25).abs() < 1e-8, "{below}");
    let mut last = 0.0;
    for i in 0..=1000 {
        let e = tangent_probability(i as f64 * 1e-3);
        assert!(
            (TANGENT_PROB_MIN..=0.25).contains(&e) && e >= last,
            "{i}: {e}"
        );
        last = e;
    }
    // the 10 mm marble sphere (κd ≈ 0.087): ε has risen by e^{−5.5} ≈
    // 0.4 % of its way from ε_min to ¼
    let share = (tangent_probability(0.087) - TANGENT_PROB_MIN) / (0.25 - TANGENT_PROB_MIN);
    assert!(share < 5e-3, "{share}");
    // the axis probabilities of a sampler sum to 1, N gets the rest
    let p = SubsurfaceParams {
        albedo: [0.5; 3],
        d: [2.0, 1.0, 0.5],
        eta: 1.3,
        medium: None,
    };
    let s = ProbeSampler::new(&p, &ProbeOptions::default()).unwrap();
    assert_eq!(s.options().axes, ProbeAxes::Curvature);
    for kappa in [0.0f32, 0.05, 0.2, 0.5, 10.0] {
        let pr = s.axis_probs(kappa);
        let e = tangent_probability(kappa as f64 * 2.0);
        assert_eq!(pr, [e, e, 1.0 - 2.0 * e], "κ {kappa}");
    }
    // the weight bound's factor: √3/ε_min, and mis3's 4√3
    let g = ProbeAxes::Curvature.weight_bound().unwrap();
    assert!((g - 3f64.sqrt() / TANGENT_PROB_MIN).abs() < 1e-12);
    assert!((ProbeAxes::Mis3.weight_bound().unwrap() - 4.0 * 3f64.sqrt()).abs() < 1e-12);
    assert_eq!(ProbeAxes::Normal.weight_bound(), None);
    for a in ProbeAxes::ALL {
        assert_eq!(ProbeAxes::parse(&a.name().to_uppercase()), Some(a));
    }
    assert_eq!(ProbeAxes::parse("tangent"), None);
}

#[test]
fn tangent_probability_follows_the_slow_lobe_at_a_quarter_turn() {
    // Between ε_min and ¼, ε rises as the profile's slow lobe e^{−r/3d}
    // at the arc length r = π/(2κ) where a sphere of curvature κ has
    // turned 90° from xo, normalized to 1 at κd = kd_full: computed
    // here from that geometry (d = 1, κ = kd), not from the formula.
    let slow_lobe_at_quarter_turn = |kd: f64| {
        let (d, kappa) = (1.0, kd);
        let r = std::f64::consts::FRAC_PI_2 / kappa;
        (-r / (3.0 * d)).exp()
    };
    let full = slow_lobe_at_quarter_turn(TANGENT_PROB_FULL_AT);
    for kd in [0.087, 0.2, 0.35, 0.5, 0.75, 0.9] {
        let e = tangent_probability(kd);
        let share = (e - TANGENT_PROB_MIN) / (0.25 - TANGENT_PROB_MIN);
        let want = slow_lobe_at_quarter_turn(kd) / full;
        assert!(
            (share - want).abs() <= 1e-12 + 1e-9 * want,
            "κd {kd}: share {share}, slow lobe {want}"
        );
    }
}

#[test]
fn options_validate() {
    let p = SubsurfaceParams {
        albedo: [0.5; 3],
        d: [1.0; 3],
        eta: 1.3,
        medium: None,
    };
    for q in [0.0, 1.0, f64::NAN] {
        let e = ProbeSampler::new(
            &p,
            &ProbeOptions {
                rmax_quantile: q,
                ..ProbeOptions::default()
            },
        )
        .unwrap_err();
        assert_eq!(e.param, crate::error::Param::RmaxQuantile, "{e}");
    }
    let s = ProbeSampler::new(&p, &ProbeOptions::default()).unwrap();
    assert!((s.rmax() - profile::quantile(0.999)).abs() < 1e-12);
}

/// The pair's two segments are, bit for bit, what `sample_probe` gives
/// at φ and at the twin's angle (φ + ½ turn): sharing the channel,
/// radius and axis between them changes nothing (`crate::kernels`).
#[test]
fn probe_pair_is_two_probes_at_opposite_angles_bit_for_bit() {
    let params = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight);
    let params = params.unwrap();
    let mut rng = Rng::from_key(7);
    let frame = Frame::from_normal(Vec3::new(0.3, -0.5, 0.8).normalize());
    let xo = Vec3::new(0.25, -1.5, 3.0);
    let mut n = 0;
    for axes in ProbeAxes::ALL {
        let opts = ProbeOptions {
            axes,
            ..ProbeOptions::default()
        };
        let s = ProbeSampler::new(&params, &opts).unwrap();
        for i in 0..2000 {
            let u = ProbeRandoms::from_rng(&mut rng);
            let kappa = (i % 7) as f32 * 0.4;
            let twin = ProbeRandoms {
                angle: (u.angle + 0.5).fract(),
                ..u
            };
            let [a, b] = s.sample_probe_pair(xo, &frame, kappa, &u).unwrap();
            for (got, want) in [
                (a, s.sample_probe(xo, &frame, kappa, &u)),
                (b, s.sample_probe(xo, &frame, kappa, &twin)),
            ] {
                let want = want.unwrap();
                assert_eq!(
                    (got.ray.o, got.ray.d, got.t_max, got.probs, got.channel),
                    (want.ray.o, want.ray.d, want.t_max, want.probs, want.channel),
                    "{axes:?}, probe {i}"
                );
                assert_eq!((got.xo, got.frame.n), (want.xo, want.frame.n));
                n += 1;
            }
            // the twin lies across xo: the two disk offsets are opposite
            let (oa, ob) = (a.ray.o - xo, b.ray.o - xo);
            let v = -a.ray.d;
            let (da, db) = (oa - v * oa.dot(v), ob - v * ob.dot(v));
            assert!(
                (da + db).length() <= 1e-5 * (1.0 + da.length()),
                "{da} {db}"
            );
        }
    }
    assert_eq!(n, 2 * 2000 * ProbeAxes::ALL.len());
}

#[test]
fn the_plane_model_is_the_probe_on_the_tangent_plane() {
    // For a probe along N the model's offset d is where the probe line
    // crosses the tangent plane through xo, its weight what `weigh`
    // gives a single hit there on a surface of normal N, and P(N) the
    // axis probability; the pair's model is its first probe's. Probes
    // along T or B have none. The segments are `sample_probe`'s and
    // `sample_probe_pair`'s, bit for bit.
    let params = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight);
    let s = ProbeSampler::new(&params.unwrap(), &ProbeOptions::default()).unwrap();
    let mut rng = Rng::from_key(17);
    let frame = Frame::from_normal(Vec3::new(0.3, -0.5, 0.8).normalize());
    let xo = Vec3::new(0.25, -1.5, 3.0);
    let (mut along_n, mut tangent) = (0, 0);
    for i in 0..4000 {
        let u = ProbeRandoms::from_rng(&mut rng);
        // κ·d from 0 to ~1.3: ε from ε_min to ¼
        let kappa = (i % 9) as f32 * 0.2;
        let (seg, plane) = s.sample_probe_and_plane(xo, &frame, kappa, &u).unwrap();
        let want = s.sample_probe(xo, &frame, kappa, &u).unwrap();
        assert_eq!(
            (seg.ray.o, seg.ray.d, seg.t_max),
            (want.ray.o, want.ray.d, want.t_max)
        );
        let ([a, b], pair_plane) = s
            .sample_probe_pair_and_plane(xo, &frame, kappa, &u)
            .unwrap();
        let [wa, wb] = s.sample_probe_pair(xo, &frame, kappa, &u).unwrap();
        assert_eq!((a.ray.o, b.ray.o, a.ray.d), (wa.ray.o, wb.ray.o, wa.ray.d));
        assert_eq!(plane, pair_plane);
        let on_n = seg.ray.d.dot(frame.n) < -0.999;
        let Some(pm) = plane else {
            assert!(!on_n, "probe {i} along N without a model");
            tangent += 1;
            continue;
        };
        assert!(on_n, "probe {i}: a model for a probe along T or B");
        along_n += 1;
        let (o, d, n) = (seg.ray.o, seg.ray.d, frame.n);
        let t = (xo - o).dot(n) / d.dot(n);
        let p = o + d * t;
        let r = s.rmax() as f32;
        assert!(
            (p - (xo + pm.offset)).length() < 1e-5 * r,
            "probe {i}: crosses at {p}, model at {}",
            xo + pm.offset
        );
        assert!(pm.offset.dot(n).abs() < 1e-5 * r && pm.offset.length() <= r * 1.0001);
        let w = s.weigh(&seg, t, n, 1).unwrap().weight;
        assert!(
            (w - pm.weight).abs().max_element() <= 1e-3 * w.max_element(),
            "probe {i}: weigh {w} against the model's {}",
            pm.weight
        );
        assert_eq!(pm.p_normal, s.axis_probs(kappa)[AXIS_N] as f32);
    }
    assert!(
        along_n > 2500 && tangent > 300,
        "{along_n} along N, {tangent} along T/B"
    );
}
