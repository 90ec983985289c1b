//! `--denoise-layers` (docs/output.md, "Denoising"): each light group
//! denoised with the beauty's guides as `denoised_RGBA_<group>`; the
//! denoised groups add up to the denoised beauty within a stated
//! tolerance, each is closer to its own reference than the noisy group,
//! and `lucent denoise --layers` of the frame gives the same layers.

use std::path::{Path, PathBuf};

use lucent::geometry::Vec3;

use super::denoise::{channels, have_oidn, rel_mse, rgb, run};

/// The groups of `scenes/sun-and-bulb.toml`.
const GROUPS: [&str; 3] = ["bulb", "default", "sun"];

/// The lower half of the frame: the floor and the objects, lit by every
/// group, without the bulb itself (its few saturated pixels OIDN spreads
/// into the black around them in the bulb's group: docs/output.md,
/// "Denoising").
const REGION: &str = "0,36,96,72";

/// sun-and-bulb at 96 × 72 in `dir`.
fn small_scene(dir: &Path) -> PathBuf {
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/scenes/sun-and-bulb.toml"))
        .unwrap()
        .replace("resolution = [320, 240]", "resolution = [96, 72]")
        .replace("\"meshes/", &format!("\"{root}/scenes/meshes/"));
    assert!(text.contains("[96, 72]"));
    let p = dir.join("small.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn layer(ch: &std::collections::BTreeMap<String, Vec<f32>>, name: &str) -> Vec<Vec3> {
    rgb(
        ch,
        ["R", "G", "B"]
            .map(|c| format!("{name}.{c}"))
            .each_ref()
            .map(|s| s.as_str()),
    )
}

#[test]
fn denoised_groups_add_up_to_the_denoised_beauty_and_are_each_denoised() {
    if !have_oidn() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let s = scene.to_str().unwrap();
    let (noisy, reference, later) = (
        dir.path().join("noisy.exr"),
        dir.path().join("ref.exr"),
        dir.path().join("later.exr"),
    );
    let common = [
        "--aov",
        "lightgroups",
        "--region",
        REGION,
        "--threads",
        "2",
        "-q",
        "-o",
    ];
    run(&[
        &["render", s, "--spp", "8", "--denoise", "--denoise-layers"][..],
        &common,
        &[noisy.to_str().unwrap()],
    ]
    .concat());
    run(&[
        &["render", s, "--spp", "512", "--seed", "7"][..],
        &common,
        &[reference.to_str().unwrap()],
    ]
    .concat());
    let (n, r) = (channels(&noisy), channels(&reference));

    // The groups partition the beauty; denoised one by one they add up to
    // the denoised beauty only approximately (OIDN is not linear): within
    // relMSE 2e-3 and a tenth of the noise the denoise removed (measured
    // 1.0e-3 against 2.2e-2).
    let clean = layer(&n, "denoised");
    let mut sum = vec![Vec3::ZERO; clean.len()];
    for g in GROUPS {
        for (s, p) in sum.iter_mut().zip(layer(&n, &format!("denoised_RGBA_{g}"))) {
            *s += p;
        }
    }
    let apart = rel_mse(&sum, &clean);
    let removed = rel_mse(&layer_rgb(&n), &clean);
    eprintln!(
        "denoised groups vs denoised beauty: relMSE {apart:.2e}; noisy vs denoised {removed:.2e}"
    );
    assert!(
        apart < 2e-3 && apart < 0.1 * removed,
        "{apart} vs {removed}"
    );

    // Each group denoised is closer to its reference than the noisy group
    // (measured 0.08× to 0.11×).
    for g in GROUPS {
        let want = layer(&r, &format!("RGBA_{g}"));
        let before = rel_mse(&layer(&n, &format!("RGBA_{g}")), &want);
        let after = rel_mse(&layer(&n, &format!("denoised_RGBA_{g}")), &want);
        eprintln!("{g}: relMSE noisy {before:.2e}, denoised {after:.2e}");
        assert!(
            after < 0.3 * before,
            "{g}: noisy {before}, denoised {after}"
        );
    }

    // The same layers from the finished frame, later, bit for bit.
    run(&[
        "denoise",
        noisy.to_str().unwrap(),
        "--layers",
        "--threads",
        "2",
        "-q",
        "-o",
        later.to_str().unwrap(),
    ]);
    let l = channels(&later);
    for g in GROUPS {
        for c in ["R", "G", "B"] {
            let name = format!("denoised_RGBA_{g}.{c}");
            assert!(l[&name] == n[&name], "{name} differs");
        }
    }
    // and without --layers, none
    let plain = dir.path().join("plain.exr");
    run(&[
        "render",
        s,
        "--spp",
        "8",
        "--denoise",
        "--aov",
        "lightgroups",
        "-q",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(!channels(&plain).keys().any(|k| k.starts_with("denoised_")));
}

/// The beauty R G B.
fn layer_rgb(ch: &std::collections::BTreeMap<String, Vec<f32>>) -> Vec<Vec3> {
    rgb(ch, ["R", "G", "B"])
}
