//! Heavy tails on real meshes: the shipped scenes scenes/smooth-bunny.toml
//! (the Stanford bunny, smooth-shaded) and scenes/thin-shapes.toml (a thin
//! leaf and a sharp-edged cube) under one small light, rendered small with
//! the default estimator. At every pixel on the bodies the largest single
//! sample, against the mean of the pixel's other samples, must stay within
//! a bound: one sample at hundreds of times the others is the tail that
//! makes relMSE×spp grow with spp.
//!
//! Ignored: it fails today on the bunny (234×). The tail is not the
//! probes': light the smooth coat mirrors from one part of the bunny into
//! the lamp (entry lobe → coat at grazing incidence, Fr near 1 → lamp) is a
//! caustic a path tracer finds only through the entry lobe's direction
//! (docs/accuracy.md, "Real meshes"). With `specular = false` both scenes
//! pass (68× and 97×), and still pass with the coat off and
//! `axes = "normal"` or a tangent floor ε_min of 0.0002: at this size the
//! probe weights alone make no tail. Run it with `--ignored` after a
//! change to the coat or the path's caustics.

use std::path::{Path, PathBuf};

use lucent::accel::{self, Backend};
use lucent::integrator::aov::NoAov;
use lucent::integrator::path::{radiance, Scratch};
use lucent::integrator::{Context, Counters, NoClock};
use lucent::sampling::{Draw, SampleRng};

/// Image width and height of the small renders.
const SIZE: u32 = 32;
/// Samples per pixel.
const SPP: u64 = 48;

/// The shipped scene `name` at SIZE × SIZE.
fn scene(name: &str) -> lucent::scene::Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text.replace(
        "resolution = [256, 256]",
        &format!("resolution = [{SIZE}, {SIZE}]"),
    );
    assert!(
        text.contains(&format!("[{SIZE}, {SIZE}]")),
        "{name}: resolution"
    );
    lucent::scene::load_str(&text, Path::new(&path)).unwrap()
}

/// Over the pixels on the bodies (mean above 0.02 per channel sum), the
/// largest ratio of one sample (channel sum) to the mean of the pixel's
/// other samples, and that pixel.
fn worst_sample_ratio(scene: &lucent::scene::Scene) -> (f64, (u32, u32)) {
    let accel = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let ctx = Context::new(scene, accel.as_ref());
    let mut scratch = Scratch::default();
    let mut counters = Counters::default();
    let mut worst = (0.0, (0, 0));
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (mut sum, mut max) = (0.0f64, 0.0f64);
            for s in 0..SPP {
                let mut rng = SampleRng::new(3, (y * SIZE + x) as u64, s);
                let [jx, jy] = rng.uniform2_packed();
                let ray = ctx.scene.camera.ray(x as f32 + jx, y as f32 + jy);
                let l = radiance::<_, NoClock>(
                    &ctx,
                    ray,
                    &mut rng,
                    &mut scratch,
                    &mut counters,
                    &mut NoAov,
                );
                let v = l.element_sum() as f64;
                // one sample may be negative (the control variate's term);
                // the pixel's mean may not
                assert!(v.is_finite(), "pixel ({x}, {y}): {l:?}");
                sum += v;
                max = max.max(v);
            }
            let others = (sum - max) / (SPP - 1) as f64;
            if sum / (SPP as f64) < 0.02 || others <= 0.0 {
                continue;
            }
            let ratio = max / others;
            if ratio > worst.0 {
                worst = (ratio, (x, y));
            }
        }
    }
    worst
}

#[test]
#[ignore = "the smooth coat's caustic on the bunny (docs/accuracy.md, \"Real meshes\")"]
fn no_sample_outweighs_its_pixel_on_real_meshes() {
    for name in ["smooth-bunny.toml", "thin-shapes.toml"] {
        let (ratio, (x, y)) = worst_sample_ratio(&scene(name));
        println!(
            "{name}: largest sample {ratio:.1}× its pixel's other samples' mean at ({x}, {y})"
        );
        assert!(
            ratio < MAX_RATIO,
            "{name}: one sample at ({x}, {y}) is {ratio:.1}× the mean of the pixel's others"
        );
    }
}

/// The bound: above what the estimator gives without the coat's caustic
/// (68× on the bunny, 97× on the thin shapes; docs/accuracy.md, "Real
/// meshes"), below the caustic's 234×.
const MAX_RATIO: f64 = 150.0;
