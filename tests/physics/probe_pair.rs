//! The two variance reductions of the probe estimator at the camera vertex
//! on a smooth translucent sphere lit from the side, where the light at the
//! entry point changes across the profile: the antithetic probe pair
//! (`integrator::path`, `PAIR_DEPTH`; the default, so the scene here asks
//! for one plain probe where it compares against one) and the plane
//! control variate (`control_variate = true`,
//! `integrator::control_variate`). Each must
//! (a) leave the mean
//! where one plain probe puts it — both are unbiased estimators of the same
//! integral — and (b) cut the per-sample variance of the lit body to well
//! below one probe's (docs/accuracy.md). Hand-made breaks that (b) catches:
//! the pair's twin at the *same* angle (two copies of one entry point;
//! ratio 0.97 against 0.45). The control variate (a choice between a
//! probe and its mirror as the plane model's light at each asks, never a
//! subtraction): ratio 0.64 (bound 0.7); with the pair it changes nothing (the
//! pair traces both mirrors).

use std::path::Path;

use lucent::accel::{self, Backend};
use lucent::integrator::aov::NoAov;
use lucent::integrator::path::{radiance, Scratch};
use lucent::integrator::{Context, Counters, NoClock};
use lucent::materials::Material;
use lucent::sampling::{Draw, SampleRng};

const SCENE: &str = r#"
units_per_mm = 0.1

[camera]
look_from = [0.0, 0.0, 4.4]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0
resolution = [32, 32]

[render]
max_depth = 8

[environment]
radiance = [0.03, 0.03, 0.03]

[materials.marble]
type = "subsurface"
preset = "marble"
MARBLE_OPTIONS

[materials.lamp]
type = "diffuse"
albedo = [0.0, 0.0, 0.0]

[[shapes]]
name = "light"
type = "quad"
material = "lamp"
emission = [50.0, 50.0, 50.0]
scale = [0.4, 0.4, 1]
rotate = [[-135, 0, 1, 0]]
translate = [3.0, 0.0, 3.0]

[[shapes]]
name = "ball"
type = "sphere"
material = "marble"
subdivisions = 4
"#;

/// The scene with `options` added to the marble's material.
fn scene(options: &str) -> lucent::scene::Scene {
    lucent::scene::load_str(
        &SCENE.replace("MARBLE_OPTIONS", options),
        Path::new("probe_pair.toml"),
    )
    .unwrap()
}

/// Per channel mean and variance of `n` samples at pixel (x, y) of `scene`.
fn stats_of(scene: &lucent::scene::Scene, x: u32, y: u32, n: u64) -> ([f64; 3], [f64; 3]) {
    let accel = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let ctx = Context::new(scene, accel.as_ref());
    pixel_stats(&ctx, x, y, n)
}

/// Per channel mean and variance of `n` samples at pixel (x, y).
fn pixel_stats(ctx: &Context, x: u32, y: u32, n: u64) -> ([f64; 3], [f64; 3]) {
    let mut scratch = Scratch::default();
    let mut counters = Counters::default();
    let (mut s1, mut s2) = ([0f64; 3], [0f64; 3]);
    for s in 0..n {
        let mut rng = SampleRng::new(7, (y * 32 + x) as u64, s);
        let [jx, jy] = rng.uniform2_packed();
        let ray = ctx.scene.camera.ray(x as f32 + jx, y as f32 + jy);
        let l = radiance::<_, NoClock>(ctx, ray, &mut rng, &mut scratch, &mut counters, &mut NoAov);
        for c in 0..3 {
            s1[c] += l[c] as f64;
            s2[c] += (l[c] as f64).powi(2);
        }
    }
    let nf = n as f64;
    let mean = s1.map(|v| v / nf);
    let var = std::array::from_fn(|c| (s2[c] / nf - mean[c] * mean[c]) * nf / (nf - 1.0));
    (mean, var)
}

/// Each lit-body pixel's mean under `test` equals its mean under `base`
/// (within 5 standard errors, per channel), and the ratio of their
/// relative variances summed over the pixels, `test` over `base`. The
/// pixels are on the right half of the sphere, all lit (the light is 45°
/// to the right of the camera): from facing the camera to near the rim.
fn lit_body_variance_ratio(
    test: &lucent::scene::Scene,
    base: &lucent::scene::Scene,
    what: &str,
) -> f64 {
    let n = 3000;
    let pixels: Vec<(u32, u32)> = (17..27).flat_map(|x| [(x, 14), (x, 18)]).collect();
    let (mut var_test, mut var_base) = (0.0, 0.0);
    for &(x, y) in &pixels {
        let (m2, v2) = stats_of(test, x, y, n);
        let (m1, v1) = stats_of(base, x, y, n);
        for c in 0..3 {
            assert!(
                m1[c] > 0.05,
                "pixel ({x}, {y}) is not on the lit body: {m1:?}"
            );
            // the same integral: means within 5 standard errors
            let se = ((v1[c] + v2[c]) / n as f64).sqrt();
            assert!(
                (m1[c] - m2[c]).abs() < 5.0 * se,
                "pixel ({x}, {y}) ch{c}: {what} {} vs {} (se {se})",
                m2[c],
                m1[c]
            );
            var_test += v2[c] / (m1[c] * m1[c]);
            var_base += v1[c] / (m1[c] * m1[c]);
        }
    }
    let ratio = var_test / var_base;
    println!("relative variance: {what} {var_test:.3}, against {var_base:.3}, ratio {ratio:.3}");
    ratio
}

#[test]
fn the_pair_keeps_the_mean_and_cuts_the_lit_bodys_variance() {
    // (the control variate off in both: the pair alone against one probe)
    let pair = scene("control_variate = false\nprobe_pair = true");
    let one = scene("control_variate = false\nprobe_pair = false");
    let ratio = lit_body_variance_ratio(&pair, &one, "pair");
    assert!(
        ratio < 0.6,
        "the pair's variance is {ratio:.3} of one probe's"
    );
}

#[test]
fn the_control_variate_keeps_the_mean_and_cuts_the_lit_bodys_variance() {
    let default = scene("");
    let ss = default
        .materials
        .iter()
        .find_map(|m| match m {
            Material::Subsurface(ss) => Some(ss),
            _ => None,
        })
        .unwrap();
    assert_eq!(
        (ss.control_variate(), ss.probe_pair()),
        (false, true),
        "the pair, without the control variate, is the default"
    );
    // (the pair off in both: the control variate alone against one probe)
    let one = scene("probe_pair = false");
    let cv = scene("control_variate = true\nprobe_pair = false");
    let ratio = lit_body_variance_ratio(&cv, &one, "control variate");
    assert!(
        ratio < 0.7,
        "the control variate's variance is {ratio:.3} of one probe's"
    );
}

#[test]
fn the_control_variate_leaves_the_pair_as_it_is() {
    // the plane model chooses between a probe and its mirror; the pair
    // traces both, so with the pair the model draws nothing and changes
    // not one sample (module docs of integrator::control_variate)
    let samples = |options: &str| {
        let s = scene(options);
        let accel = accel::build(&s.meshes, Backend::Bvh).unwrap();
        let ctx = Context::new(&s, accel.as_ref());
        [(20u32, 14u32), (24, 18)].map(|(x, y)| pixel_stats(&ctx, x, y, 64))
    };
    assert_eq!(
        samples("control_variate = true\nprobe_pair = true"),
        samples("control_variate = false\nprobe_pair = true")
    );
}

#[test]
fn the_pair_keeps_the_mean_where_its_twin_often_misses() {
    // The marble at 1 unit per mm: the profile (d ≈ 0.9 units) is as wide
    // as the sphere (radius 1), so one probe of a pair often finds the
    // sphere and its twin, across xo, does not; that probe then carries
    // the pair's estimate alone, with weight ½ (`entries`). The pair's
    // pixel means must still be one probe's.
    let text = |options: &str| {
        SCENE
            .replace("units_per_mm = 0.1", "units_per_mm = 1.0")
            .replace("MARBLE_OPTIONS", options)
    };
    let load = |options: &str| {
        lucent::scene::load_str(&text(options), Path::new("probe_pair.toml")).unwrap()
    };
    let pair = load("control_variate = false\nprobe_pair = true");
    let one = load("control_variate = false");
    let n = 4000;
    for &(x, y) in &[(16, 16), (20, 14), (23, 18), (12, 16)] {
        let (m2, v2) = stats_of(&pair, x, y, n);
        let (m1, v1) = stats_of(&one, x, y, n);
        for c in 0..3 {
            assert!(m1[c] > 0.0, "pixel ({x}, {y}) is black: {m1:?}");
            let se = ((v1[c] + v2[c]) / n as f64).sqrt();
            assert!(
                (m1[c] - m2[c]).abs() < 5.0 * se,
                "pixel ({x}, {y}) ch{c}: pair {} vs one probe {} (se {se})",
                m2[c],
                m1[c]
            );
        }
    }
}

/// The curvature the probe axes read on a smooth sphere of radius ρ is
/// 1/ρ on every triangle, whether the mesh has the render's cache (a
/// subsurface material: `MeshCurvature::axes`) or not (the per-hit
/// `exit_curvature`): the axis probabilities are chosen for the surface's
/// real bending, not a fixed scale.
#[test]
fn probe_axes_read_the_curvature_of_the_surface() {
    let text = SCENE.replace("MARBLE_OPTIONS", "").replace(
        "subdivisions = 4\n",
        "subdivisions = 3\nscale = [3.0, 3.0, 3.0]\n\n[[shapes]]\nname = \"plaster\"\n\
         type = \"sphere\"\nmaterial = \"lamp\"\nsubdivisions = 3\nscale = [0.5, 0.5, 0.5]\n\
         translate = [0.0, 5.0, 0.0]\n",
    );
    let scene = lucent::scene::load_str(&text, Path::new("curvature.toml")).unwrap();
    let accel = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let ctx = Context::new(&scene, accel.as_ref());
    let mut checked = [0; 2];
    for (geom, (mesh, object)) in scene.meshes.iter().zip(&scene.objects).enumerate() {
        let (radius, cached) = match (&scene.materials[object.material], object.name.as_str()) {
            (Material::Subsurface(_), "ball") => (3.0, 0),
            (_, "plaster") => (0.5, 1),
            _ => continue,
        };
        assert_eq!(ctx.curvature[geom].is_some(), cached == 0);
        for prim in 0..mesh.triangle_count() as u32 {
            let [a, b, c] = mesh.triangle(prim);
            let k = ctx.axes_curvature(geom as u32, prim, (a + b + c) / 3.0);
            assert!(
                (k * radius - 1.0).abs() < 0.1,
                "sphere of radius {radius}, triangle {prim}: κ = {k}"
            );
            checked[cached] += 1;
        }
    }
    assert!(checked[0] > 0 && checked[1] > 0, "{checked:?}");
}

/// The control variate is drawn only where it can act (module docs of
/// `integrator::control_variate`): at the camera vertex, under an area
/// light. Where it cannot — no area light, or a vertex at or below the
/// context's `cv_depth` — switching it on changes not one sample: the same
/// randoms, rays and radiance as with it off. Where it can, it does change
/// the samples (else this test would prove nothing).
#[test]
fn the_control_variate_is_drawn_only_at_the_camera_vertex_under_an_area_light() {
    let pixels = [(20u32, 14u32), (24, 18), (16, 16)];
    let samples = |scene: &lucent::scene::Scene, cv_depth: Option<u32>| {
        let accel = accel::build(&scene.meshes, Backend::Bvh).unwrap();
        let mut ctx = Context::new(scene, accel.as_ref());
        if let Some(d) = cv_depth {
            ctx.cv_depth = d;
        }
        pixels.map(|(x, y)| pixel_stats(&ctx, x, y, 64))
    };
    // one probe: with the pair the model has nothing to choose
    let lit_on = scene("control_variate = true\nprobe_pair = false");
    let lit_off = scene("control_variate = false\nprobe_pair = false");
    assert_ne!(
        samples(&lit_on, None),
        samples(&lit_off, None),
        "the control variate changed nothing where it applies"
    );
    assert_eq!(
        samples(&lit_on, Some(0)),
        samples(&lit_off, Some(0)),
        "drawn at a vertex at cv_depth"
    );
    let dark = |options: &str| {
        let text = SCENE
            .replace("MARBLE_OPTIONS", options)
            .replace("emission = [50.0, 50.0, 50.0]\n", "");
        lucent::scene::load_str(&text, Path::new("no_area_light.toml")).unwrap()
    };
    let (dark_on, dark_off) = (
        dark("control_variate = true\nprobe_pair = false"),
        dark("control_variate = false\nprobe_pair = false"),
    );
    assert!(
        !Context::new(
            &dark_on,
            accel::build(&dark_on.meshes, Backend::Bvh)
                .unwrap()
                .as_ref()
        )
        .plan
        .area_lights
    );
    assert_eq!(
        samples(&dark_on, None),
        samples(&dark_off, None),
        "drawn without an area light"
    );
}
