//! The glossy materials through the whole renderer: a white-furnace sphere
//! (conductor with F ≈ 1, plastic with ρ = 1, rough and smooth) vanishes
//! into a constant environment, and the scene keys build the materials
//! they name.

use std::sync::Arc;

use crate::common::scene::{object, TestScene};
use lucent::accel::{self, Backend};
use lucent::geometry::{Mesh, Vec3};
use lucent::materials::{Conductor, Material, Plastic};
use lucent::render::{render, RenderOptions};
use lucent::scene::{shapes, Camera};

/// The image mean per channel and its standard error.
fn mean_and_error(pixels: &[Vec3], c: usize) -> (f64, f64) {
    let n = pixels.len() as f64;
    let mean = pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n;
    let var = pixels
        .iter()
        .map(|p| (p[c] as f64 - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// A convex sphere filling the view in a constant environment L: each
/// path reflects once and escapes, so a material that reflects all light
/// at every angle renders L. The camera sits close, so every pixel sees
/// the sphere. A lobe whose sampled weights are not f cos / pdf, a smooth
/// coat's branch weights that do not add up, or a lost multiple-scattering
/// term fails (by up to half of L at roughness 1).
#[test]
fn white_furnace_spheres_render_the_environment() {
    let env = Vec3::new(0.5, 0.8, 1.25);
    let cam = Camera::new(Vec3::new(0.0, 0.0, 1.6), Vec3::ZERO, Vec3::Y, 30.0, 24, 24);
    let s = shapes::sphere(3);
    let mesh = Mesh::new(s.positions().to_vec(), s.indices.clone(), None);
    let white = Vec3::ONE;
    let materials = [
        (
            "rough conductor",
            Material::Conductor(Arc::new(Conductor::new(white, Vec3::splat(1e4), 0.8))),
        ),
        (
            "mirror conductor",
            Material::Conductor(Arc::new(Conductor::new(white, Vec3::splat(1e4), 0.0))),
        ),
        (
            "rough plastic",
            Material::Plastic(Arc::new(Plastic::new(white, 1.5, 0.5))),
        ),
        (
            "smooth plastic",
            Material::Plastic(Arc::new(Plastic::new(white, 1.5, 0.0))),
        ),
    ];
    for (name, m) in materials {
        let scene = TestScene {
            camera: cam.clone(),
            spp: 16,
            max_depth: 8,
            seed: 3,
            environment: Some(env),
        }
        .build(vec![mesh.clone()], vec![m], vec![object("s", 0, None)]);
        let a = accel::build(&scene.meshes, Backend::Bvh).unwrap();
        let film = render(&scene, a.as_ref(), &RenderOptions::default())
            .unwrap()
            .0;
        for c in 0..3 {
            let (mean, se) = mean_and_error(&film.pixels, c);
            let want = env[c] as f64;
            assert!(
                (mean - want).abs() < 4.0 * se + 4e-3 * want,
                "{name} channel {c}: mean {mean}, L {want} (se {se})"
            );
        }
    }
}

/// The scene keys: a named metal gets its table's n + ik, `n`/`k` give
/// their own, a dielectric with `roughness` > 0 is rough and without it
/// the smooth interface, a plastic gets η = 1.5 unless given.
#[test]
fn scene_keys_build_the_named_materials() {
    let text = r#"
[camera]
look_from = [0, 0, 4]
look_at = [0, 0, 0]
resolution = [8, 8]
[materials.gold]
type = "conductor"
metal = "gold"
roughness = 0.3
[materials.custom]
type = "conductor"
n = [0.2, 0.9, 1.1]
k = [3.9, 2.4, 2.1]
[materials.frosted]
type = "dielectric"
eta = 1.5
roughness = 0.4
[materials.glass]
type = "dielectric"
eta = 1.5
roughness = 0
[materials.red]
type = "plastic"
albedo = [0.8, 0.1, 0.1]
roughness = 0.2
[[shapes]]
type = "sphere"
material = "gold"
"#;
    let s = lucent::scene::load_str(text, std::path::Path::new("s.toml")).unwrap();
    let by = |n: &str| {
        let i = s.output.material_names.iter().position(|m| m == n).unwrap();
        &s.materials[i]
    };
    let gold = lucent::materials::metals::metal("gold").unwrap();
    assert!(
        matches!(by("gold"), Material::Conductor(c) if c.eta == gold.eta() && c.k == gold.k() && c.roughness == 0.3)
    );
    assert!(
        matches!(by("custom"), Material::Conductor(c) if c.eta == Vec3::new(0.2, 0.9, 1.1) && c.is_smooth())
    );
    assert!(
        matches!(by("frosted"), Material::RoughDielectric(d) if d.eta == 1.5 && d.roughness == 0.4)
    );
    assert_eq!(*by("glass"), Material::Dielectric { eta: 1.5 });
    assert!(
        matches!(by("red"), Material::Plastic(p) if p.eta == 1.5 && p.albedo.x == 0.8 && !p.is_smooth())
    );
}
