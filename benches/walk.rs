//! The random walk's cost per walk (`integrator::randomwalk::walk`): walks
//! entering the marble sphere of `scenes/smooth-sphere.toml` at random
//! points of its surface, with the distance bounds that spare flights their
//! ray query (`geometry::distance`) and with them switched off, on the
//! default backend. Run with `cargo bench --bench walk`; the figures of
//! whole renders are in docs/accuracy.md, "Random walk: cost per sample".

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use lucent::accel::{build, Backend};
use lucent::geometry::{Frame, Ray, Vec3};
use lucent::integrator::interaction::offset_along;
use lucent::integrator::randomwalk::{walk, Boundary};
use lucent::integrator::{Context, Counters};
use lucent::materials::Material;
use lucent::sampling::{cosine_hemisphere, uniform_sphere, Draw, SampleRng};

const WALKS: u64 = 256;

fn walks(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/smooth-sphere.toml");
    let scene = lucent::scene::load(&path).unwrap();
    let (geom, medium) = scene
        .objects
        .iter()
        .enumerate()
        .find_map(|(i, o)| match &scene.materials[o.material] {
            Material::Subsurface(ss) => Some((i, ss.params().medium.unwrap())),
            _ => None,
        })
        .unwrap();
    let accel = build(&scene.meshes, Backend::default_available()).unwrap();
    let mut g = c.benchmark_group("walk");
    g.throughput(Throughput::Elements(WALKS));
    for bounds in [true, false] {
        let mut ctx = Context::new(&scene, accel.as_ref());
        if !bounds {
            ctx.without_distance_bounds();
        }
        let mesh = &scene.meshes[geom];
        let id = if bounds { "bounds" } else { "no bounds" };
        g.bench_function(id, |b| {
            b.iter(|| {
                let mut counters = Counters::default();
                let mut acc = Vec3::ZERO;
                for i in 0..WALKS {
                    let mut rng = SampleRng::new(1, i, 0);
                    // the sphere's surface point in a random direction,
                    // entered along a cosine-distributed inward direction
                    let d = uniform_sphere(rng.uniform2());
                    let r = mesh.bounding_radius();
                    let Some(hit) =
                        accel.intersect(&Ray::new(d * (2.0 * r), -d), 0.0, f32::INFINITY)
                    else {
                        continue;
                    };
                    let p = d * (2.0 * r) - d * hit.t;
                    let n = mesh.face_normal(hit.prim);
                    let n_in = if n.dot(d) > 0.0 { -n } else { n };
                    let w = Frame::from_normal(n_in).to_world(cosine_hemisphere(rng.uniform2()));
                    let ray = Ray::new(offset_along(p, n_in, ctx.ray_epsilon), w.normalize());
                    let end = walk(
                        &ctx,
                        &medium,
                        Boundary::Dielectric(1.5),
                        ray,
                        &mut rng,
                        &mut counters,
                    );
                    if let Some((_, weight)) = end {
                        acc += weight;
                    }
                }
                black_box(acc)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, walks);
criterion_main!(benches);
