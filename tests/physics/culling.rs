//! Rays answered by bounds (`lucent::integrator::culling`): a ray the
//! proof says meets nothing meets nothing in either backend, and the
//! estimator's samples are the same, bit for bit, with culling on and off.

use lucent::accel::{self, Backend};
use lucent::geometry::{Ray, Vec3};
use lucent::integrator::path::{radiance, Scratch};
use lucent::integrator::{Context, Counters, NoClock};
use lucent::sampling::{uniform_sphere, Draw, Rng, SampleRng};
use lucent::scene::load_str;
use std::path::Path;

/// A convex sphere and box, a non-convex lumpy sphere, a quad light and a
/// diffuse floor: rays from each, in every direction.
const SCENE: &str = r#"
[camera]
look_from = [0.0, 2.0, 9.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 40.0
resolution = [48, 32]

[render]
spp = 1
max_depth = 6

[environment]
radiance = [0.2, 0.2, 0.2]

[materials.marble]
type = "subsurface"
preset = "marble"
MARBLE_OPTIONS

[materials.rough]
type = "subsurface"
preset = "skin1"
roughness = 0.4

[materials.white]
type = "diffuse"
albedo = [0.7, 0.7, 0.7]

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]

[[shapes]]
name = "light"
type = "quad"
material = "lamp"
emission = [20.0, 20.0, 20.0]
scale = [0.6, 0.6, 1]
rotate = [[90.0, 1.0, 0.0, 0.0]]
translate = [0.5, 3.0, 1.0]

[[shapes]]
name = "ball"
type = "sphere"
material = "marble"
subdivisions = 3
translate = [-1.6, 0.0, 0.0]

[[shapes]]
name = "block"
type = "box"
material = "rough"
scale = [0.7, 0.7, 0.7]
translate = [1.6, 0.0, 0.0]

[[shapes]]
name = "floor"
type = "quad"
material = "white"
scale = [6.0, 6.0, 1]
rotate = [[-90.0, 1.0, 0.0, 0.0]]
translate = [0.0, -1.0, 0.0]
"#;

fn scene(marble: &str) -> lucent::scene::Scene {
    load_str(
        &SCENE.replace("MARBLE_OPTIONS", marble),
        Path::new("culling.toml"),
    )
    .unwrap()
}

fn backends() -> Vec<Backend> {
    let mut b = vec![Backend::Bvh];
    if cfg!(feature = "embree") {
        b.push(Backend::Embree3);
    }
    b
}

/// For random rays leaving every object (its front and back sides, in
/// both hemispheres), rays from anywhere in the scene and shadow segments
/// from the objects to the light: wherever the proof says "meets nothing",
/// the accelerator finds nothing; and the proof does answer many of them,
/// so this is not vacuous.
#[test]
fn a_ray_proven_to_miss_meets_nothing_in_either_backend() {
    let scene = scene("");
    let meshes = &scene.meshes;
    for backend in backends() {
        let accel = accel::build(meshes, backend).unwrap();
        let ctx = Context::new(&scene, accel.as_ref());
        let culling = ctx.culling.as_ref().expect("a small scene is culled");
        // The sphere, the box and both quads are convex-outside.
        assert_eq!(culling.convex_count(), 4, "{backend:?}");
        let light = 0u32;
        let mut rng = Rng::new(11, 0, 0);
        let (mut proven, mut total) = (0usize, 0usize);
        let mut check = |ray: &Ray, t_max: f32, ends: [Option<u32>; 2], what: &str| {
            total += 1;
            if culling.misses(ray, t_max, ends) {
                proven += 1;
                let hit = accel.intersect(ray, 0.0, t_max);
                assert!(
                    hit.is_none(),
                    "{backend:?}: {what} {ray:?} to t = {t_max} proven to miss, but hits {hit:?}"
                );
            }
        };
        for (geom, mesh) in meshes.iter().enumerate() {
            let geom = geom as u32;
            for _ in 0..4000 {
                let prim = (rng.uniform() * mesh.triangle_count() as f32) as u32;
                let prim = prim.min(mesh.triangle_count() as u32 - 1);
                let [a, b, c] = mesh.triangle(prim);
                let [u, v] = rng.uniform2();
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                let p = a + (b - a) * u + (c - a) * v;
                let n = mesh.face_normal(prim);
                let d = uniform_sphere(rng.uniform2());
                // Leave towards the side d points to, offset as the
                // integrator offsets (interaction::offset_origin).
                let front = d.dot(n) >= 0.0;
                let o = lucent::integrator::interaction::offset_origin(p, n, d, ctx.ray_epsilon);
                let from = ctx.leaving(geom, front);
                check(&Ray::new(o, d), f32::INFINITY, [from, None], "leaving");
                // A shadow segment from here to a point on the light's
                // front face, where the integrator would send one.
                let [lu, lv] = rng.uniform2();
                let [la, lb, lc] = meshes[light as usize].triangle(0);
                let q = la + (lb - la) * lu * (1.0 - lv) + (lc - la) * lv;
                let ln = meshes[light as usize].face_normal(0);
                let to = q - o;
                if geom != light && to.dot(ln) < 0.0 && to.dot(if front { n } else { -n }) > 0.0 {
                    let ends = [from, ctx.leaving(light, true)];
                    check(&Ray::new(o, to), 1.0 - 1e-4, ends, "shadow");
                }
            }
        }
        // Rays from anywhere, as camera rays start.
        for _ in 0..20000 {
            let o = Vec3::new(
                rng.uniform() * 16.0 - 8.0,
                rng.uniform() * 10.0 - 3.0,
                rng.uniform() * 16.0 - 8.0,
            );
            let d = uniform_sphere(rng.uniform2());
            check(&Ray::new(o, d), f32::INFINITY, [None, None], "free");
        }
        assert!(
            proven > total / 5,
            "{backend:?}: only {proven} of {total} rays proven to miss"
        );
    }
}

/// Each sample's radiance, and the rays it counts, with culling as the
/// context builds it and with it switched off, for `spp` samples of
/// every pixel; and how many queries culling answered.
fn samples(
    scene: &lucent::scene::Scene,
    backend: Backend,
    cull: bool,
) -> (Vec<[u32; 3]>, u64, u64) {
    let accel = accel::build(&scene.meshes, backend).unwrap();
    let mut ctx = Context::new(scene, accel.as_ref());
    if !cull {
        ctx.culling = None;
    }
    let mut scratch = Scratch::default();
    let mut counters = Counters::default();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            for s in 0..4 {
                let mut rng = SampleRng::new(3, (y * w + x) as u64, s);
                let [jx, jy] = rng.uniform2_packed();
                let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy);
                let l = radiance::<_, NoClock>(
                    &ctx,
                    ray,
                    &mut rng,
                    &mut scratch,
                    &mut counters,
                    &mut lucent::integrator::aov::NoAov,
                );
                out.push(l.to_array().map(f32::to_bits));
            }
        }
    }
    (out, counters.rays, counters.culled)
}

/// Culling changes no sample: the same radiance, bit for bit, and the
/// same ray count, on the BVH and on Embree, with the smooth coat and the
/// rough one, a diffuse floor, the probe pair and the control variate —
/// while it answers a good share of the queries.
#[test]
fn culling_changes_no_sample_bit_for_bit() {
    for marble in [
        "",
        "probe_pair = false",
        "control_variate = true\nprobe_pair = false",
    ] {
        let scene = scene(marble);
        for backend in backends() {
            let (on, rays_on, culled) = samples(&scene, backend, true);
            let (off, rays_off, none) = samples(&scene, backend, false);
            assert_eq!(none, 0);
            assert_eq!(rays_on, rays_off, "{backend:?} {marble:?}");
            let differ = on.iter().zip(&off).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{backend:?} {marble:?}: {differ} samples differ");
            assert!(
                culled * 10 > rays_on,
                "{backend:?} {marble:?}: only {culled} of {rays_on} queries culled"
            );
        }
    }
}
