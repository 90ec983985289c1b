//! The same scene rendered on Embree and on our BVH. Both trace identical
//! sample streams (the random numbers depend only on seed, pixel and sample
//! index), so the images may differ only where the two backends' floating
//! point answers differ enough to send a path elsewhere: the per-channel
//! image means must agree within Monte-Carlo noise, and nearly every pixel
//! must agree to rounding.
//!
//! Run on Embree 3 and on Embree 4 (where this process has it; required
//! under scripts/test.sh, which sets `LUCENT_REQUIRE_EMBREE4`). Built only
//! with the `embree` feature (`#[cfg]` in tests/accel/main.rs).

use std::path::Path;

use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::render::{render, RenderOptions};
use lucent::scene::{self, Camera};

fn render_with(scene: &scene::Scene, backend: Backend) -> Film {
    let a = accel::build(&scene.meshes, backend).unwrap();
    render(
        scene,
        a.as_ref(),
        &RenderOptions {
            spp: Some(4),
            seed: Some(5),
            ..Default::default()
        },
    )
    .unwrap()
    .0
}

fn compare(name: &str, which: Backend) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let mut scene = scene::load(&path).unwrap();
    let c = &scene.camera;
    scene.camera = Camera::new(c.look_from, c.look_at, c.up, c.fov_y, 160, 120);
    let bvh = render_with(&scene, Backend::Bvh);
    let embree = render_with(&scene, which);
    let n = bvh.pixels.len() as f64;
    for ch in 0..3 {
        let (mut mb, mut me, mut var) = (0.0, 0.0, 0.0);
        for (a, b) in bvh.pixels.iter().zip(&embree.pixels) {
            mb += a[ch] as f64;
            me += b[ch] as f64;
        }
        mb /= n;
        me /= n;
        for a in &bvh.pixels {
            var += (a[ch] as f64 - mb).powi(2);
        }
        let se = (var / (n - 1.0) / n).sqrt();
        // independent renders would differ by ~√2·se; these share streams
        assert!(
            (mb - me).abs() < 3.0 * se,
            "{name} ch{ch}: bvh {mb} {} {me} (se {se})",
            which.name()
        );
    }
    let same = bvh
        .pixels
        .iter()
        .zip(&embree.pixels)
        .filter(|(a, b)| (**a - **b).abs().max_element() <= 1e-3 * a.max_element().max(1e-3))
        .count();
    assert!(
        same as f64 > 0.95 * n,
        "{name} on {}: only {same} of {n} pixels agree",
        which.name()
    );
}

/// Embree 4 if this process can load it; else `None` (skipped, saying
/// so), unless `LUCENT_REQUIRE_EMBREE4` is set, where that fails the test.
fn embree4() -> Option<Backend> {
    match Backend::Embree4.resolve() {
        Ok(b) => Some(b),
        Err(e) if std::env::var_os("LUCENT_REQUIRE_EMBREE4").is_none() => {
            eprintln!("Embree 4 not tested: {e}");
            None
        }
        Err(e) => panic!("LUCENT_REQUIRE_EMBREE4 is set but {e}"),
    }
}

#[test]
fn cornell_box_matches_across_backends() {
    compare("cornell.toml", Backend::Embree3);
}

#[test]
fn marble_bunny_matches_across_backends() {
    compare("marble-bunny.toml", Backend::Embree3);
}

#[test]
fn cornell_box_matches_across_backends_on_embree4() {
    if let Some(b) = embree4() {
        compare("cornell.toml", b);
    }
}

#[test]
fn marble_bunny_matches_across_backends_on_embree4() {
    if let Some(b) = embree4() {
        compare("marble-bunny.toml", b);
    }
}
