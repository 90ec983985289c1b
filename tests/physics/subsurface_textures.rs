//! Textured subsurface parameters rendered (`docs/bssrdf.md` §13): a
//! uniform texture renders as the constant parameter it holds, and a
//! half-and-half texture gives each half the image of its own constant
//! material, also within the probe radius of the seam — the parameters
//! are those of the exit point xo, whatever the entry point's texel.
//! Scenes are loaded from TOML beside PNGs the tests write.

use std::path::Path;

use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::integrator::IntegratorKind;
use lucent::materials::Material;
use lucent::render::{render, RenderOptions};
use lucent::scene::Scene;
use lucent::texture::srgb_to_linear;

/// The flat slab of `scenes/slab-uniform.toml`, 10 × 10 wide (its sides
/// ≥ 2 Rmax from what the camera sees), 16 × 16 pixels of 0.22 units, its
/// top face's u = (z + 1)/2 running down the image; `material` is the
/// `[materials.slab]` body and `extra` more tables.
fn slab(material: &str, extra: &str) -> String {
    format!(
        "units_per_mm = 1.0\n\
         [camera]\nlook_from = [0.0, 10.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\n\
         up = [0.0, 0.0, -1.0]\nfov_y = 20.0\nresolution = [16, 16]\n\
         [render]\nspp = 16\nmax_depth = 4\nseed = 7\n\
         [environment]\nradiance = [1.0, 1.0, 1.0]\n\
         {extra}\
         [materials.slab]\ntype = \"subsurface\"\neta = 1.3\n{material}\n\
         [[shapes]]\nname = \"slab\"\ntype = \"box\"\nmaterial = \"slab\"\n\
         scale = [5.0, 5.0, 5.0]\ntranslate = [0.0, -5.0, 0.0]\n"
    )
}

fn load(dir: &Path, text: &str) -> Scene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    lucent::scene::load(&path).unwrap()
}

fn run(scene: &Scene) -> Film {
    run_with(scene, IntegratorKind::Path)
}

fn run_with(scene: &Scene, integrator: IntegratorKind) -> Film {
    let a = accel::build(&scene.meshes, Backend::default_available()).unwrap();
    let opts = RenderOptions {
        integrator,
        ..Default::default()
    };
    render(scene, a.as_ref(), &opts).unwrap().0
}

fn write_png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> u8) {
    image::RgbImage::from_fn(w, h, |x, y| image::Rgb([f(x, y); 3]))
        .save(path)
        .unwrap();
}

/// `[textures.NAME]` tables: (name, file, colour space).
fn textures(t: &[(&str, &str, &str)]) -> String {
    t.iter()
        .map(|(n, f, s)| format!("[textures.{n}]\nfile = \"{f}\"\ncolor_space = \"{s}\"\n"))
        .collect()
}

/// An f64 triple as TOML, each value written so that it reads back to the
/// same bits.
fn triple(v: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

const A: [f64; 3] = [0.2, 0.5, 0.8];
const DMFP: [f64; 3] = [0.3, 0.4, 0.25];

/// The mistake: a textured material sampled with parameters other than
/// the texel's (the factor not applied, or applied twice, the LOD or probe
/// radius of the untextured material, the sRGB curve skipped on the
/// albedo or applied to the lengths). A uniform albedo texture of sRGB
/// value 150 and a uniform length texture of linear value 200 render, bit
/// for bit, as the constant material of A·t and dmfp·k with the
/// diffusion estimator; with the random walk, whose medium (σs, σa from
/// the albedo table's inversion) must follow the texels too, within 10⁻⁴
/// (the textured material inverts A by a table of the inversion).
#[test]
fn a_uniform_texture_renders_as_the_constant_medium() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("a.png"), 4, 4, |_, _| 150);
    write_png(&dir.path().join("k.png"), 4, 4, |_, _| 200);
    let t = srgb_to_linear(150.0 / 255.0) as f64;
    let k = (200.0f32 / 255.0) as f64;
    let tables = textures(&[("a", "a.png", "srgb"), ("k", "k.png", "linear")]);
    let textured = load(
        dir.path(),
        &slab(
            &format!(
                "albedo = {}\ndmfp = {}\nalbedo_texture = \"a\"\ndmfp_texture = \"k\"",
                triple(A),
                triple(DMFP)
            ),
            &tables,
        ),
    );
    let constant = load(
        dir.path(),
        &slab(
            &format!(
                "albedo = {}\ndmfp = {}",
                triple(A.map(|a| t * a)),
                triple(DMFP.map(|d| d * k))
            ),
            "",
        ),
    );
    for integrator in [IntegratorKind::Path, IntegratorKind::RandomWalk] {
        let (tex, con) = (
            run_with(&textured, integrator),
            run_with(&constant, integrator),
        );
        let lit = con.pixels.iter().filter(|p| p.min_element() > 0.01).count();
        assert!(lit > 128, "{integrator:?}: {lit} lit pixels");
        if integrator == IntegratorKind::Path {
            assert!(tex.pixels == con.pixels, "{integrator:?}: pixels differ");
            continue;
        }
        // the walk's medium: α' of a textured A from the material's table
        // of the inversion (within 2·10⁻⁵), not the bisection itself
        let worst = tex
            .pixels
            .iter()
            .zip(&con.pixels)
            .map(|(a, b)| (*a - *b).abs().max_element() / b.max_element().max(1e-3))
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-4, "{integrator:?}: relative difference {worst}");
    }
}

/// The mistake: the parameters taken at the entry point xi (or mixed from
/// xo and xi) instead of the exit point xo. The slab's texture is A·1 on
/// the image's upper half and A·t below (or the lengths: dmfp·1 and
/// dmfp·k); the probe radius Rmax spans most of the image, so a probe from
/// almost every pixel reaches the other half. With the exit point's
/// parameters each pixel whose footprint stays on one side (its texels,
/// MIP levels included) is, bit for bit, that side's constant material.
#[test]
fn each_half_of_a_split_texture_renders_as_its_constant_medium() {
    let dir = tempfile::tempdir().unwrap();
    // columns: u < ½ is z < 0, the image's upper half
    write_png(&dir.path().join("split.png"), 256, 8, |x, _| {
        if x < 128 {
            255
        } else {
            90
        }
    });
    let t = srgb_to_linear(90.0 / 255.0) as f64;
    let k = (90.0f32 / 255.0) as f64;
    let tables = textures(&[("s", "split.png", "srgb"), ("l", "split.png", "linear")]);
    for (key, low_a, low_d) in [
        ("albedo_texture = \"s\"", A.map(|a| t * a), DMFP),
        ("dmfp_texture = \"l\"", A, DMFP.map(|d| d * k)),
    ] {
        let body = |a: [f64; 3], d: [f64; 3], tex: &str| {
            format!("albedo = {}\ndmfp = {}\n{tex}", triple(a), triple(d))
        };
        let textured = run(&load(dir.path(), &slab(&body(A, DMFP, key), &tables)));
        let upper_scene = load(dir.path(), &slab(&body(A, DMFP, ""), ""));
        // the upper rows compared lie 0.77 to 1.65 units from the seam
        // (pixels of 2·10·tan 10° / 16 = 0.22 units): all within Rmax
        let Material::Subsurface(ss) = &upper_scene.materials[0] else {
            panic!("not a subsurface material")
        };
        assert!(ss.probe().rmax() > 1.7, "Rmax {}", ss.probe().rmax());
        let upper = run(&upper_scene);
        let lower = run(&load(dir.path(), &slab(&body(low_a, low_d, ""), "")));
        assert_ne!(upper.get(8, 2), lower.get(8, 2), "{key}: halves alike");
        let mut near = 0;
        for y in 0..16u32 {
            // the seam is at row 8; its MIP footprint spreads ~2 pixels
            let want = match y {
                0..=4 => &upper,
                12..=15 => &lower,
                _ => continue,
            };
            for x in 0..16 {
                assert_eq!(
                    textured.get(x, y),
                    want.get(x, y),
                    "{key}: pixel ({x}, {y})"
                );
            }
            near += 1;
        }
        assert_eq!(near, 9);
    }
}
