//! The BVH's innermost loop, the watertight ray/triangle test, scalar
//! (four calls) against the 4-lane SSE packet test on the same triangles
//! and rays. Run with `cargo bench --bench kernels`.
//!
//! Triangles are small (edge ≤ 0.2 in the unit cube) and rays random, so
//! about one test in ten hits, as in a BVH leaf that a ray's box test let
//! through.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use lucent::accel::bvh::triangle::{RayTri, Tri4};
use lucent::geometry::{Ray, Vec3};
use lucent::sampling::Rng;

const PACKETS: usize = 1024;

fn setup() -> (Vec<Tri4>, Vec<[Vec3; 3]>, Vec<RayTri>) {
    let mut rng = Rng::from_key(3);
    let mut p = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
    let mut packets = Vec::with_capacity(PACKETS);
    let mut tris = Vec::with_capacity(4 * PACKETS);
    for _ in 0..PACKETS {
        let mut t4 = Tri4::EMPTY;
        for lane in 0..4 {
            let a = p();
            let tri = [a, a + (p() - 0.5) * 0.4, a + (p() - 0.5) * 0.4];
            t4.set(lane, tri, lane as u32);
            tris.push(tri);
        }
        packets.push(t4);
    }
    let rays = (0..PACKETS)
        .map(|_| {
            let o = p() * 4.0 - 1.5;
            RayTri::new(&Ray::new(o, p() - o))
        })
        .collect();
    (packets, tris, rays)
}

fn triangle_test(c: &mut Criterion) {
    let (packets, tris, rays) = setup();
    let mut g = c.benchmark_group("triangle_test");
    g.throughput(Throughput::Elements(4 * PACKETS as u64));
    g.bench_function("scalar_x4", |b| {
        b.iter(|| {
            let mut hits = 0u32;
            for (i, r) in rays.iter().enumerate() {
                for t in &tris[4 * i..4 * i + 4] {
                    hits += r.intersect(t[0], t[1], t[2], 0.0, f32::INFINITY).is_some() as u32;
                }
            }
            black_box(hits)
        })
    });
    g.bench_function("packet_sse", |b| {
        b.iter(|| {
            let mut hits = 0u32;
            for (r, t4) in rays.iter().zip(&packets) {
                hits += r.intersect4(t4, 0.0, f32::INFINITY).mask.count_ones();
            }
            black_box(hits)
        })
    });
    g.finish();
}

criterion_group!(benches, triangle_test);
criterion_main!(benches);
