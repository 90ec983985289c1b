//! Ray-query backends on a 1.31M-triangle displaced sphere: build time and
//! incoherent nearest-hit, occlusion and all-hits (probe) throughput with 1
//! and 2 rayon threads.
//!
//! Every backend lucent was built with is measured through the same
//! `&dyn Accel` code ([`helpers::nearest_throughput`]), so the figures
//! compare backends, not harnesses. Run with `cargo bench --bench accel`.

use std::sync::Arc;
use std::time::Duration;

use criterion::{
    criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput,
};
use lucent::accel::{self, Accel, Backend};
use lucent::geometry::{Mesh, Ray, Vec3};
use lucent::scene::shapes;

mod helpers {
    use super::*;
    use rayon::prelude::*;

    /// Rays per criterion iteration.
    pub const BATCH: usize = 100_000;

    /// Incoherent rays: origins uniform on the sphere of radius 3, each
    /// aimed at a uniform random point of the unit ball (so nearly all of
    /// them hit the displaced unit sphere, at random places). The generator
    /// is shared with `lucent bench` (`lucent_tools::bench::rays`).
    pub fn incoherent_rays(n: usize, seed: u64) -> Vec<Ray> {
        lucent_tools::bench::rays::incoherent_rays(n, seed, Vec3::ZERO, 1.0)
    }

    pub fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("rayon pool")
    }

    /// Traces every ray for its nearest hit on `pool`; returns the number
    /// of hits (so the work cannot be optimized away).
    pub fn trace_nearest(accel: &dyn Accel, rays: &[Ray], pool: &rayon::ThreadPool) -> usize {
        pool.install(|| {
            rays.par_chunks(1024)
                .map(|c| {
                    c.iter()
                        .filter(|r| accel.intersect(r, 0.0, f32::INFINITY).is_some())
                        .count()
                })
                .sum()
        })
    }

    /// Adds one benchmark per thread count to `c`: nearest-hit throughput of
    /// `accel` on `rays`, reported in rays/s.
    pub fn nearest_throughput(c: &mut Criterion, accel: &dyn Accel, rays: &[Ray]) {
        let mut g = c.benchmark_group("nearest_incoherent_1.3M");
        g.sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(4))
            .throughput(Throughput::Elements(rays.len() as u64));
        for threads in [1, 2] {
            let p = pool(threads);
            let hits = trace_nearest(accel, rays, &p);
            assert!(hits > rays.len() * 9 / 10, "only {hits} hits");
            g.bench_with_input(
                BenchmarkId::new(accel.name(), format!("{threads}t")),
                &threads,
                |b, _| b.iter(|| trace_nearest(accel, rays, &p)),
            );
        }
        g.finish();
    }

    /// Build time of `backend` over `meshes`: with 1 and 2 rayon threads
    /// for our BVH; once for Embree, which builds on its own TBB threads
    /// whatever the rayon pool. Flat sampling runs each build exactly once
    /// per sample, which keeps the 1.3M-triangle builds to about ten each.
    pub fn build_time(c: &mut Criterion, meshes: &Arc<Vec<Mesh>>, backend: Backend) {
        let mut g = c.benchmark_group("build_1.3M");
        g.sample_size(10)
            .sampling_mode(SamplingMode::Flat)
            .warm_up_time(Duration::from_millis(100))
            .measurement_time(Duration::from_secs(5));
        let threads: &[usize] = match backend {
            Backend::Bvh => &[1, 2],
            Backend::Embree | Backend::Embree3 | Backend::Embree4 => &[2],
        };
        for &t in threads {
            let p = pool(t);
            let id = match backend {
                Backend::Bvh => format!("{t}t"),
                _ => "own-threads".to_string(),
            };
            g.bench_with_input(BenchmarkId::new(backend.name(), id), &t, |b, _| {
                b.iter(|| p.install(|| accel::build(meshes, backend).unwrap()))
            });
        }
        g.finish();
    }
}

/// Shadow-ray and all-hits (probe) throughput, measured like
/// [`helpers::nearest_throughput`] on the same rays and pools.
mod more_queries {
    use super::*;
    use lucent::accel::ProbeHits;
    use rayon::prelude::*;

    fn group<'a>(
        c: &'a mut Criterion,
        name: &str,
        n: usize,
    ) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
        let mut g = c.benchmark_group(name);
        g.sample_size(10)
            .warm_up_time(Duration::from_secs(1))
            .measurement_time(Duration::from_secs(4))
            .throughput(Throughput::Elements(n as u64));
        g
    }

    /// Occlusion over the whole ray (t in [0, inf)).
    pub fn trace_occluded(accel: &dyn Accel, rays: &[Ray], pool: &rayon::ThreadPool) -> usize {
        pool.install(|| {
            rays.par_chunks(1024)
                .map(|c| {
                    c.iter()
                        .filter(|r| accel.occluded(r, 0.0, f32::INFINITY))
                        .count()
                })
                .sum()
        })
    }

    /// Every hit on mesh 0 along the segment t in [0, 6] (through the whole
    /// sphere: ≥ 2 hits per hitting ray); returns the total hit count.
    pub fn trace_probe(accel: &dyn Accel, rays: &[Ray], pool: &rayon::ThreadPool) -> usize {
        pool.install(|| {
            rays.par_chunks(1024)
                .enumerate()
                .map(|(k, c)| {
                    let mut out = ProbeHits::new();
                    c.iter()
                        .enumerate()
                        .map(|(i, r)| {
                            accel.hits_on_segment(r, 6.0, 0, (k * 1024 + i) as u32, &mut out);
                            out.total()
                        })
                        .sum::<usize>()
                })
                .sum()
        })
    }

    pub fn occluded_throughput(c: &mut Criterion, accel: &dyn Accel, rays: &[Ray]) {
        let mut g = group(c, "occluded_incoherent_1.3M", rays.len());
        for threads in [1, 2] {
            let p = helpers::pool(threads);
            let n = trace_occluded(accel, rays, &p);
            assert!(n > rays.len() * 9 / 10, "only {n} occluded");
            g.bench_with_input(
                BenchmarkId::new(accel.name(), format!("{threads}t")),
                &threads,
                |b, _| b.iter(|| trace_occluded(accel, rays, &p)),
            );
        }
        g.finish();
    }

    pub fn probe_throughput(c: &mut Criterion, accel: &dyn Accel, rays: &[Ray]) {
        let mut g = group(c, "all_hits_segment_1.3M", rays.len());
        for threads in [1, 2] {
            let p = helpers::pool(threads);
            let n = trace_probe(accel, rays, &p);
            assert!(n > rays.len() * 18 / 10, "only {n} probe hits");
            g.bench_with_input(
                BenchmarkId::new(accel.name(), format!("{threads}t")),
                &threads,
                |b, _| b.iter(|| trace_probe(accel, rays, &p)),
            );
        }
        g.finish();
    }
}

fn backends() -> Vec<Backend> {
    let mut v = vec![Backend::Bvh];
    if Backend::default_available() == Backend::Embree {
        v.push(Backend::Embree);
    }
    v
}

fn bench(c: &mut Criterion) {
    let meshes = Arc::new(vec![shapes::displaced_sphere(8, 0.1)]);
    let rays = helpers::incoherent_rays(helpers::BATCH, 1);
    for backend in backends() {
        helpers::build_time(c, &meshes, backend);
        let accel = accel::build(&meshes, backend).unwrap();
        helpers::nearest_throughput(c, accel.as_ref(), &rays);
        more_queries::occluded_throughput(c, accel.as_ref(), &rays);
        more_queries::probe_throughput(c, accel.as_ref(), &rays);
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
