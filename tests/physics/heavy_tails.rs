//! Heavy tails on real meshes: the shipped scenes scenes/smooth-bunny.toml
//! (the Stanford bunny, smooth-shaded), scenes/thin-shapes.toml (a thin
//! leaf and a sharp-edged cube) and scenes/smooth-sphere.toml under one
//! small light, rendered small with the default estimator, two
//! independent runs of `SPP` samples a pixel. Two checks per scene:
//!
//! - at every pixel on the bodies the largest single sample, against the
//!   mean of the pixel's other samples, stays within `MAX_RATIO`: one
//!   sample at hundreds of times the others is a tail;
//! - relMSE×spp measured between the two runs (variance only, no
//!   reference needed) at `SPP` samples is not above its value at the
//!   first `FEW` samples of each run by more than `MAX_GROWTH`: with a
//!   heavy tail, few samples rarely meet the rare large ones and the
//!   figure grows with spp; without one it is flat.
//!
//! Caught: the smooth coat's caustic on the bunny (light the coat mirrors
//! from one part of the body into the lamp, found only through the entry
//! lobe's direction) when the coat is not regularized after a
//! non-specular vertex (`regularize = 0`: 691× and 0.28 → 1.10 with the
//! default pair at the camera vertex); docs/accuracy.md, "Real meshes".
//! `regularize = 0.2` (a narrow lobe still sampled by the coat) passes
//! with the pair: 192× and flat.
//! The test profile is optimized (`[profile.test]`), so the suite runs it
//! in a few seconds.

use std::path::{Path, PathBuf};

use lucent::accel::{self, Backend};
use lucent::geometry::Vec3;
use lucent::integrator::aov::NoAov;
use lucent::integrator::path::{radiance, Scratch};
use lucent::integrator::{Context, Counters, NoClock};
use lucent::sampling::{Draw, SampleRng};
use rayon::prelude::*;

/// Image width and height of the small renders.
const SIZE: u32 = 20;
/// Samples per pixel of each run.
const SPP: u64 = 256;
/// The first samples of each run that make the low-spp figure.
const FEW: u64 = 16;
/// relMSE's ε (as the study's metrics).
const EPS: f64 = 0.01;

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

/// One pixel's two runs: the sums of their first FEW and of all SPP
/// samples, the largest sample (channel sum) and the sum of all samples'
/// channel sums.
#[derive(Clone, Copy, Default)]
struct PixelRuns {
    few: [Vec3; 2],
    all: [Vec3; 2],
    max: f64,
    total: f64,
}

/// The two runs of pixel (x, y).
fn pixel(ctx: &Context, x: u32, y: u32) -> PixelRuns {
    let mut scratch = Scratch::default();
    let mut counters = Counters::default();
    let mut p = PixelRuns::default();
    for run in 0..2 {
        for s in 0..SPP {
            let mut rng = SampleRng::new(3 + run as u64, (y * SIZE + x) as u64, s);
            let [jx, jy] = rng.uniform2_packed();
            let ray = ctx.scene.camera.ray(x as f32 + jx, y as f32 + jy);
            let l =
                radiance::<_, NoClock>(ctx, ray, &mut rng, &mut scratch, &mut counters, &mut NoAov);
            // one sample may be negative (the control variate's term);
            // the pixel's mean may not
            assert!(l.is_finite(), "pixel ({x}, {y}): {l:?}");
            if s < FEW {
                p.few[run] += l;
            }
            p.all[run] += l;
            let v = l.element_sum() as f64;
            p.max = p.max.max(v);
            p.total += v;
        }
    }
    p
}

/// What the checks read from a scene's renders.
struct Tails {
    /// The largest sample over the mean of its pixel's others, and where.
    worst_ratio: (f64, (u32, u32)),
    /// relMSE×spp between the two runs at FEW and at SPP samples.
    rel_few: f64,
    rel_all: f64,
}

fn tails(scene: &lucent::scene::Scene) -> Tails {
    let accel = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let ctx = Context::new(scene, accel.as_ref());
    let pixels: Vec<((u32, u32), PixelRuns)> = (0..SIZE * SIZE)
        .into_par_iter()
        .map(|i| ((i % SIZE, i / SIZE), pixel(&ctx, i % SIZE, i / SIZE)))
        .collect();
    let n = 2 * SPP;
    let mut worst_ratio = (0.0, (0, 0));
    let (mut rel_few, mut rel_all) = (0.0, 0.0);
    for &(xy, p) in &pixels {
        let others = (p.total - p.max) / (n - 1) as f64;
        if p.total / n as f64 >= 0.02 && others > 0.0 && p.max / others > worst_ratio.0 {
            worst_ratio = (p.max / others, xy);
        }
        // the reference: both runs' mean
        let r = (p.all[0] + p.all[1]) / n as f32;
        for c in 0..3 {
            let d = (r[c] as f64).powi(2) + EPS;
            let few = (p.few[0][c] - p.few[1][c]) as f64 / FEW as f64;
            let all = (p.all[0][c] - p.all[1][c]) as f64 / SPP as f64;
            rel_few += few * few / (2.0 * d);
            rel_all += all * all / (2.0 * d);
        }
    }
    let m = (3 * pixels.len()) as f64;
    Tails {
        worst_ratio,
        rel_few: rel_few / m * FEW as f64,
        rel_all: rel_all / m * SPP as f64,
    }
}

#[test]
fn no_sample_outweighs_its_pixel_and_the_error_is_flat_in_spp_on_real_meshes() {
    for name in [
        "smooth-bunny.toml",
        "thin-shapes.toml",
        "smooth-sphere.toml",
    ] {
        let t = tails(&scene(name));
        let (ratio, (x, y)) = t.worst_ratio;
        println!(
            "{name}: largest sample {ratio:.1}× its pixel's others at ({x}, {y}); \
             relMSE×spp {:.4} at {FEW} spp, {:.4} at {SPP}",
            t.rel_few, t.rel_all
        );
        assert!(
            ratio < MAX_RATIO,
            "{name}: one sample at ({x}, {y}) is {ratio:.1}× the mean of the pixel's others"
        );
        assert!(
            t.rel_all < MAX_GROWTH * t.rel_few,
            "{name}: relMSE×spp {:.4} at {SPP} spp against {:.4} at {FEW}",
            t.rel_all,
            t.rel_few
        );
    }
}

/// The bound on one sample against its pixel's others: above what the
/// default gives on the three scenes, below the caustic's. The largest
/// sample of a render is itself noisy: on the bunny the default gives
/// 270×, 36× and 73× with the runs' seeds at 3, 13 and 23, one plain probe
/// 96×, 213× and 70×, the mirror coat (`regularize = 0`) 691× at 3
/// (docs/journal.md, 2026-12-07 and 2026-12-08).
const MAX_RATIO: f64 = 400.0;
/// How much relMSE×spp may grow from FEW to SPP samples: each figure is a
/// mean over a few hundred pixels of squared differences, a few per cent
/// of noise each; the caustic doubles it.
const MAX_GROWTH: f64 = 1.5;
