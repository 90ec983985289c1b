//! Diffusion against exact transport under one key light
//! (`docs/bssrdf.md` §10, "Where the light leaves"; `docs/accuracy.md`,
//! "Key light"): `scenes/keylight-sphere.toml` — a marble sphere of radius
//! 10 mm (≈ 1.2 diffusion lengths of its red channel) lit from the side,
//! the left half of the image the lit hemisphere, the right half the dark
//! one — rendered at 24² with the diffusion estimator and with the random
//! walk. The target: each half's mean within 3 % of the walk per channel.
//!
//! Statistical tolerance: eight renders of 32 spp per side with
//! independent seeds; the bound is 3 % + 3 standard errors of the ratio,
//! from the seeds' spread (measured 2–3.6 %, nearly all of it the walk's,
//! whose exits find the light only by chance). So at these counts the
//! bound is about 10 %: today's far half fails it by far, today's lit
//! half (−8…−11 %) does not clearly; a model meant to pass should be
//! checked with more walk samples (`scripts/keylight-report.sh`).
//!
//! Ignored until the model carries light across the body: today's
//! diffusion is −10…−13 % on the lit half and −75…−82 % on the far one
//! (`scripts/keylight-report.sh`, 48², 4 × 256 spp; here −72…−79 %). The
//! profile's tail is far shorter than the medium's transfer, more so on a
//! curved body, and the exit lobe is blind to where the light came from
//! (`docs/bssrdf.md` §10, "Where the light leaves"). The tabulated
//! profile (`profile = "tabulated"`) fixes the shape on the half-space:
//! far half −29…−45 %, lit −7…−8 %; what is left is curvature and the
//! exit. The last test here pins that much.

use std::path::Path;

use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::integrator::IntegratorKind;
use lucent::render::{render, RenderOptions};
use lucent::scene::{load_str, Camera, Scene};

const RES: u32 = 24;
const SEEDS: u64 = 8;

/// The scene file at RES², with `spp` and `seed`.
fn scene(spp: u32, seed: u64) -> Scene {
    scene_with(spp, seed, "")
}

/// [`scene`] with `extra` (TOML lines) added to the marble material.
fn scene_with(spp: u32, seed: u64, extra: &str) -> Scene {
    let text = include_str!("../../scenes/keylight-sphere.toml").replace(
        "preset = \"marble\"",
        &format!("preset = \"marble\"\n{extra}"),
    );
    let mut s = load_str(&text, Path::new("scenes/keylight-sphere.toml")).unwrap();
    let c = &s.camera;
    s.camera = Camera::new(c.look_from, c.look_at, c.up, c.fov_y, RES, RES);
    s.settings.spp = spp;
    s.settings.seed = seed;
    s
}

fn run(scene: &Scene, integrator: IntegratorKind) -> Film {
    let a = accel::build(&scene.meshes, Backend::default_available()).unwrap();
    let opts = RenderOptions {
        integrator,
        ..Default::default()
    };
    let (film, stats) = render(scene, a.as_ref(), &opts).unwrap();
    assert_eq!(stats.counters.nonfinite, 0);
    film
}

/// Mean per channel of the lit (left) and far (right) halves of the
/// sphere's disk: pixels whose square lies wholly inside the disk and on
/// one side of its centre line. The disk: the unit sphere seen from 4.4
/// units with a 30° field, radius tan(asin(1/4.4))/tan(15°) of half the
/// image.
fn halves(film: &Film) -> [[f64; 3]; 2] {
    let c = RES as f64 / 2.0;
    let r = (1.0f64 / 4.4).asin().tan() / 15f64.to_radians().tan() * c;
    let mut sum = [[0.0; 3]; 2];
    let mut n = [0.0; 2];
    for y in 0..RES as usize {
        for x in 0..RES as usize {
            let dx = (x as f64 - c).abs().max((x as f64 + 1.0 - c).abs());
            let dy = (y as f64 - c).abs().max((y as f64 + 1.0 - c).abs());
            if dx * dx + dy * dy > r * r {
                continue;
            }
            let side = if x as f64 + 1.0 <= c {
                0
            } else if x as f64 >= c {
                1
            } else {
                continue;
            };
            let p = film.pixels[y * RES as usize + x];
            for k in 0..3 {
                sum[side][k] += p[k] as f64;
            }
            n[side] += 1.0;
        }
    }
    assert!(n[0] > 100.0 && n[1] > 100.0, "{n:?} pixels");
    std::array::from_fn(|s| sum[s].map(|v| v / n[s]))
}

/// Mean and standard error over the seeds of each half and channel.
fn mean_se(per_seed: &[[[f64; 3]; 2]]) -> [[(f64, f64); 3]; 2] {
    let k = per_seed.len() as f64;
    std::array::from_fn(|s| {
        std::array::from_fn(|c| {
            let m = per_seed.iter().map(|v| v[s][c]).sum::<f64>() / k;
            let var = per_seed.iter().map(|v| (v[s][c] - m).powi(2)).sum::<f64>() / (k - 1.0);
            (m, (var / k).sqrt())
        })
    })
}

#[test]
#[ignore = "the model does not yet carry light across the body: far half −75…−82 % with the fit, −29…−45 % with the tabulated profile (docs/accuracy.md, \"Key light\")"]
fn each_half_of_a_sphere_under_a_key_light_is_within_3_percent_of_the_random_walk() {
    let sides = |integrator, spp| {
        let v: Vec<_> = (1..=SEEDS)
            .map(|seed| halves(&run(&scene(spp, seed), integrator)))
            .collect();
        mean_se(&v)
    };
    let walk = sides(IntegratorKind::RandomWalk, 32);
    let diff = sides(IntegratorKind::Path, 32);
    let mut failures = Vec::new();
    for (s, name) in ["lit", "far"].iter().enumerate() {
        for c in 0..3 {
            let ((md, sd), (mw, sw)) = (diff[s][c], walk[s][c]);
            let e = md / mw - 1.0;
            let se = (md / mw) * ((sd / md).powi(2) + (sw / mw).powi(2)).sqrt();
            println!(
                "{name} ch{c}: diffusion {md:.5} ± {sd:.5}, walk {mw:.5} ± {sw:.5}: {:+.1} ± {:.1} %",
                100.0 * e,
                100.0 * se
            );
            if e.abs() > 0.03 + 3.0 * se {
                failures.push(format!("{name} ch{c}: {:+.1} %", 100.0 * e));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// The tabulated profile (`profile = "tabulated"`, `docs/bssrdf.md` §10)
/// carries the key light across the body: on the far half it returns
/// more than 40 % of the walk's light in every channel, where the fit
/// returns less than 35 % (at 4 × 256 spp, 48²: 0.71 / 0.64 / 0.56
/// against 0.25 / 0.20 / 0.19; here 0.64 / 0.52 / 0.56 against
/// 0.27 / 0.18 / 0.20), and the lit half stays within 20 % of the walk
/// (−7…−8 % at 48², here −6…−9 %). At 32 spp a seed's far half of the
/// fit read 0.47 of the walk: the far half is lit by few probes, so
/// fewer samples make the test depend on the random numbers. Rd weighed from the fit's shape fails the far bound;
/// truncating the table at the fit's Rmax (16 mm, short of the 20 mm
/// diameter) does not (far 0.67 / 0.46 / 0.59). Four seeds of 128 spp at 24² per side (3 s).
#[test]
fn the_tabulated_profile_carries_a_key_light_to_the_far_half() {
    let sides = |integrator, extra: &str| {
        let v: Vec<_> = (1..=4)
            .map(|seed| halves(&run(&scene_with(128, seed, extra), integrator)))
            .collect();
        mean_se(&v)
    };
    let walk = sides(IntegratorKind::RandomWalk, "");
    let tab = sides(IntegratorKind::Path, "profile = \"tabulated\"");
    let fit = sides(IntegratorKind::Path, "profile = \"burley\"");
    let ratio = |d: [[(f64, f64); 3]; 2], s: usize, c: usize| d[s][c].0 / walk[s][c].0;
    let rows: Vec<[f64; 3]> = (0..3)
        .map(|c| [ratio(tab, 0, c), ratio(tab, 1, c), ratio(fit, 1, c)])
        .collect();
    for (c, [lit, far, fit_far]) in rows.iter().enumerate() {
        println!("ch{c}: tabulated lit {lit:.3}, far {far:.3}; fit far {fit_far:.3}");
    }
    for (c, &[lit, far, fit_far]) in rows.iter().enumerate() {
        assert!(far > 0.4, "ch{c}: tabulated far half {far:.3} of the walk");
        assert!(
            fit_far < 0.35,
            "ch{c}: fit far half {fit_far:.3} of the walk"
        );
        assert!(
            (lit - 1.0).abs() < 0.2,
            "ch{c}: tabulated lit half {lit:.3}"
        );
    }
}
