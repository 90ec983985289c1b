//! Region renders and pasting (docs/output.md, "Region renders"): a
//! `--region` render is a normal EXR whose data window is the region and
//! whose display window is the frame, with the beauty and every pass as
//! float channels, equal bit for bit to the same pixels of the full frame;
//! `lucent paste` changes only the region's pixels of a frame, bit for
//! bit, and refuses files that do not match (exit 2, nothing written).

use std::path::Path;
use std::process::{Command, Output};

pub(crate) use crate::common::exr_file::Exr;

const FIXTURE: &str = "tests/fixtures/marble-ball.toml";

fn lucent(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn ok(dir: &Path, args: &[&str]) {
    let o = lucent(dir, args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A directory holding the fixture scene (24×16) as `scene.toml`.
fn scene_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(FIXTURE, dir.path().join("scene.toml")).unwrap();
    dir
}

const RENDER: [&str; 8] = [
    "render",
    "scene.toml",
    "--quiet",
    "--spp",
    "3",
    "--threads",
    "2",
    "--aov",
];

/// `render` with every pass and `extra`.
fn render(dir: &Path, extra: &[&str]) {
    let mut a = RENDER.to_vec();
    a.push("all");
    a.extend_from_slice(extra);
    ok(dir, &a);
}

/// Caught: a data window written at (0, 0) (the region's pixels shifted),
/// a display window of the region's size, and a region whose pixels are
/// not the frame's (a region render keyed by its own pixel index).
#[test]
fn a_region_render_is_the_frames_pixels_in_a_data_window() {
    let dir = scene_dir();
    let d = dir.path();
    render(d, &["-o", "full.exr"]);
    render(d, &["--region", "5,3,17,11", "-o", "region.exr"]);
    let (full, region) = (
        Exr::read(&d.join("full.exr")),
        Exr::read(&d.join("region.exr")),
    );
    assert_eq!(region.display, (0, 0, 24, 16));
    assert_eq!(region.data, (5, 3, 12, 8));
    assert_eq!(full.data, (0, 0, 24, 16));
    assert_eq!(region.names(), full.names());
    assert!(full.names().len() > 40, "{:?}", full.names());
    for c in 0..full.channels.len() {
        for y in 3..11 {
            for x in 5..17 {
                assert_eq!(
                    region.at(c, x, y),
                    full.at(c, x, y),
                    "{} at ({x}, {y})",
                    full.channels[c].0
                );
            }
        }
    }
    // the preview is the region's
    let png = image::open(d.join("region.png")).unwrap();
    assert_eq!((png.width(), png.height()), (12, 8));
    // a region outside the frame is bad input
    let o = lucent(
        d,
        &[
            "render",
            "scene.toml",
            "--region",
            "20,0,25,4",
            "-o",
            "x.exr",
        ],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--region"));
    assert!(!d.join("x.exr").exists());
}

/// Caught: a paste that shifts the region, writes it over the whole
/// frame, drops channels, or touches a pixel outside the region.
#[test]
fn paste_changes_only_the_region_bit_for_bit() {
    let dir = scene_dir();
    let d = dir.path();
    // the pseudo-random sampler: a scrambled net integrates a pixel that is
    // constant on its strata exactly, for every seed alike
    render(d, &["--sampler", "random", "-o", "frame.exr"]);
    // other samples: every pixel of the region differs from the frame's
    render(
        d,
        &[
            "--sampler",
            "random",
            "--seed",
            "99",
            "--region",
            "3,2,11,9",
            "-o",
            "fix.exr",
        ],
    );
    ok(
        d,
        &["paste", "--quiet", "fix.exr", "frame.exr", "-o", "out.exr"],
    );
    let (frame, fix, out) = (
        Exr::read(&d.join("frame.exr")),
        Exr::read(&d.join("fix.exr")),
        Exr::read(&d.join("out.exr")),
    );
    assert_eq!(out.names(), frame.names());
    assert_eq!((out.display, out.data), (frame.display, frame.data));
    let r = frame.names().iter().position(|n| *n == "R").unwrap();
    assert_ne!(
        fix.at(r, 5, 5),
        frame.at(r, 5, 5),
        "the seeds give other pixels"
    );
    for c in 0..frame.channels.len() {
        for y in 0..16 {
            for x in 0..24 {
                let inside = (3..11).contains(&x) && (2..9).contains(&y);
                let want = if inside {
                    fix.at(c, x, y)
                } else {
                    frame.at(c, x, y)
                };
                assert_eq!(out.at(c, x, y), want, "{} ({x}, {y})", frame.channels[c].0);
            }
        }
    }
    assert!(d.join("out.png").exists());
    let attrs = lucent::film::exr_layers::read_attributes(&d.join("out.exr")).unwrap();
    let pasted = lucent::film::exr_layers::text_attribute(&attrs, "lucent/pasted");
    assert_eq!(pasted.as_deref(), Some("3,2,11,9 from fix.exr"));
}

/// Caught: a paste that writes whatever it is given. Each mismatch is
/// exit 2 naming the file and what differs, and nothing is written.
#[test]
fn paste_refuses_files_that_do_not_match() {
    let dir = scene_dir();
    let d = dir.path();
    render(d, &["-o", "frame.exr"]);
    // other channels: the beauty alone
    let mut a = RENDER.to_vec();
    a.extend_from_slice(&["Z", "--region", "0,0,4,4", "-o", "z.exr"]);
    ok(d, &a);
    // another display window: the scene at another resolution
    let text = std::fs::read_to_string(d.join("scene.toml")).unwrap();
    let small = text.replace("resolution = [24, 16]", "resolution = [12, 8]");
    std::fs::write(d.join("small.toml"), small).unwrap();
    let mut a = RENDER.to_vec();
    a[1] = "small.toml";
    a.extend_from_slice(&["all", "--region", "0,0,4,4", "-o", "small.exr"]);
    ok(d, &a);
    std::fs::write(d.join("text.exr"), "not an image").unwrap();
    for (region, field) in [
        ("z.exr", "channels"),
        ("small.exr", "displayWindow"),
        ("text.exr", "OpenEXR"),
    ] {
        let o = lucent(d, &["paste", region, "frame.exr", "-o", "out.exr"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{region}: {err}");
        assert!(err.contains(region) && err.contains(field), "{err}");
        assert!(!d.join("out.exr").exists() && !d.join("out.png").exists());
    }
    // the frame cannot be its own output
    let o = lucent(d, &["paste", "z.exr", "frame.exr", "-o", "frame.exr"]);
    assert_eq!(o.status.code(), Some(2));
}
