//! White-furnace tests of the path tracer: closed-form answers for scenes
//! where light transport can be summed by hand.

use crate::common;

use common::backends;

use crate::common::scene::{object, TestScene};
use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::geometry::Vec3;
use lucent::materials::Material;
use lucent::render::{render, RenderOptions};
use lucent::scene::{shapes, Camera, Scene};

fn scene_with(
    mesh: lucent::geometry::Mesh,
    material: Material,
    emission: Option<Vec3>,
    env: Option<Vec3>,
    camera: Camera,
    spp: u32,
    max_depth: u32,
) -> Scene {
    TestScene {
        camera,
        spp,
        max_depth,
        seed: 7,
        environment: env,
    }
    .build(vec![mesh], vec![material], vec![object("s", 0, emission)])
}

fn faceted_sphere(level: u32) -> lucent::geometry::Mesh {
    let s = shapes::sphere(level);
    lucent::geometry::Mesh::new(s.positions().to_vec(), s.indices.clone(), None)
}

fn render_with(scene: &Scene, backend: Backend) -> Film {
    let a = accel::build(&scene.meshes, backend).unwrap();
    render(scene, a.as_ref(), &RenderOptions::default())
        .unwrap()
        .0
}

/// A convex diffuse object under a constant environment L: a path bounces
/// once and escapes, so every pixel on the object is exactly ρ·L per sample
/// (zero variance) and every other pixel is L. With ρ = 1 the object
/// vanishes into the furnace.
#[test]
fn convex_diffuse_sphere_in_constant_environment() {
    let env = Vec3::new(0.5, 0.8, 1.25);
    let cam = Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 48, 32);
    for backend in backends() {
        for rho in [Vec3::ONE, Vec3::new(0.2, 0.5, 0.9)] {
            let scene = scene_with(
                faceted_sphere(3),
                Material::Diffuse { albedo: rho },
                None,
                Some(env),
                cam.clone(),
                4,
                8,
            );
            let film = render_with(&scene, backend);
            let (mut on, mut off) = (0, 0);
            for p in &film.pixels {
                // pixels straddling the silhouette mix the two values
                if (*p - env).abs().max_element() < 1e-5 {
                    off += 1;
                } else if (*p - rho * env).abs().max_element() < 1e-5 {
                    on += 1;
                } else {
                    let t = (p.x - env.x) / (rho.x * env.x - env.x + 1e-30);
                    assert!(
                        rho == Vec3::ONE || (0.0..=1.0).contains(&t),
                        "{backend:?}: pixel {p} is no mix of L and ρL"
                    );
                }
            }
            if rho == Vec3::ONE {
                assert_eq!(
                    off,
                    film.pixels.len(),
                    "{backend:?}: ρ = 1 must give exactly L everywhere"
                );
            } else {
                assert!(on > 150 && off > 300, "{backend:?}: on {on} off {off}");
            }
        }
    }
}

/// Inside a closed sphere of albedo ρ whose inner surface emits Le, the
/// radiance everywhere is Le (1 + ρ + ρ² + …) = Le / (1 − ρ). This exercises
/// next-event estimation, MIS with BSDF sampling, many bounces and Russian
/// roulette together; the mean over the image must match within 4 standard
/// errors.
#[test]
fn closed_emissive_sphere_sums_the_neumann_series() {
    let le = Vec3::new(1.0, 0.5, 0.25);
    for (rho, backend) in [(0.5f32, Backend::Bvh), (0.8, *backends().last().unwrap())] {
        let mut mesh = faceted_sphere(2);
        mesh.flip_winding(); // front faces inward
        let cam = Camera::new(Vec3::ZERO, Vec3::new(0.3, 0.2, -1.0), Vec3::Y, 90.0, 32, 32);
        let scene = scene_with(
            mesh,
            Material::Diffuse {
                albedo: Vec3::splat(rho),
            },
            Some(le),
            None,
            cam,
            16,
            200,
        );
        let film = render_with(&scene, backend);
        let n = film.pixels.len() as f64;
        for c in 0..3 {
            let vals: Vec<f64> = film.pixels.iter().map(|p| p[c] as f64).collect();
            let mean = vals.iter().sum::<f64>() / n;
            let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            let se = (var / n).sqrt();
            let expect = le[c] as f64 / (1.0 - rho as f64);
            assert!(
                (mean - expect).abs() < 4.0 * se + 1e-4 * expect,
                "{backend:?} ρ={rho} ch{c}: mean {mean} expected {expect} (se {se})"
            );
            assert!(
                se < 0.02 * expect,
                "test too noisy to mean anything: se {se}"
            );
        }
    }
}

/// The same image for any thread count: bitwise.
#[test]
fn image_is_identical_for_any_thread_count() {
    let mut mesh = faceted_sphere(2);
    mesh.flip_winding();
    let cam = Camera::new(Vec3::ZERO, Vec3::new(0.3, 0.2, -1.0), Vec3::Y, 90.0, 37, 21);
    let scene = scene_with(
        mesh,
        Material::Diffuse {
            albedo: Vec3::splat(0.7),
        },
        Some(Vec3::ONE),
        None,
        cam,
        3,
        20,
    );
    let a = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let one = render(
        &scene,
        a.as_ref(),
        &RenderOptions {
            threads: Some(1),
            ..Default::default()
        },
    )
    .unwrap()
    .0;
    let two = render(
        &scene,
        a.as_ref(),
        &RenderOptions {
            threads: Some(2),
            ..Default::default()
        },
    )
    .unwrap()
    .0;
    let bits = |f: &Film| {
        f.pixels
            .iter()
            .flat_map(|p| p.to_array())
            .map(f32::to_bits)
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&one), bits(&two));
    let other_seed = render(
        &scene,
        a.as_ref(),
        &RenderOptions {
            seed: Some(8),
            ..Default::default()
        },
    )
    .unwrap()
    .0;
    assert_ne!(bits(&one), bits(&other_seed));
}
