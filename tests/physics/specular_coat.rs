//! The specular layer on top of a subsurface material reflects in the
//! mirror direction about the shading normal: ωr = 2(ωo·n)n − ωo.
//!
//! A constant environment cannot tell a wrong reflection direction from
//! the right one; a small light can. The scenes: a flat subsurface slab
//! with no active channel (A = 0, so all it shows is its specular layer;
//! docs/scene-format.md) seen at 45° by a camera whose central ray meets
//! the slab at the origin, and a small one-sided area light placed where
//! that ray's mirror reflection goes. The highlight must then sit at the
//! image centre, with the brightness the Fresnel reflectance predicts
//! (F·Le: reflected with probability F, weight 1), and nothing else may be
//! lit. On a slab whose shading normals are tilted (an OBJ with `vn`), the
//! light is moved to the mirror direction about the tilted normal, 20°
//! away from the geometric mirror direction, and the highlight must follow.
//!
//! Built with `scene::load_str` and rendered through the public API only.

use crate::common;

use std::path::Path;

use lucent::accel;
use lucent::geometry::Vec3;
use lucent::render::{render, RenderOptions};
use lucent::scene::load_str;

const RES: usize = 33;
const LE: f32 = 50.0;
const ETA: f64 = 2.0;
/// Distance of the camera and of the light from the origin.
const DIST: f32 = 4.0;
/// Half the side of the square light.
const HALF: f32 = 0.4;

/// Unpolarized Fresnel reflectance from outside (Born & Wolf, in f64).
fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin_t = (1.0 - cos_i * cos_i).sqrt() / eta;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The slab (top face y = 0) as an OBJ whose top face has the shading
/// normal `n_top` and the other faces their geometric normals.
fn slab_obj(n_top: Vec3) -> String {
    let mut s = String::new();
    for y in [-1.0, 0.0] {
        for (x, z) in [(-3.0, -3.0), (3.0, -3.0), (3.0, 3.0), (-3.0, 3.0)] {
            s += &format!("v {x} {y} {z}\n");
        }
    }
    // 1-4 bottom, 5-8 top (counter-clockwise seen from outside)
    s += &format!("vn {} {} {}\n", n_top.x, n_top.y, n_top.z);
    s += "vn 0 -1 0\nvn 0 0 -1\nvn 1 0 0\nvn 0 0 1\nvn -1 0 0\n";
    let faces = [
        ([5, 8, 7, 6], 1), // top (+y)
        ([1, 2, 3, 4], 2), // bottom
        ([1, 5, 6, 2], 3), // z = −3
        ([2, 6, 7, 3], 4), // x = +3
        ([3, 7, 8, 4], 5), // z = +3
        ([4, 8, 5, 1], 6), // x = −3
    ];
    for (q, n) in faces {
        s += &format!(
            "f {a}//{n} {b}//{n} {c}//{n}\nf {a}//{n} {c}//{n} {d}//{n}\n",
            a = q[0],
            b = q[1],
            c = q[2],
            d = q[3]
        );
    }
    s
}

/// The scene: camera on (0, 1, 1), light in direction `to_light` from the
/// origin, facing it; the slab is `slab` (a `[[shapes]]` body) with a coat
/// of `roughness`.
fn scene_text(to_light: Vec3, slab: &str, roughness: f32) -> String {
    let eye = Vec3::new(0.0, 1.0, 1.0).normalize() * DIST;
    let l = to_light.normalize() * DIST;
    // The quad faces +z; turning it by θ about x makes it face
    // (0, −sin θ, cos θ), which must be −to_light.
    let theta = (to_light.y).atan2(-to_light.z).to_degrees();
    format!(
        r#"
[camera]
look_from = [{ex}, {ey}, {ez}]
look_at = [0, 0, 0]
fov_y = 20
resolution = [{RES}, {RES}]

[render]
spp = 256
max_depth = 4
seed = 5

[materials.coat]
type = "subsurface"
albedo = [0, 0, 0]
dmfp = [1, 1, 1]
eta = {ETA}
specular = true
roughness = {roughness}

[materials.black]
type = "diffuse"
albedo = [0, 0, 0]

[[shapes]]
name = "light"
type = "quad"
material = "black"
emission = [{LE}, {LE}, {LE}]
scale = {HALF}
rotate = [[{theta}, 1, 0, 0]]
translate = [{lx}, {ly}, {lz}]

[[shapes]]
name = "slab"
material = "coat"
{slab}
"#,
        ex = eye.x,
        ey = eye.y,
        ez = eye.z,
        lx = l.x,
        ly = l.y,
        lz = l.z,
    )
}

/// Renders the scene in `dir` and checks that the highlight is at the
/// image centre with brightness F(cos θ)·Le and that nothing else is lit
/// brighter than `dark` × F·Le (0: not at all).
fn check_highlight(dir: &Path, text: &str, cos_i: f64, what: &str, dark: f32) {
    check_highlight_with(dir, text, cos_i, what, dark, &RenderOptions::default());
}

/// [`check_highlight`] rendered with `opts` (another integrator).
fn check_highlight_with(
    dir: &Path,
    text: &str,
    cos_i: f64,
    what: &str,
    dark: f32,
    opts: &RenderOptions,
) {
    let path = dir.join("coat.toml");
    std::fs::write(&path, text).unwrap();
    let scene = load_str(text, &path).unwrap();
    let f = fresnel(cos_i, ETA) as f32;
    for backend in common::backends() {
        let a = accel::build(&scene.meshes, backend).unwrap();
        let film = render(&scene, a.as_ref(), opts).unwrap().0;
        assert_eq!((film.width as usize, film.height as usize), (RES, RES));
        let c = RES / 2;
        let px = |x: usize, y: usize| film.pixels[y * RES + x];
        let mut centre = Vec3::ZERO;
        for y in c - 1..=c + 1 {
            for x in c - 1..=c + 1 {
                centre += px(x, y) / 9.0;
            }
        }
        // 9 × 256 Bernoulli(F) samples of Le: ~6 % standard error
        for k in 0..3 {
            assert!(
                (centre[k] / (f * LE) - 1.0).abs() < 0.3,
                "{what} {backend:?}: centre {centre} but F·Le = {}",
                f * LE
            );
        }
        // The mirror image of the light spans HALF / (2 DIST) radians on
        // either side of the centre; nothing beyond it may be lit.
        let px_per_rad = RES as f32 / 20f32.to_radians();
        let radius = HALF / (2.0 * DIST) * std::f32::consts::SQRT_2 * px_per_rad + 1.5;
        let mut lit = 0;
        for y in 0..RES {
            for x in 0..RES {
                let r = ((x as f32 - c as f32).powi(2) + (y as f32 - c as f32).powi(2)).sqrt();
                if px(x, y).max_element() > dark * f * LE {
                    lit += 1;
                    assert!(
                        r <= radius,
                        "{what} {backend:?}: pixel ({x}, {y}) lit, {r} px from the centre"
                    );
                }
            }
        }
        assert!(lit >= 9, "{what}: only {lit} pixels lit");
    }
}

#[test]
fn highlight_is_in_the_mirror_direction_of_a_flat_coat() {
    let dir = tempfile::tempdir().unwrap();
    let slab = "type = \"box\"\nscale = [3, 0.5, 3]\ntranslate = [0, -0.5, 0]";
    let text = scene_text(Vec3::new(0.0, 1.0, -1.0), slab, 0.0);
    check_highlight(
        dir.path(),
        &text,
        std::f64::consts::FRAC_1_SQRT_2,
        "flat box",
        0.0,
    );
    // the same through an OBJ whose shading normals are the geometric ones
    std::fs::write(dir.path().join("slab.obj"), slab_obj(Vec3::Y)).unwrap();
    let text = scene_text(
        Vec3::new(0.0, 1.0, -1.0),
        "type = \"obj\"\nfile = \"slab.obj\"",
        0.0,
    );
    check_highlight(
        dir.path(),
        &text,
        std::f64::consts::FRAC_1_SQRT_2,
        "flat obj",
        0.0,
    );
}

#[test]
fn highlight_follows_the_shading_normal() {
    let dir = tempfile::tempdir().unwrap();
    // shading normal tilted 10° towards the camera (+z)
    let a = 10f32.to_radians();
    let ns = Vec3::new(0.0, a.cos(), a.sin());
    std::fs::write(dir.path().join("slab.obj"), slab_obj(ns)).unwrap();
    let wo = Vec3::new(0.0, 1.0, 1.0).normalize();
    let wr = 2.0 * wo.dot(ns) * ns - wo;
    // 20° from the geometric mirror direction: far outside the light
    assert!(wr.dot(Vec3::new(0.0, 1.0, -1.0).normalize()) < 15f32.to_radians().cos());
    let text = scene_text(wr, "type = \"obj\"\nfile = \"slab.obj\"", 0.0);
    // The Fresnel split is taken at the geometric normal (cos 45°) or at
    // the shading normal (cos 35°); the two differ by less than the test's
    // tolerance, so either convention passes.
    let cos_g = std::f64::consts::FRAC_1_SQRT_2;
    let cos_s = wo.dot(ns) as f64;
    assert!((fresnel(cos_g, ETA) / fresnel(cos_s, ETA) - 1.0).abs() < 0.15);
    check_highlight(
        dir.path(),
        &text,
        0.5 * (cos_g + cos_s),
        "tilted shading normals",
        0.0,
    );
}

/// A nearly smooth rough coat (roughness 0.05, α = 0.0025: its lobe is
/// far narrower than the light) puts the highlight where the mirror does,
/// as bright (E ≈ Fr away from grazing), with the GGX tails lighting the
/// rest at under 5 % of it; on flat and tilted shading normals alike.
#[test]
fn nearly_smooth_rough_coat_puts_the_highlight_where_the_mirror_does() {
    let dir = tempfile::tempdir().unwrap();
    let slab = "type = \"box\"\nscale = [3, 0.5, 3]\ntranslate = [0, -0.5, 0]";
    let text = scene_text(Vec3::new(0.0, 1.0, -1.0), slab, 0.05);
    check_highlight(
        dir.path(),
        &text,
        std::f64::consts::FRAC_1_SQRT_2,
        "rough 0.05, flat box",
        0.05,
    );
    let a = 10f32.to_radians();
    let ns = Vec3::new(0.0, a.cos(), a.sin());
    std::fs::write(dir.path().join("slab.obj"), slab_obj(ns)).unwrap();
    let wo = Vec3::new(0.0, 1.0, 1.0).normalize();
    let wr = 2.0 * wo.dot(ns) * ns - wo;
    let text = scene_text(wr, "type = \"obj\"\nfile = \"slab.obj\"", 0.05);
    check_highlight(
        dir.path(),
        &text,
        wo.dot(ns) as f64,
        "rough 0.05, tilted shading normals",
        0.05,
    );
}

/// The random walk's diffuse boundary (`boundary = "diffuse"`) reflects
/// light arriving from outside as a mirror with probability Fr, like the
/// smooth coat: the same highlight, at the mirror direction about the
/// surface's normal (the walk's boundary is the geometric surface), with
/// nothing else lit above a tenth of it (A = 0: what the walk's medium and
/// its exit light sampling return there is far below the highlight).
#[test]
fn the_random_walks_diffuse_boundary_reflects_in_the_mirror_direction() {
    let dir = tempfile::tempdir().unwrap();
    let slab = "type = \"box\"\nscale = [3, 0.5, 3]\ntranslate = [0, -0.5, 0]";
    let text = scene_text(Vec3::new(0.0, 1.0, -1.0), slab, 0.0).replace(
        "specular = true\n",
        "specular = true\nboundary = \"diffuse\"\n",
    );
    assert!(text.contains("boundary"));
    let opts = RenderOptions {
        integrator: lucent::integrator::IntegratorKind::RandomWalk,
        ..Default::default()
    };
    check_highlight_with(
        dir.path(),
        &text,
        std::f64::consts::FRAC_1_SQRT_2,
        "random walk, diffuse boundary",
        0.1,
        &opts,
    );
}
