//! Image textures rendered: a marker texel lands on the pixel its texture
//! coordinates predict, a constant texture renders as the constant
//! parameter, a flat normal map changes nothing. Scenes are loaded from
//! TOML beside PNGs the tests write, so the loader's texture path (sRGB
//! decoding, generated UVs, the texture table) is the one exercised.

use std::path::Path;

use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::render::{render, RenderOptions};
use lucent::scene::Scene;
use lucent::texture::srgb_to_linear;

/// A quad [-1, 1]² facing +z seen straight on, filling an 8 × 8 frame
/// exactly (tan(fov/2) = 1/5 at distance 5), under a white environment:
/// each sample of a diffuse quad is its albedo where it lands.
const QUAD_VIEW: &str = "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
    fov_y = 22.619864948040426\nresolution = [8, 8]\n\
    [render]\nspp = 256\nmax_depth = 2\n\
    [environment]\nradiance = [1, 1, 1]\n";

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

fn write_png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    image::RgbImage::from_fn(w, h, |x, y| image::Rgb(f(x, y)))
        .save(path)
        .unwrap();
}

/// The texel at column 5, row 2 (from the top) of an 8 × 8 texture on the
/// quad is its only bright one: u ∈ [5/8, 6/8], v ∈ [5/8, 6/8], which the
/// camera sees at pixel (5, 2). Bilinear filtering spreads a texel's tent
/// over its neighbours: averaged over the pixel, ¾ · ¾ of it stays there,
/// ¾ · ⅛ goes to each side neighbour.
#[test]
fn a_marker_texel_lands_at_the_predicted_pixel() {
    let dir = tempfile::tempdir().unwrap();
    write_png(&dir.path().join("marker.png"), 8, 8, |x, y| {
        if (x, y) == (5, 2) {
            [255, 255, 255]
        } else {
            [0, 0, 0]
        }
    });
    let scene = load(
        dir.path(),
        &format!(
            "{QUAD_VIEW}[textures.marker]\nfile = \"marker.png\"\n\
             [materials.m]\ntype = \"diffuse\"\nalbedo_texture = \"marker\"\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\n"
        ),
    );
    let film = run(&scene);
    let mut best = (0, 0, 0.0f32);
    for y in 0..8 {
        for x in 0..8 {
            let v = film.get(x, y).x;
            if v > best.2 {
                best = (x, y, v);
            }
        }
    }
    assert_eq!((best.0, best.1), (5, 2), "brightest pixel {best:?}");
    assert!((best.2 - 0.5625).abs() < 0.03, "marker pixel {}", best.2);
    let side = film.get(4, 2).x;
    assert!((side - 0.09375).abs() < 0.02, "its neighbour {side}");
    assert!(
        film.get(2, 5).x < 1e-6,
        "the mirrored pixel {}",
        film.get(2, 5).x
    );
}

/// The mistake: a JPEG texture decoded other than as stored (channels
/// swapped, left linear, rows flipped). A JPEG renders exactly as a PNG
/// of the pixels the JPEG decodes to.
#[test]
fn a_jpeg_texture_renders_as_the_png_of_its_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::from_fn(8, 8, |x, y| {
        image::Rgb([(x * 30) as u8, (y * 30) as u8, 200 - (x * y) as u8])
    });
    img.save(dir.path().join("t.jpg")).unwrap();
    let decoded = image::open(dir.path().join("t.jpg")).unwrap().into_rgb8();
    assert_ne!(decoded.get_pixel(7, 0), decoded.get_pixel(0, 7));
    decoded.save(dir.path().join("t.png")).unwrap();
    let frame = |file: &str| {
        run(&load(
            dir.path(),
            &format!(
                "{QUAD_VIEW}[textures.t]\nfile = \"{file}\"\n\
                 [materials.m]\ntype = \"diffuse\"\nalbedo_texture = \"t\"\n\
                 [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\n"
            ),
        ))
    };
    let (jpeg, png) = (frame("t.jpg"), frame("t.png"));
    assert!(jpeg.pixels.iter().any(|p| p.max_element() > 0.1));
    assert_eq!(jpeg.pixels, png.pixels);
}

/// A sphere on a floor under an area light: an albedo texture of one
/// colour renders as the constant albedo it decodes to.
#[test]
fn a_constant_texture_renders_as_the_constant_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let c = [200u8, 90, 30];
    write_png(&dir.path().join("flat.png"), 5, 3, |_, _| c);
    let lin = c.map(|v| srgb_to_linear(v as f32 / 255.0));
    let body = |albedo: &str| {
        format!(
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 0.5, 0]\nresolution = [24, 16]\n\
             [render]\nspp = 8\nmax_depth = 4\nseed = 3\n\
             [textures.flat]\nfile = \"flat.png\"\n\
             [materials.m]\ntype = \"diffuse\"\n{albedo}\n\
             [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
             [[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\ntranslate = [0, 1, 0]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nscale = 4\n\
             rotate = [[-90, 1, 0, 0]]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\nemission = [4, 4, 4]\n\
             translate = [0, 4, 0]\nrotate = [[90, 1, 0, 0]]\n"
        )
    };
    let textured = run(&load(dir.path(), &body("albedo_texture = \"flat\"")));
    let constant = run(&load(
        dir.path(),
        &body(&format!(
            "albedo = [{:?}, {:?}, {:?}]",
            lin[0] as f64, lin[1] as f64, lin[2] as f64
        )),
    ));
    let mut worst = 0.0f32;
    for (a, b) in textured.pixels.iter().zip(&constant.pixels) {
        worst = worst.max((*a - *b).abs().max_element() / b.max_element().max(1e-3));
    }
    assert!(worst < 1e-4, "largest relative pixel difference {worst}");
}

/// A normal map of flat texels (½, ½, 1) (16-bit: 32768/65535 is ½ within
/// 1.6e-5) on a sphere renders as the sphere without it.
#[test]
fn a_flat_normal_map_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(4, 4, |_, _| {
        image::Rgb([32768, 32768, 65535])
    })
    .save(dir.path().join("n.png"))
    .unwrap();
    let body = |normal: &str| {
        format!(
            "[camera]\nlook_from = [0, 0, 4]\nlook_at = [0, 0, 0]\nresolution = [16, 16]\n\
             [render]\nspp = 8\nmax_depth = 3\n\
             [environment]\nradiance = [1, 1, 1]\n\
             [textures.n]\nfile = \"n.png\"\ncolor_space = \"linear\"\n\
             [materials.m]\ntype = \"plastic\"\nalbedo = [0.5, 0.4, 0.3]\nroughness = 0.3\n\
             {normal}\n\
             [[shapes]]\ntype = \"sphere\"\nmaterial = \"m\"\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\ntranslate = [0, -1, 0]\n\
             scale = 3\nrotate = [[-90, 1, 0, 0]]\n\
             [materials.light]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"light\"\nemission = [3, 3, 3]\n\
             translate = [1, 3, 1]\nrotate = [[90, 1, 0, 0]]\n"
        )
    };
    let mapped = run(&load(dir.path(), &body("normal_map = \"n\"")));
    let plain = run(&load(dir.path(), &body("")));
    let (mut diff, mut total) = (0.0f64, 0.0f64);
    for (a, b) in mapped.pixels.iter().zip(&plain.pixels) {
        diff += (*a - *b).abs().element_sum() as f64;
        total += b.element_sum() as f64;
    }
    assert!(total > 0.0);
    assert!(
        diff / total < 1e-3,
        "mean relative difference {}",
        diff / total
    );
}

/// A normal map that tilts every normal by 45° towards the tangent (+u,
/// +x on the quad) turns a diffuse quad lit from 45° on the +x side
/// towards the light: cos 0 instead of cos 45°, √2 times the light (a
/// tilt the wrong way would face away: black).
#[test]
fn a_tilting_normal_map_follows_the_tangent_frame() {
    let dir = tempfile::tempdir().unwrap();
    // (2c − 1) = (sin 45°, 0, cos 45°): tilted towards +u (+x on the quad)
    let t = (std::f32::consts::FRAC_1_SQRT_2 * 0.5 + 0.5) * 65535.0;
    image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(2, 2, |_, _| {
        image::Rgb([t.round() as u16, 32768, t.round() as u16])
    })
    .save(dir.path().join("n.png"))
    .unwrap();
    let body = |normal: &str| {
        format!(
            "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
             fov_y = 10\nresolution = [4, 4]\n[render]\nspp = 64\nmax_depth = 1\n\
             [textures.n]\nfile = \"n.png\"\ncolor_space = \"linear\"\n\
             [materials.m]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n{normal}\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\nscale = 20\n\
             [materials.light]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
             [[shapes]]\ntype = \"quad\"\nmaterial = \"light\"\nemission = [1, 1, 1]\n\
             translate = [707.1068, 0, 707.1068]\nrotate = [[225, 0, 1, 0]]\n"
        )
    };
    let mean = |f: &Film| f.pixels.iter().map(|p| p.x as f64).sum::<f64>() / f.pixels.len() as f64;
    let tilted = mean(&run(&load(dir.path(), &body("normal_map = \"n\""))));
    let flat = mean(&run(&load(dir.path(), &body(""))));
    let ratio = tilted / flat;
    assert!(
        (ratio - 2f64.sqrt()).abs() < 0.02,
        "tilted / flat = {ratio}"
    );
}
