//! Energy of the subsurface material's coat, smooth and rough
//! (`docs/bssrdf.md` §6), through the scene loader and the path tracer.
//!
//! A large, thick, flat slab (profile renormalized, so the medium alone
//! reflects exactly A) under a uniform environment L = 1, seen at μo =
//! cos θo = 0.25 through a narrow camera, so every pixel sees the same
//! angle. The coat reflects E(μo) (Fr(μo) for the smooth coat) and passes
//! 1 − E(μo) to the medium, which reflects A of it: each pixel converges to
//!
//!   E(μo) + (1 − E(μo)) A,
//!
//! and to exactly 1 for A = 1 (a white furnace), at every roughness. Without
//! `specular` the reflected part is lost: (1 − E(μo)) A. Grazing view makes
//! E differ from Fr by several per cent for rough coats, so weighting the
//! medium by 1 − Fr instead of 1 − E would fail the furnace.
//!
//! At the camera vertex the smooth coat is split (mirror and medium both
//! followed); deeper hits, and rough coats everywhere, choose one (the
//! rough coat with light sampling at xo). A second furnace looks at a
//! white diffuse panel above the slab, so every coated hit there is at
//! depth ≥ 1.

use crate::common;

use std::path::Path;

use common::{backends, mean_se};
use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::materials::Material;
use lucent::render::{render, RenderOptions};
use lucent::scene::{load_str, Scene};

const ETA: f32 = 1.5;
const MU_O: f32 = 0.25;

/// The slab scene: coat `roughness`, medium albedo `a`, `specular`; with
/// `panel`, the camera looks at a white diffuse panel above the slab
/// instead of at the slab.
fn scene(roughness: f32, a: f32, specular: bool, panel: bool) -> Scene {
    let sin = (1.0 - MU_O * MU_O).sqrt();
    let (eye, look_at, fov) = if panel {
        // the panel at (0, 4, 0) faces (0, −0.707, 0.707); the camera 3
        // units along that normal sees nothing else
        ("[0.0, 1.8787, 2.1213]".to_string(), "[0.0, 4.0, 0.0]", 20.0)
    } else {
        (
            format!("[0.0, {}, {}]", 10.0 * MU_O, 10.0 * sin),
            "[0.0, 0.0, 0.0]",
            1.0,
        )
    };
    let text = format!(
        r#"
units_per_mm = 1.0

[camera]
look_from = {eye}
look_at = {look_at}
fov_y = {fov}
resolution = [24, 24]

[render]
spp = 256
max_depth = 6
seed = 3

[environment]
radiance = [1.0, 1.0, 1.0]

[materials.slab]
type = "subsurface"
albedo = [{a}, {a}, {a}]
dmfp = [0.2, 0.2, 0.2]
eta = {ETA}
renormalize = true
specular = {specular}
roughness = {roughness}

[materials.white]
type = "diffuse"
albedo = [1.0, 1.0, 1.0]

[[shapes]]
name = "slab"
type = "box"
material = "slab"
scale = [50.0, 5.0, 50.0]
translate = [0.0, -5.0, 0.0]
{panel}
"#,
        panel = if panel {
            "[[shapes]]\nname = \"panel\"\ntype = \"quad\"\nmaterial = \"white\"\n\
             rotate = [[45, 1, 0, 0]]\ntranslate = [0, 4, 0]\n"
        } else {
            ""
        }
    );
    load_str(&text, Path::new("coat.toml")).unwrap()
}

fn render_film(scene: &Scene, backend: Backend) -> Film {
    let a = accel::build(&scene.meshes, backend).unwrap();
    render(scene, a.as_ref(), &RenderOptions::default())
        .unwrap()
        .0
}

/// What the coat reflects at μo: E from the material's table, or Fr.
fn coat_albedo(scene: &Scene) -> f32 {
    let ss = scene
        .materials
        .iter()
        .find_map(|m| match m {
            Material::Subsurface(ss) => Some(ss),
            _ => None,
        })
        .expect("the slab's material");
    match ss.rough_coat() {
        Some(c) => c.albedo(MU_O),
        None => lucent::fresnel::dielectric(MU_O, ETA),
    }
}

fn check(what: &str, scene: &Scene, expected: f32, tol: f64) {
    for backend in backends() {
        let (mean, se) = mean_se(&render_film(scene, backend));
        eprintln!("{what} {backend:?}: mean {mean:.4?} se {se:.5?}, expected {expected:.4}");
        for c in 0..3 {
            let err = (mean[c] - expected as f64).abs() / expected as f64;
            assert!(
                err < tol,
                "{what} {backend:?}: mean {} vs {expected} ({:.2} %)",
                mean[c],
                100.0 * err
            );
            assert!(3.0 * se[c] < tol * expected as f64, "{what}: too noisy");
        }
    }
}

#[test]
fn coated_white_slab_is_a_white_furnace_at_every_roughness() {
    for roughness in [0.0, 0.3, 0.7, 1.0] {
        let s = scene(roughness, 1.0, true, false);
        check(&format!("roughness {roughness}, A = 1"), &s, 1.0, 0.01);
    }
}

#[test]
fn coated_slab_reflects_coat_albedo_plus_the_transmitted_part_times_a() {
    for roughness in [0.0, 0.5] {
        let a = 0.5;
        let s = scene(roughness, a, true, false);
        let e = coat_albedo(&s);
        check(
            &format!("roughness {roughness}, A = {a}"),
            &s,
            e + (1.0 - e) * a,
            0.01,
        );
        let s = scene(roughness, a, false, false);
        let e = coat_albedo(&s);
        check(
            &format!("roughness {roughness}, A = {a}, no specular"),
            &s,
            (1.0 - e) * a,
            0.01,
        );
    }
    // the rough coat reflects visibly less than a mirror at this angle
    let fr = lucent::fresnel::dielectric(MU_O, ETA);
    let e = coat_albedo(&scene(0.5, 0.5, true, false));
    assert!(e < 0.9 * fr, "E {e} vs Fr {fr}");
}

/// Every coated hit here is at depth ≥ 1, where even the smooth coat and
/// the medium are chosen between instead of split.
#[test]
fn white_furnace_holds_where_coated_hits_choose() {
    for roughness in [0.0, 0.4] {
        let s = scene(roughness, 1.0, true, true);
        check(&format!("panel, roughness {roughness}"), &s, 1.0, 0.01);
    }
}

/// A closed box around the scene, its faces turned inward and emitting
/// radiance 1: inside, every direction sees radiance 1, as under the
/// uniform environment, but here the light is an area light, so the rough
/// coat's light sampling and its MIS with the coat's lobe sampling carry
/// the reflection. Their weights must sum to 1 for every direction (both
/// strategies using the same pdf of the coat lobe), or the coat's
/// reflection is off.
#[test]
fn the_rough_coat_under_an_enclosing_area_light_reflects_as_under_the_environment() {
    let dir = tempfile::tempdir().unwrap();
    // the 8 corners of [-h, h]³ and the 6 faces, each as two triangles
    // wound so that their normal points to the centre
    let h = 200.0f32;
    let corner = |i: usize| {
        [
            if i & 1 == 0 { -h } else { h },
            if i & 2 == 0 { -h } else { h },
            if i & 4 == 0 { -h } else { h },
        ]
    };
    let mut obj = String::new();
    for i in 0..8 {
        let c = corner(i);
        obj += &format!("v {} {} {}\n", c[0], c[1], c[2]);
    }
    for (axis, side) in [(0, 0), (0, 1), (1, 0), (1, 1), (2, 0), (2, 1)] {
        // the face's corners in cyclic order
        let (a, b) = (
            [1usize, 2, 4][(axis + 1) % 3],
            [1usize, 2, 4][(axis + 2) % 3],
        );
        let base = side * [1usize, 2, 4][axis];
        let mut q = [base, base + a, base + a + b, base + b];
        // (q1 − q0) × (q3 − q0) has the sign of the axis for this order;
        // inward is −sign at side 1, +sign at side 0
        if side == 1 {
            q.reverse();
        }
        obj += &format!(
            "f {} {} {}\nf {} {} {}\n",
            q[0] + 1,
            q[1] + 1,
            q[2] + 1,
            q[0] + 1,
            q[2] + 1,
            q[3] + 1
        );
    }
    std::fs::write(dir.path().join("dome.obj"), obj).unwrap();
    let base = scene(0.5, 0.5, true, false);
    let e = coat_albedo(&base);
    let text = format!(
        r#"
units_per_mm = 1.0
[camera]
look_from = [0.0, {y}, {z}]
look_at = [0.0, 0.0, 0.0]
fov_y = 1.0
resolution = [24, 24]
[render]
spp = 256
max_depth = 6
seed = 3
[materials.slab]
type = "subsurface"
albedo = [0.5, 0.5, 0.5]
dmfp = [0.2, 0.2, 0.2]
eta = {ETA}
renormalize = true
roughness = 0.5
[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]
[[shapes]]
name = "slab"
type = "box"
material = "slab"
scale = [50.0, 5.0, 50.0]
translate = [0.0, -5.0, 0.0]
[[shapes]]
name = "dome"
type = "obj"
file = "dome.obj"
material = "lamp"
emission = [1.0, 1.0, 1.0]
"#,
        y = 10.0 * MU_O,
        z = 10.0 * (1.0 - MU_O * MU_O).sqrt(),
    );
    let path = dir.path().join("dome.toml");
    std::fs::write(&path, &text).unwrap();
    let s = lucent::scene::load(&path).unwrap();
    assert_eq!(
        coat_albedo(&s),
        e,
        "the same coat as the environment's scene"
    );
    check(
        "rough coat under an enclosing light",
        &s,
        e + (1.0 - e) * 0.5,
        0.01,
    );
}
