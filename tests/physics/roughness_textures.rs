//! Roughness read from a texture (`docs/scene-format.md`, "Textures"):
//! a conductor, a rough dielectric, a plastic's coat and a subsurface
//! material's coat. Their energy compensation reads albedo tables blended
//! between fixed roughness steps, so a textured roughness is checked
//! against the constant material of the same value (the blend's error is
//! a few 10⁻³ of the albedo at most), against a white furnace, and half
//! by half. Scenes are loaded from TOML beside PNGs the tests write.

use std::path::Path;

use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::render::{render, RenderOptions};
use lucent::scene::Scene;

/// A 24 × 24 view of a 4 × 4 floor (u = (x + 2)/4 running right in the
/// image) under a sphere light and a dim environment, or in a white
/// furnace: the floor's `material` body, and `extra` tables.
fn floor(material: &str, extra: &str, furnace: bool) -> String {
    let light = if furnace {
        "[environment]\nradiance = [1.0, 1.0, 1.0]\n"
    } else {
        "[environment]\nradiance = [0.1, 0.1, 0.1]\n\
         [[lights]]\ntype = \"sphere\"\nposition = [0.3, 2.0, -2.0]\nradius = 0.3\n\
         radiance = [60.0, 60.0, 60.0]\n"
    };
    format!(
        "[camera]\nlook_from = [0.0, 3.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\n\
         up = [0.0, 1.0, 0.0]\nfov_y = 50.0\nresolution = [24, 24]\n\
         [render]\nspp = 16\nmax_depth = 6\nseed = 3\n\
         {light}{extra}\
         [materials.m]\n{material}\n\
         [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nrotate = [[-90.0, 1.0, 0.0, 0.0]]\n\
         scale = 2.0\n"
    )
}

fn load(dir: &Path, text: &str) -> Scene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    lucent::scene::load(&path).unwrap()
}

fn run(scene: &Scene) -> Film {
    let a = accel::build(&scene.meshes, Backend::default_available()).unwrap();
    render(scene, a.as_ref(), &RenderOptions::default())
        .unwrap()
        .0
}

/// A linear grey PNG whose column x holds `f(x)`.
fn write_png(path: &Path, w: u32, f: impl Fn(u32) -> u8) {
    image::RgbImage::from_fn(w, 4, |x, _| image::Rgb([f(x); 3]))
        .save(path)
        .unwrap();
}

const TEXTURE: &str = "[textures.r]\nfile = \"r.png\"\ncolor_space = \"linear\"\n";

/// The materials, as `[materials.m]` bodies without their roughness.
fn materials() -> Vec<&'static str> {
    let mut m = vec![
        "type = \"conductor\"\nmetal = \"gold\"",
        "type = \"plastic\"\nalbedo = [0.6, 0.3, 0.1]",
        "type = \"dielectric\"\neta = 1.5",
    ];
    if cfg!(feature = "subsurface") {
        m.push(
            "type = \"subsurface\"\nalbedo = [0.8, 0.6, 0.4]\ndmfp = [0.3, 0.2, 0.1]\neta = 1.4",
        );
    }
    m
}

/// The relative difference of the means of `a` and `b` over the columns
/// `cols`, the largest of the channels'. Means, not pixels: a coat's
/// lobe is picked by comparing a random number with its albedo, so where
/// the two albedos differ by the blend's error a few samples pick the
/// other lobe.
fn mean_difference(a: &Film, b: &Film, cols: std::ops::Range<usize>) -> f32 {
    let w = a.width as usize;
    let mean = |f: &Film| {
        f.pixels
            .iter()
            .enumerate()
            .filter(|(i, _)| cols.contains(&(i % w)))
            .fold(glam::Vec3::ZERO, |s, (_, p)| s + *p)
    };
    let (p, q) = (mean(a), mean(b));
    ((p - q).abs() / q.max(glam::Vec3::splat(1e-6))).max_element()
}

/// The mistake: a textured roughness rendered with a roughness other than
/// the texel's (the factor applied twice or not at all, the base's own
/// table or distribution kept), or a coat whose albedo, entry lobe or
/// regularized coat does not follow it. A uniform texture of 100/255
/// times `roughness = 0.8` (0.314, between two steps) renders as the
/// constant roughness of that value to within the blend's error (the same
/// random numbers: the two differ by a few samples that pick the other
/// lobe).
#[test]
fn a_uniform_roughness_texture_renders_as_the_constant() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("r.png"), 4, |_| 100);
    let r = 100.0f32 / 255.0 * 0.8;
    for m in materials() {
        let tex = load(
            dir.path(),
            &floor(
                &format!("{m}\nroughness = 0.8\nroughness_texture = \"r\""),
                TEXTURE,
                false,
            ),
        );
        let con = load(
            dir.path(),
            &floor(&format!("{m}\nroughness = {r}"), "", false),
        );
        let (t, c) = (run(&tex), run(&con));
        let lit = c.pixels.iter().filter(|p| p.max_element() > 0.05).count();
        assert!(lit > 150, "{m}: {lit} lit pixels");
        for cols in [0..6, 6..12, 12..18, 18..24] {
            let d = mean_difference(&t, &c, cols.clone());
            assert!(d < 2e-3, "{m}, columns {cols:?}: relative difference {d}");
        }
    }
}

/// The mistake: the energy compensation of one roughness (the material's
/// factor, or a wrong step) applied to the lobe of another, which a white
/// furnace shows: a conductor of F = 1 and a white plastic reflect all of
/// a uniform environment at every roughness, so a floor whose roughness
/// runs from 0 to 1 across the image is 1 everywhere, in bands of four
/// columns (64 samples a pixel: the band's noise is about 10⁻³).
#[test]
fn a_varying_roughness_keeps_the_white_furnace() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("r.png"), 256, |x| x as u8);
    for m in [
        "type = \"conductor\"\nn = [1.0, 1.0, 1.0]\nk = [10000.0, 10000.0, 10000.0]",
        "type = \"plastic\"\nalbedo = [1.0, 1.0, 1.0]",
    ] {
        let text = floor(&format!("{m}\nroughness_texture = \"r\""), TEXTURE, true);
        let scene = load(dir.path(), &text.replace("spp = 16", "spp = 64"));
        let f = run(&scene);
        let w = f.width as usize;
        for x in (0..w).step_by(4) {
            let band: Vec<f32> = f
                .pixels
                .iter()
                .enumerate()
                .filter(|(i, _)| (x..x + 4).contains(&(i % w)))
                .map(|(_, p)| p.x)
                .collect();
            let mean = band.iter().sum::<f32>() / band.len() as f32;
            assert!((mean - 1.0).abs() < 5e-3, "{m}: columns {x}..: {mean}");
        }
    }
}

/// The mistake: the roughness read at the wrong place (u and v swapped,
/// the image mirrored) or one half's value used on both. A texture of
/// roughness 0.16 on its left half and 0.78 on its right renders each
/// half as the constant material of its own roughness, away from the
/// columns that filtering mixes: at the seam, and near the floor's edges,
/// where the texture repeats and the far rows' wide footprints reach
/// across.
#[test]
fn a_half_and_half_roughness_matches_each_constant_on_its_half() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (40u8, 200u8);
    write_png(
        &dir.path().join("r.png"),
        64,
        |x| if x < 32 { a } else { b },
    );
    for m in materials() {
        let tex = load(
            dir.path(),
            &floor(&format!("{m}\nroughness_texture = \"r\""), TEXTURE, false),
        );
        let t = run(&tex);
        for (v, cols) in [(a, 4..10), (b, 14..20)] {
            let r = v as f32 / 255.0;
            let con = load(
                dir.path(),
                &floor(&format!("{m}\nroughness = {r}"), "", false),
            );
            let d = mean_difference(&t, &run(&con), cols.clone());
            assert!(d < 2e-3, "{m}, roughness {r}, columns {cols:?}: {d}");
        }
    }
}
