//! Costs of the BSSRDF estimator's pieces, each for every option: a radius
//! sample and a disk-density evaluation per radius sampler, and one whole
//! probe (segment, all-hits query, pick, weight) on a flat plane under the
//! BVH, for an aligned and a 60°-tilted shading frame (a 2-triangle mesh,
//! so mostly the estimator's own cost). Run with `cargo bench --bench bssrdf`.
//!
//! These were `#[ignore]`d tests that printed timings; the variance the probe
//! one also printed is measured by `lucent study` (docs/accuracy.md).

use std::hint::black_box;
use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use lucent::accel::{build, Backend, ProbeHits};
use lucent::bssrdf::{
    profile, ChannelStrategy, ProbeAxes, ProbeOptions, ProbeRandoms, ProbeSampler, RadialDist,
    RadiusSampler, SubsurfaceParams, TableSpacing,
};
use lucent::geometry::{Frame, Mesh, Vec3};
use lucent::integrator::probe::{sample_entry, ProbeTarget};
use lucent::sampling::Rng;

const N: usize = 4096;

fn samplers() -> Vec<(&'static str, RadiusSampler)> {
    vec![
        ("uniform", RadiusSampler::Uniform),
        ("table16", RadiusSampler::table(16)),
        ("table256", RadiusSampler::table(256)),
        (
            "table64_uniform_nodes",
            RadiusSampler::Table {
                size: 64,
                spacing: TableSpacing::Uniform,
            },
        ),
        ("analytic", RadiusSampler::Analytic),
        ("mixture", RadiusSampler::Mixture),
    ]
}

fn radius_samplers(c: &mut Criterion) {
    let mut rng = Rng::from_key(1);
    let us: Vec<f64> = (0..N).map(|_| rng.uniform_f64()).collect();
    let rs: Vec<f64> = (0..N).map(|i| i as f64 * 1e-3).collect();
    let mut g = c.benchmark_group("radius");
    g.throughput(Throughput::Elements(N as u64));
    for (name, s) in samplers() {
        let dist = RadialDist::new(s, 1.0, profile::quantile(0.999)).unwrap();
        g.bench_function(format!("{name}/sample_and_pdf"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for &u in &us {
                    let (r, p) = dist.sample(u);
                    acc += r + p;
                }
                black_box(acc)
            })
        });
        g.bench_function(format!("{name}/pdf"), |b| {
            b.iter(|| rs.iter().map(|&r| dist.pdf(black_box(r))).sum::<f64>())
        });
    }
    g.finish();
}

fn probes(c: &mut Criterion) {
    let params = SubsurfaceParams::from_preset("marble", 1.0, profile::Fit::Searchlight).unwrap();
    let l = 1000.0;
    let plane = Mesh::new(
        vec![
            Vec3::new(-l, -l, 0.0),
            Vec3::new(l, -l, 0.0),
            Vec3::new(l, l, 0.0),
            Vec3::new(-l, l, 0.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
        None,
    );
    let meshes = Arc::new(vec![plane]);
    let accel = build(&meshes, Backend::Bvh).unwrap();
    let target = ProbeTarget {
        accel: accel.as_ref(),
        geom: 0,
        mesh: &meshes[0],
    };
    let xo = Vec3::new(0.37, -0.21, 0.0);
    let mut rng = Rng::from_key(9);
    let us: Vec<ProbeRandoms> = (0..N).map(|_| ProbeRandoms::from_rng(&mut rng)).collect();
    let mut g = c.benchmark_group("probe");
    g.throughput(Throughput::Elements(N as u64));
    for deg in [0.0f32, 60.0] {
        let a = deg.to_radians();
        let frame =
            Frame::from_normal(Vec3::new(a.sin() * 0.6, a.sin() * 0.8, a.cos()).normalize());
        for axes in ProbeAxes::ALL {
            for channel in [ChannelStrategy::Single, ChannelStrategy::Mis] {
                for (name, radius) in samplers() {
                    let opts = ProbeOptions {
                        axes,
                        channel,
                        radius,
                        ..ProbeOptions::default()
                    };
                    let s = ProbeSampler::new(&params, &opts).unwrap();
                    let mut hits = ProbeHits::new();
                    let id = format!("tilt{deg}/{axes:?}/{channel:?}/{name}");
                    g.bench_function(id, |b| {
                        b.iter(|| {
                            let mut acc = Vec3::ZERO;
                            for u in &us {
                                if let Some(ps) =
                                    sample_entry(&s, xo, &frame, 0.0, u, &target, &mut hits)
                                {
                                    acc += ps.weight;
                                }
                            }
                            black_box(acc)
                        })
                    });
                }
            }
        }
    }
    g.finish();
}

criterion_group!(benches, radius_samplers, probes);
criterion_main!(benches);
