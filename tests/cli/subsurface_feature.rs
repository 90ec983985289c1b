//! The `subsurface` feature from the command line, in either build: with
//! it, a subsurface scene renders and `info` says so; without it, `info`
//! says the feature is off and a subsurface scene is refused at load with
//! exit 2, naming the file, the line and the field of the material's
//! `type`, before anything is written. CI runs this file in both builds
//! (scripts/test.sh).

use std::process::Command;

fn lucent() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
}

/// A marble sphere on a floor, 24×16 (`type = "subsurface"` on line 22).
const MARBLE_BALL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/marble-ball.toml"
);

#[test]
fn info_says_whether_the_build_has_subsurface_support() {
    let out = lucent().arg("info").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let want = if cfg!(feature = "subsurface") {
        "\nsubsurface: yes"
    } else {
        "\nsubsurface: no (built without the `subsurface` feature)"
    };
    assert!(text.contains(want), "{text}");
}

#[test]
fn a_subsurface_scene_renders_only_in_a_build_with_subsurface_support() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("ball.exr");
    let out = lucent()
        .args(["render", MARBLE_BALL, "--spp", "1", "-q", "-o"])
        .arg(&exr)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    if cfg!(feature = "subsurface") {
        assert!(out.status.success(), "{err}");
        assert!(exr.is_file());
        return;
    }
    assert_eq!(out.status.code(), Some(2), "{err}");
    let line = std::fs::read_to_string(MARBLE_BALL)
        .unwrap()
        .lines()
        .position(|l| l == "type = \"subsurface\"")
        .unwrap()
        + 1;
    for needle in [
        format!("marble-ball.toml:{line}"),
        "materials.marble.type".into(),
        "this build of lucent has no subsurface support: built without the `subsurface` feature"
            .into(),
    ] {
        assert!(err.contains(&needle), "no {needle:?} in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn the_random_walk_exists_only_in_a_build_with_subsurface_support() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cornell.toml");
    let out = lucent()
        .args(["render", cornell, "--spp", "1", "-q"])
        .args(["--integrator", "randomwalk", "--threads", "1", "-o"])
        .arg(dir.path().join("c.exr"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    if cfg!(feature = "subsurface") {
        assert!(out.status.success(), "{err}");
    } else {
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("randomwalk"), "{err}");
    }
}
