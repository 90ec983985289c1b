//! Subsurface level of detail (`lucent::materials::lod`) end to end:
//! energy on the uniformly lit slab (the slab gives A) with LOD forced, bare
//! and under smooth and rough coats, against the full estimator; no probe
//! query where every hit is under LOD; the camera footprint as the rule
//! sees it; LOD off and LOD that never triggers leave the image bit for bit.

use crate::common;

use std::path::Path;

use common::mean_se;
use lucent::accel::{self, Backend};
use lucent::film::Film;
use lucent::integrator::Counters;
use lucent::materials::estimator_options::Assignments;
use lucent::materials::{LodMode, Material};
use lucent::render::{render, RenderOptions};
use lucent::scene::{self, load_str, Scene};

fn slab_scene() -> Scene {
    scene::load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/slab-uniform.toml"
    )))
    .unwrap()
}

fn with_lod(scene: &Scene, lod: LodMode) -> Scene {
    let mut s = scene.clone();
    Assignments::default()
        .with("lod", lod.name())
        .apply_all(&mut s.materials)
        .unwrap();
    s
}

fn run(scene: &Scene, spp: u32, seed: u64) -> (Film, Counters) {
    let a = accel::build(&scene.meshes, Backend::Bvh).unwrap();
    let (film, stats) = render(
        scene,
        a.as_ref(),
        &RenderOptions {
            spp: Some(spp),
            seed: Some(seed),
            ..Default::default()
        },
    )
    .unwrap();
    (film, stats.counters)
}

fn subsurface(scene: &Scene) -> &lucent::materials::Subsurface {
    scene
        .materials
        .iter()
        .find_map(|m| match m {
            Material::Subsurface(s) => Some(s.as_ref()),
            _ => None,
        })
        .unwrap()
}

/// Asserts `mean` is within 1 % of `expected` per channel, with noise well
/// below that.
fn within_1pct(what: &str, film: &Film, expected: [f64; 3]) -> [f64; 3] {
    let (mean, se) = mean_se(film);
    eprintln!("{what}: mean {mean:.4?} se {se:.5?} expected {expected:.4?}");
    for c in 0..3 {
        let err = (mean[c] - expected[c]).abs() / expected[c];
        assert!(
            err < 0.01,
            "{what} ch{c}: {} vs {} ({:.2} %)",
            mean[c],
            expected[c],
            100.0 * err
        );
        assert!(4.0 * se[c] < 0.01 * expected[c], "{what}: too noisy");
    }
    mean
}

/// The slab reflects A·CDF(Rmax) under uniform light; LOD forced on gives
/// that within 1 %, as the full estimator does, and casts no probe.
#[test]
fn forced_lod_on_the_uniform_slab_reflects_a_without_probes() {
    let base = slab_scene();
    let ss = subsurface(&base);
    let a = ss.albedo();
    let expected = [a.x as f64, a.y as f64, a.z as f64];
    let (full, cf) = run(&with_lod(&base, LodMode::Off), 256, 1);
    let m_full = within_1pct("full", &full, expected);
    assert!(cf.probes() > 0);
    let (lod, cl) = run(&with_lod(&base, LodMode::Force), 256, 1);
    let m_lod = within_1pct("lod forced", &lod, expected);
    assert_eq!(cl.probes(), 0, "a probe was cast under forced LOD");
    // the two estimate the same value: within their noise of each other
    let (_, se_full) = mean_se(&full);
    for c in 0..3 {
        assert!(
            (m_full[c] - m_lod[c]).abs() < 4.0 * se_full[c] + 1e-3 * expected[c],
            "ch{c}: full {} lod {}",
            m_full[c],
            m_lod[c]
        );
    }
}

/// The coat scene of tests/physics/coat.rs (renormalized slab at μo = 0.25 under
/// uniform light L = 1): the coat reflects E(μo) (Fr for the smooth one),
/// the medium A of the rest, with `panel` every coated hit at depth ≥ 1.
fn coat_scene(roughness: f32, a: f32, panel: bool) -> Scene {
    let mu: f32 = 0.25;
    let sin = (1.0 - mu * mu).sqrt();
    let (eye, look_at, fov) = if panel {
        ("[0.0, 1.8787, 2.1213]".to_string(), "[0.0, 4.0, 0.0]", 20.0)
    } else {
        (
            format!("[0.0, {}, {}]", 10.0 * mu, 10.0 * sin),
            "[0.0, 0.0, 0.0]",
            1.0,
        )
    };
    let panel = if panel {
        "[[shapes]]\nname = \"panel\"\ntype = \"quad\"\nmaterial = \"white\"\n\
         rotate = [[45, 1, 0, 0]]\ntranslate = [0, 4, 0]\n"
    } else {
        ""
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
[environment]
radiance = [1.0, 1.0, 1.0]
[materials.slab]
type = "subsurface"
albedo = [{a}, {a}, {a}]
dmfp = [0.2, 0.2, 0.2]
eta = 1.5
renormalize = true
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
"#
    );
    load_str(&text, Path::new("coat.toml")).unwrap()
}

/// Under the smooth and the rough coat, forced LOD agrees with the full
/// estimator and with E + (1 − E)·A (and the white furnace, A = 1, where
/// coated hits choose between coat and medium).
#[test]
fn forced_lod_keeps_the_coat_energy() {
    for roughness in [0.0f32, 0.5] {
        let s = coat_scene(roughness, 0.5, false);
        let ss = subsurface(&s);
        let e = match ss.rough_coat() {
            Some(c) => c.albedo(0.25),
            None => lucent::fresnel::dielectric(0.25, 1.5),
        } as f64;
        let expected = [e + (1.0 - e) * 0.5; 3];
        let (full, _) = run(&with_lod(&s, LodMode::Off), 256, 2);
        let m_full = within_1pct(&format!("full, roughness {roughness}"), &full, expected);
        let (lod, c) = run(&with_lod(&s, LodMode::Force), 256, 2);
        let m_lod = within_1pct(&format!("lod, roughness {roughness}"), &lod, expected);
        assert_eq!(c.probes(), 0);
        for ch in 0..3 {
            assert!((m_full[ch] - m_lod[ch]).abs() < 0.01 * expected[ch]);
        }
        let furnace = coat_scene(roughness, 1.0, true);
        let (lod, c) = run(&with_lod(&furnace, LodMode::Force), 256, 3);
        within_1pct(
            &format!("lod panel furnace, roughness {roughness}"),
            &lod,
            [1.0; 3],
        );
        assert_eq!(c.probes(), 0);
    }
}

/// The slab seen straight down from 10 units, 32 px over 20°: a camera
/// ray's footprint on the slab is (10 / cos θ) · 2 tan 10° / 32 · cos²θ. With the
/// switch just above the centre pixel's width LOD never triggers (the
/// image is bit for bit the full estimator's, probes the same); just below
/// it, the rays near the axis — and only they — go without probes.
#[test]
fn auto_lod_switches_at_the_analytic_camera_footprint() {
    let base = slab_scene();
    let ss = subsurface(&base);
    let rmax = ss.probe().rmax() as f32;
    let w_centre = 10.0 * 2.0 * 10f32.to_radians().tan() / 32.0;
    let at = |threshold: f32| {
        let mut s = base.clone();
        for m in s.materials.iter_mut() {
            if let Material::Subsurface(ss) = m {
                *ss = std::sync::Arc::new((**ss).clone().with_lod(LodMode::Auto, threshold));
            }
        }
        s
    };
    let (off, c_off) = run(&with_lod(&base, LodMode::Off), 4, 5);
    let (above, c_above) = run(&at(1.0005 * w_centre / rmax), 4, 5);
    assert_eq!(c_above.probes(), c_off.probes());
    assert!(
        off.pixels == above.pixels,
        "LOD that never triggers changed the image"
    );
    let (_, c_below) = run(&at(0.99 * w_centre / rmax), 4, 5);
    assert!(
        c_below.probes() < c_off.probes(),
        "no LOD just below the footprint"
    );
    // At angle θ off the axis the plane is 10/cos θ away and the cone's
    // spread cos²θ times the pixel's: width w_centre·cos θ ≥ 0.99 w_centre
    // where tan θ ≤ 0.1425, within 12.93 pixels of the centre (pitch
    // 2 tan 10°/32): π·12.93² ≈ 525 of the 1024 pixels lose their probes
    // (each pixel casts the same number: two per sample, the antithetic
    // pair, and the bounced rays leave for the sky)
    let per_pixel = c_off.probes() as f64 / 1024.0;
    let lost = (c_off.probes() - c_below.probes()) as f64 / per_pixel;
    assert!(lost > 500.0 && lost < 550.0, "{lost} pixels under LOD");
    // everywhere under LOD with a threshold far below the footprint
    let (_, c_all) = run(&at(0.01 * w_centre / rmax), 4, 5);
    assert_eq!(c_all.probes(), 0);
}

/// `lucent render --lod force` renders; a value other than auto, off or
/// force exits 2.
#[test]
fn cli_lod_flag_overrides_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/slab-uniform.toml");
    let go = |lod: &str, name: &str| {
        let out = dir.path().join(name);
        let res = std::process::Command::new(env!("CARGO_BIN_EXE_lucent"))
            .args(["render", scene, "--spp", "2", "--lod", lod, "-o"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            res.status.success(),
            "{}",
            String::from_utf8_lossy(&res.stderr)
        );
        out
    };
    assert!(go("force", "force.exr").exists());
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render", scene, "--lod", "sometimes"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}

/// On a sphere large enough for LOD (2R ≥ Rmax) in a constant
/// environment, the light entering is the same everywhere, and LOD forced
/// must give the full estimator's mean: A_plane times the curvature
/// correction f(κo) of the sphere (module docs of `materials::lod`,
/// "Curvature"), which the full estimator's probe hits carry as well. With
/// the correction off both lose it alike; with it on, LOD must multiply by
/// f, not divide.
#[test]
fn forced_lod_on_a_sphere_keeps_the_curvature_correction() {
    let scene = |correction: &str| {
        load_str(
            &format!(
                "units_per_mm = 0.1\n\
                 [camera]\nlook_from = [0, 0, 3.2]\nlook_at = [0, 0, 0]\nfov_y = 30\n\
                 resolution = [32, 32]\n\
                 [render]\nmax_depth = 8\n\
                 [environment]\nradiance = [1, 1, 1]\n\
                 [materials.marble]\ntype = \"subsurface\"\npreset = \"marble\"\n\
                 curvature_correction = \"{correction}\"\n\
                 [[shapes]]\nname = \"ball\"\ntype = \"sphere\"\nsubdivisions = 5\n\
                 material = \"marble\"\n"
            ),
            Path::new("lod-sphere.toml"),
        )
        .unwrap()
    };
    let mut means = Vec::new();
    for correction in ["auto", "off"] {
        let base = scene(correction);
        let (full, cf) = run(&with_lod(&base, LodMode::Off), 64, 1);
        let (lod, cl) = run(&with_lod(&base, LodMode::Force), 64, 1);
        assert!(cf.probes() > 0 && cl.probes() == 0);
        let ((m_full, se_full), (m_lod, se_lod)) = (mean_se(&full), mean_se(&lod));
        eprintln!("correction {correction}: full {m_full:.5?} ± {se_full:.5?}, lod {m_lod:.5?} ± {se_lod:.5?}");
        for c in 0..3 {
            let se = (se_full[c].powi(2) + se_lod[c].powi(2)).sqrt();
            assert!(
                (m_full[c] - m_lod[c]).abs() < 4.0 * se + 2e-3 * m_full[c],
                "correction {correction} ch{c}: full {} lod {}",
                m_full[c],
                m_lod[c]
            );
        }
        means.push(m_full);
    }
    // not vacuous: the correction changes this sphere's image by more than
    // the tolerance above
    let ratio = [0, 1, 2].map(|c| means[0][c] / means[1][c]);
    eprintln!("auto / off: {ratio:.4?}");
    assert!(ratio.iter().all(|r| *r > 1.03), "{ratio:?}");
}
