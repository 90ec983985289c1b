//! `regularize = 0` restores the pixels of the renderer before the option
//! existed, bit for bit: `tests/fixtures/smooth-bunny-region.exr` is a
//! region of scenes/smooth-bunny.toml rendered by main at 6d847a1 (the
//! commands below, `--accel bvh`), where the default regularized coat
//! changes most pixels (docs/bssrdf.md §6, "Regularized coat").
//!
//! Caught: the coat regularized with the option off, or the path's
//! random numbers drawn differently for it. A change that is meant to
//! change the default's pixels regenerates the fixture with the same
//! command and says so.

use std::path::Path;
use std::process::Command;

use super::region::Exr;

const FIXTURE: &str = "tests/fixtures/smooth-bunny-region.exr";

/// `lucent render scenes/smooth-bunny.toml` over the fixture's region
/// with `extra`, read back.
fn render(extra: &[&str]) -> Exr {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("region.exr");
    let root = env!("CARGO_MANIFEST_DIR");
    let o = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args([
            "render",
            "scenes/smooth-bunny.toml",
            "--region",
            "96,208,112,224",
        ])
        .args([
            "--spp",
            "4",
            "--seed",
            "5",
            "--threads",
            "2",
            "--accel",
            "bvh",
            "-q",
        ])
        .arg("-o")
        .arg(&out)
        .args(extra)
        .current_dir(root)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    Exr::read(&out)
}

#[test]
fn regularize_off_renders_todays_pixels_bit_for_bit() {
    let fixture = Exr::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join(FIXTURE));
    let off = render(&["--regularize", "0"]);
    assert_eq!(off.data, fixture.data);
    assert_eq!(off.channels, fixture.channels, "regularize = 0");
    // the region exercises the rule: the default changes its pixels
    let on = render(&[]);
    assert_ne!(on.channels, fixture.channels, "the default");
}
