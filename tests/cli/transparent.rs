//! The transparent film (`--transparent`, docs/output.md, "Transparent
//! film"): `A` is the fraction of a pixel's camera rays that hit, the
//! environment seen directly is left out of the beauty, so the beauty is
//! premultiplied and "over" the environment gives back the opaque render;
//! light groups carry the same `A`; parts merge to the single render's
//! bits.

use std::path::Path;
use std::process::Command;

use crate::region::Exr;

/// A diffuse sphere lit by a constant sky `E` and a lamp out of view.
const SCENE: &str = "[camera]\nlook_from = [0, 0, 4]\nlook_at = [0, 0, 0]\nresolution = [20, 14]\n\
    [render]\nspp = 4\n[environment]\nradiance = [0.25, 0.5, 0.75]\n\
    [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
    [materials.lamp]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
    [[shapes]]\ntype = \"sphere\"\nmaterial = \"white\"\n\
    [[shapes]]\ntype = \"quad\"\nmaterial = \"lamp\"\nemission = [4, 4, 4]\n\
    rotate = [[90, 1, 0, 0]]\ntranslate = [0, 5, 0]\n";
const SKY: [f32; 3] = [0.25, 0.5, 0.75];

fn ok(dir: &Path, args: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Channel `name`'s values.
fn values(e: &Exr, name: &str) -> Vec<f32> {
    let c = e.names().iter().position(|n| *n == name).unwrap();
    e.channels[c].1.iter().map(|b| f32::from_bits(*b)).collect()
}

/// Caught: an `A` of 1 (or of the sample count), the environment left in
/// the beauty of a transparent film, a light group whose `A` is not the
/// beauty's.
#[test]
fn the_transparent_beauty_over_the_sky_is_the_opaque_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let common = ["render", "s.toml", "--quiet", "--aov", "lightgroups"];
    ok(d, &[&common[..], &["-o", "opaque.exr"]].concat());
    ok(
        d,
        &[&common[..], &["--transparent", "-o", "t.exr"]].concat(),
    );
    let (o, t) = (
        Exr::read(&d.join("opaque.exr")),
        Exr::read(&d.join("t.exr")),
    );
    let a = values(&t, "A");
    assert!(values(&o, "A").iter().all(|&x| x == 1.0));
    // misses, hits and edges: not vacuous
    assert_eq!(a[0], 0.0, "the corner sees only the sky");
    assert_eq!(a[7 * 20 + 10], 1.0, "the centre sees the sphere");
    assert!(a.iter().any(|&x| x > 0.0 && x < 1.0), "no edge pixel");
    assert!(a.iter().all(|&x| (0.0..=1.0).contains(&x)));
    assert_eq!(values(&t, "RGBA_default.A"), a);
    for (c, ch) in ["R", "G", "B"].iter().enumerate() {
        let (ov, tv) = (values(&o, ch), values(&t, ch));
        for p in 0..a.len() {
            if a[p] == 0.0 {
                assert_eq!(tv[p], 0.0, "{ch} {p}: a pixel with nothing in it is 0");
            }
            // premultiplied: the transparent beauty over the sky is the
            // opaque render (the same samples, less the sky they saw)
            let over = tv[p] + (1.0 - a[p]) * SKY[c];
            assert!(
                (over - ov[p]).abs() <= 1e-5 * ov[p].max(1.0),
                "{ch} pixel {p}: over {over}, opaque {}",
                ov[p]
            );
        }
        // the one light group still sums to the beauty
        assert_eq!(values(&t, &format!("RGBA_default.{ch}")), tv);
    }
}

/// Caught: an `A` kept only by the single render (a merge writing 1), or
/// summed in a way that depends on the split.
#[test]
fn transparent_parts_merge_to_the_single_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    let common = ["render", "s.toml", "--quiet", "--transparent"];
    ok(d, &[&common[..], &["-o", "single.exr"]].concat());
    ok(
        d,
        &[&common[..], &["--samples", "0..1", "-o", "p0.exr"]].concat(),
    );
    ok(
        d,
        &[&common[..], &["--samples", "1..4", "-o", "p1.exr"]].concat(),
    );
    ok(
        d,
        &["merge", "--quiet", "-o", "merged.exr", "p0.exr", "p1.exr"],
    );
    let (s, m) = (
        Exr::read(&d.join("single.exr")),
        Exr::read(&d.join("merged.exr")),
    );
    assert_eq!(s.names(), m.names());
    assert!(s.names().contains(&"A"));
    assert!(s.channels == m.channels, "the merged frame differs");
}

/// The film row of `lucent render --explain` for these extra arguments.
fn film_row(dir: &Path, extra: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args([&["render", "s.toml", "--explain"][..], extra].concat())
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let row = text.lines().find(|l| l.trim_start().starts_with("film "));
    row.unwrap_or_else(|| panic!("no film row in\n{text}"))
        .to_string()
}

/// Caught: `--explain` describing the scene file's film and not the one the
/// command line asks for (the plan loaded without the film's override), or
/// saying nothing of the film.
#[test]
fn explain_names_the_film_the_render_would_use() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), SCENE).unwrap();
    assert!(film_row(d, &[]).contains("opaque"));
    assert!(film_row(d, &["--transparent"]).contains("transparent"));
    let with_film = format!("{SCENE}[output]\ntransparent = true\n");
    std::fs::write(d.join("s.toml"), with_film).unwrap();
    assert!(film_row(d, &[]).contains("transparent"));
    assert!(film_row(d, &["--transparent=false"]).contains("opaque"));
}
