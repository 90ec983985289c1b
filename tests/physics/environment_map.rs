//! The environment image against closed forms and against the constant
//! environment: a uniform image lights a scene as the constant radiance
//! does (in expectation: the image is light-sampled with MIS, the constant
//! is not), and one bright texel lights a diffuse plane with the
//! irradiance of its solid angle.

use std::f32::consts::PI;
use std::sync::Arc;

use crate::common;
use crate::common::scene::{object, TestScene};
use lucent::accel::{self, Backend};
use lucent::environment::image::Texels;
use lucent::environment::{EnvMap, Environment};
use lucent::film::Film;
use lucent::geometry::{Mesh, Vec3};
use lucent::integrator::IntegratorKind;
use lucent::materials::Material;
use lucent::render::{render, RenderOptions};
use lucent::scene::{shapes, Camera, Scene};

/// A `w` × `h` image, black but for `lit` texels (column, row, radiance),
/// or `fill` everywhere.
fn image(w: u32, h: u32, fill: Vec3, lit: &[(u32, u32, Vec3)]) -> Texels {
    let mut data = vec![fill; (w * h) as usize];
    for (x, y, l) in lit {
        data[(y * w + x) as usize] = *l;
    }
    Texels {
        width: w,
        height: h,
        data,
    }
}

fn with_map(mut scene: Scene, texels: Texels, rotation: f32) -> Scene {
    scene.environment = Some(Environment::Map(Arc::new(EnvMap::new(
        texels, 1.0, rotation,
    ))));
    scene
}

fn run(scene: &Scene, integrator: IntegratorKind) -> Film {
    let a = accel::build(&scene.meshes, Backend::default_available()).unwrap();
    let opts = RenderOptions {
        integrator,
        ..Default::default()
    };
    render(scene, a.as_ref(), &opts).unwrap().0
}

fn scene_of(mesh: Mesh, material: Material, camera: Camera, spp: u32, env: Option<Vec3>) -> Scene {
    TestScene {
        camera,
        spp,
        max_depth: 4,
        seed: 5,
        environment: env,
    }
    .build(vec![mesh], vec![material], vec![object("o", 0, None)])
}

/// The image means of `a` and `b` agree within 4.5 combined standard
/// errors in every channel.
fn agree(a: &Film, b: &Film, what: &str) {
    let (ma, sa) = common::mean_se(a);
    let (mb, sb) = common::mean_se(b);
    for c in 0..3 {
        let tol = 4.5 * (sa[c] * sa[c] + sb[c] * sb[c]).sqrt() + 1e-6;
        assert!(
            (ma[c] - mb[c]).abs() <= tol,
            "{what}: channel {c}: {} vs {} (tolerance {tol})",
            ma[c],
            mb[c]
        );
    }
}

/// A uniform image of radiance L lights a convex diffuse sphere as the
/// constant environment L does: exactly ρL per sample there, the same in
/// expectation with the image's light samples and MIS-weighted escapes
/// (a weight that does not sum to one — both strategies counted in full,
/// or the escape's weight without its light sample — is off by up to ρL).
#[test]
fn uniform_image_matches_the_constant_environment() {
    let l = Vec3::new(0.5, 0.8, 1.25);
    let cam = Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 24, 16);
    let material = Material::Diffuse {
        albedo: Vec3::new(0.2, 0.5, 0.9),
    };
    let constant = scene_of(
        shapes::sphere(3),
        material.clone(),
        cam.clone(),
        16,
        Some(l),
    );
    let mapped = with_map(
        scene_of(shapes::sphere(3), material, cam, 16, None),
        image(16, 8, l, &[]),
        33.0,
    );
    let a = run(&constant, IntegratorKind::Path);
    let b = run(&mapped, IntegratorKind::Path);
    agree(&a, &b, "diffuse sphere");
    // Pixels that see only the environment are exactly L in both.
    assert_eq!(a.get(0, 0), l);
    assert_eq!(b.get(0, 0), l);
}

/// The same with a subsurface sphere (marble), through the probes' entry
/// points and their light samples, and with the random walk, whose exits
/// through the dielectric boundary find the image by escaping.
#[cfg(feature = "subsurface")]
#[test]
fn uniform_image_matches_the_constant_environment_through_subsurface() {
    use lucent::bssrdf::{Fit, ProbeOptions, SubsurfaceParams};
    use lucent::materials::Subsurface;
    let l = Vec3::ONE;
    let cam = Camera::new(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 30.0, 16, 16);
    let params = SubsurfaceParams::from_preset("marble", 0.5, Fit::Searchlight).unwrap();
    let material = Material::Subsurface(Arc::new(
        Subsurface::new(params, &ProbeOptions::default(), true, true).unwrap(),
    ));
    for kind in [IntegratorKind::Path, IntegratorKind::RandomWalk] {
        let constant = scene_of(
            shapes::sphere(3),
            material.clone(),
            cam.clone(),
            32,
            Some(l),
        );
        let mapped = with_map(
            scene_of(shapes::sphere(3), material.clone(), cam.clone(), 32, None),
            image(8, 4, l, &[]),
            0.0,
        );
        agree(
            &run(&constant, kind),
            &run(&mapped, kind),
            &format!("{kind:?}"),
        );
    }
}

/// One texel of radiance L (column 3 of 16, row 1 of 8: θ from π/8 to
/// π/4) over a diffuse plane facing +y: E = L·Δφ·(sin²θ₁ − sin²θ₀)/2 with
/// Δφ = 2π/16, and the plane's radiance ρE/π. Light sampling always finds
/// the texel, so the estimate is nearly exact; a pdf without its 1/sin θ
/// Jacobian, or a texel mapped to the wrong row, misses by far more.
#[test]
fn one_bright_texel_lights_a_plane_with_its_irradiance() {
    let l = Vec3::new(100.0, 50.0, 25.0);
    let rho = 0.7;
    let p = vec![
        Vec3::new(-100.0, 0.0, 100.0),
        Vec3::new(100.0, 0.0, 100.0),
        Vec3::new(100.0, 0.0, -100.0),
        Vec3::new(-100.0, 0.0, -100.0),
    ];
    let plane = Mesh::new(p, vec![[0, 1, 2], [0, 2, 3]], None);
    let cam = Camera::new(
        Vec3::new(0.0, 10.0, 0.0),
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, -1.0),
        10.0,
        8,
        8,
    );
    let material = Material::Diffuse {
        albedo: Vec3::splat(rho),
    };
    for rotation in [0.0, 123.0] {
        let scene = with_map(
            scene_of(plane.clone(), material.clone(), cam.clone(), 64, None),
            image(16, 8, Vec3::ZERO, &[(3, 1, l)]),
            rotation,
        );
        let film = run(&scene, IntegratorKind::Path);
        let (t0, t1) = (PI / 8.0, PI / 4.0);
        let e = l * (2.0 * PI / 16.0) * (t1.sin().powi(2) - t0.sin().powi(2)) / 2.0;
        let expect = e * rho / PI;
        let (m, _) = common::mean_se(&film);
        for c in 0..3 {
            let rel = (m[c] as f32 / expect[c] - 1.0).abs();
            assert!(
                rel < 0.005,
                "channel {c}: {} vs {} ({rel})",
                m[c],
                expect[c]
            );
        }
    }
}
