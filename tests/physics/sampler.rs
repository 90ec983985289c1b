//! The samplers (docs/accuracy.md, "Low-discrepancy sampling"): the
//! sequence's error falls faster than N^−1/2 on smooth integrands, its
//! renders are bitwise the same for any thread count, and
//! the `random` sampler's pixels are the pseudo-random stream's.

use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::materials::estimator_options::Assignments;
use lucent::render::{render, RenderOptions};
use lucent::sampling::{Draw, Rng, SampleRng, SamplerKind};
use lucent::scene::Scene;

/// A smooth function on [0, 1)² and its integral.
fn smooth(u: [f32; 2]) -> f64 {
    let (x, y) = (u[0] as f64, u[1] as f64);
    x.exp() * (std::f64::consts::PI * y).sin() + x * y
}
const SMOOTH_INTEGRAL: f64 = (std::f64::consts::E - 1.0) * 2.0 / std::f64::consts::PI + 0.25;

/// RMS error over `pixels` pixels of the mean of `smooth` over samples
/// 0..n, each sample's point the draw `draw` makes of its `SampleRng`.
fn rms_error(
    sampler: SamplerKind,
    n: u32,
    pixels: u64,
    draw: impl Fn(&mut SampleRng) -> [f32; 2],
) -> f64 {
    let seed_key = Rng::seed_key(3);
    let se: f64 = (0..pixels)
        .map(|p| {
            let key = Rng::pixel_key(seed_key, p);
            let mean = (0..n)
                .map(|s| smooth(draw(&mut SampleRng::with_sampler(sampler, key, s))))
                .sum::<f64>()
                / n as f64;
            (mean - SMOOTH_INTEGRAL).powi(2)
        })
        .sum();
    (se / pixels as f64).sqrt()
}

/// From 16 to 1024 samples (64×) the pseudo-random error falls ~8×
/// (N^−1/2); the sequence's must fall at least 64× (N^−1 or faster; an
/// Owen-scrambled (0,2)-sequence on a smooth integrand gives ~N^−3/2,
/// ~512×), both for the camera's first point and for a point of the
/// second bounce's block behind a discrete choice. Catches points that are
/// not a net (wrong matrix, a non-nested scramble, a shuffle across
/// blocks) and a layout that hands the choice and the point one slot.
#[test]
fn sequence_error_falls_faster_than_root_n() {
    let camera = |r: &mut SampleRng| r.uniform2_packed();
    let bounce = |r: &mut SampleRng| {
        r.uniform2_packed();
        r.start_bounce(1);
        r.uniform();
        r.choice_and_point().1
    };
    for (what, draw) in [
        ("camera", &camera as &dyn Fn(&mut SampleRng) -> [f32; 2]),
        ("bounce", &bounce),
    ] {
        let fall = |k| rms_error(k, 16, 64, draw) / rms_error(k, 1024, 64, draw);
        let (random, sobol) = (fall(SamplerKind::Random), fall(SamplerKind::Sobol));
        assert!(
            (4.0..16.0).contains(&random),
            "{what}: pseudo-random error fell {random}× (expected ~8×)"
        );
        assert!(
            sobol > 64.0,
            "{what}: sequence error fell {sobol}× from 16 to 1024 samples"
        );
    }
}

fn marble_ball() -> Scene {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/marble-ball.toml");
    lucent::scene::load(&path).unwrap()
}

fn bits(f: &Film) -> Vec<u32> {
    f.pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(f32::to_bits)
        .collect()
}

fn render_with(scene: &Scene, sampler: SamplerKind, threads: usize, spp: u32) -> Film {
    let a = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let opts = RenderOptions {
        spp: Some(spp),
        threads: Some(threads),
        sampler: Some(sampler),
        ..Default::default()
    };
    render(scene, a.as_ref(), &opts).unwrap().0
}

/// The `random` sampler's pixels are the pseudo-random stream's: pinned
/// bits of a subsurface scene with a floor, a light and an environment,
/// its coat a mirror at every vertex (`regularize = 0`) and the plane
/// control variate at the camera vertex, one probe (`probe_pair = false`;
/// the journal,
/// 2026-12-07, "Low-discrepancy sampling: …", says how they were
/// checked). Catches any change to the stream's draws: their order, the
/// probe's or the light's layout, the camera's.
#[test]
fn random_sampler_pixels_are_the_streams() {
    let mut scene = marble_ball();
    let mirror = Assignments::default()
        .with("regularize", 0)
        .with("control_variate", true)
        .with("probe_pair", false);
    mirror.apply_all(&mut scene.materials).unwrap();
    let film = render_with(&scene, SamplerKind::Random, 2, 4);
    let hash = bits(&film).iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    });
    assert_eq!(hash, PINNED_RANDOM, "{hash:#x}");
}
const PINNED_RANDOM: u64 = 0x3382_8fdb_9afb_c6aa;

/// The sequence's render is bitwise the same for one and two threads, and
/// differs from the stream's (the sequence is in use). Catches a sequence
/// index or slot that depends on the thread or the tile instead of the
/// sample. (Splits, merges and resumes: tests/cli/farm.rs and
/// tests/robustness/interrupt.rs, with the default sampler.)
#[test]
fn sequence_renders_are_bitwise_for_any_thread_count() {
    let scene = marble_ball();
    let one = render_with(&scene, SamplerKind::Sobol, 1, 6);
    let two = render_with(&scene, SamplerKind::Sobol, 2, 6);
    assert_eq!(bits(&one), bits(&two));
    assert_ne!(
        bits(&one),
        bits(&render_with(&scene, SamplerKind::Random, 2, 6))
    );
}
