//! `regularize = 0` keeps the smooth coat a mirror at every vertex, bit
//! for bit: `tests/fixtures/smooth-bunny-region.exr` is a region of
//! scenes/smooth-bunny.toml rendered with the mirror coat everywhere and
//! the pseudo-random stream and the plane control variate (the commands
//! below, `--accel bvh`, `--sampler random`, `--control-variate true`, `--probe-pair false`), where the default regularized coat changes most pixels
//! (docs/bssrdf.md §6, "Regularized coat"); the journal (2026-12-07, "The
//! regularized coat") says which build made it.
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
            "--sampler",
            "random",
            "--control-variate",
            "true",
            "--probe-pair",
            "false",
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
    assert_eq!(differing(&off, &fixture), 0, "regularize = 0");
    // no accuracy budget is the same render (docs/bssrdf.md §14)
    let no_budget = render(&["--regularize", "0", "--accuracy", "off"]);
    assert_eq!(differing(&no_budget, &fixture), 0, "accuracy = off");
    // the region exercises the rule: the default changes its pixels
    let on = render(&[]);
    assert!(differing(&on, &fixture) > 0, "the default");
}

/// How many samples of `a` and `b` differ in their bits (every sample,
/// where the channels do not match).
fn differing(a: &Exr, b: &Exr) -> usize {
    let names = |e: &Exr| e.channels.iter().map(|c| c.0.clone()).collect::<Vec<_>>();
    if names(a) != names(b) {
        return usize::MAX;
    }
    let pairs = a.channels.iter().zip(&b.channels);
    pairs
        .map(|((_, x), (_, y))| {
            x.iter().zip(y).filter(|(p, q)| p != q).count() + x.len().abs_diff(y.len())
        })
        .sum()
}
