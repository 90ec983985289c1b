//! How often a ray crosses a closed icosphere without a hit, with Embree
//! watertight and fast (`accel::Traversal`), the figures quoted in
//! docs/performance.md ("Traversal: fast or watertight"):
//!
//!     cargo run --release --example traversal_leaks -- [N] [LEVEL ...]
//!
//! For each subdivision level (default 5 and 8: 20,480 and 1,310,720
//! triangles on the unit sphere) and each traversal, N rays (default
//! 5,000,000) each way: from outside (3 units from a target point, along a
//! uniform direction) towards a uniform target point within 0.8 of the
//! centre, and from that target point outwards. Every one must hit the
//! mesh; the misses are printed. Rays and targets are the same for both
//! traversals (seeded).

use std::sync::Arc;

use lucent::accel::{self, Backend, Traversal};
use lucent::geometry::{Ray, Vec3};
use lucent::sampling::rng::Rng;
use lucent::scene::shapes;

/// A uniform point in the unit ball.
fn in_ball(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
        if v.length_squared() <= 1.0 {
            return v;
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parse = |s: &String| -> u64 {
        s.parse().unwrap_or_else(|_| {
            eprintln!("usage: traversal_leaks [N] [LEVEL ...]: not a whole number: {s}");
            std::process::exit(2)
        })
    };
    let n = args.first().map_or(5_000_000, parse);
    let levels: Vec<u32> = if args.len() > 1 {
        args[1..].iter().map(|s| parse(s) as u32).collect()
    } else {
        vec![5, 8]
    };
    for level in levels {
        let meshes = Arc::new(vec![shapes::sphere(level)]);
        for t in [Traversal::Watertight, Traversal::Fast] {
            let a = accel::build_with(&meshes, Backend::Embree, t).unwrap_or_else(|e| {
                eprintln!("error: {e}");
                std::process::exit(1)
            });
            let mut rng = Rng::from_key(7);
            let (mut from_outside, mut from_inside) = (0u64, 0u64);
            for _ in 0..n {
                let d = loop {
                    let v = in_ball(&mut rng);
                    if v.length_squared() > 1e-4 {
                        break v.normalize();
                    }
                };
                let target = in_ball(&mut rng) * 0.8;
                let hit = |o: Vec3| a.intersect(&Ray::new(o, d), 0.0, f32::INFINITY).is_some();
                from_outside += u64::from(!hit(target - d * 3.0));
                from_inside += u64::from(!hit(target));
            }
            println!(
                "sphere({level}), {} triangles, {} ({}): {n} rays each way, misses from outside {from_outside}, from inside {from_inside}",
                meshes[0].triangle_count(),
                t.name(),
                a.name(),
            );
        }
    }
}
