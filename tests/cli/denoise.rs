//! Denoising with Open Image Denoise (docs/output.md, "Denoising"):
//! the denoised layer is closer to a long reference than the noisy beauty,
//! the guides reach OIDN in the layout it expects (a flipped or swapped
//! guide does worse), `lucent denoise` after a merge gives the single
//! render's denoised layer bit for bit, and bad input (a missing or wrong
//! library, a frame without guides, NaN) is refused with exit 2 and
//! nothing written.
//!
//! The tests that run OIDN need `LUCENT_OIDN` (scripts/test.sh sets it to
//! the 2.5.1 that scripts/install-deps.sh unpacks): without it they say so
//! and do nothing, unless `LUCENT_REQUIRE_OIDN` is set (as scripts/test.sh
//! does), where that fails them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

pub(crate) use crate::common::exr_file::channels;
use exr::prelude::FlatSamples;
use lucent::denoise::{denoise, DenoiseInput, DenoiseOptions};
use lucent::geometry::Vec3;

/// Size of the test frames: small enough for a reference in seconds, and
/// not square, so a width taken for a height garbles the image.
const W: u32 = 64;
const H: u32 = 40;
/// Samples of the noisy frames.
const NOISY: u32 = 8;
/// Samples of the reference (another seed).
const REFERENCE: u32 = 512;

fn lucent() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
}

/// Whether OIDN is there to test; panics when it must be and is not.
pub(crate) fn have_oidn() -> bool {
    if std::env::var_os("LUCENT_OIDN").is_some() {
        return true;
    }
    if std::env::var_os("LUCENT_REQUIRE_OIDN").is_some() {
        panic!("LUCENT_REQUIRE_OIDN is set but LUCENT_OIDN is not");
    }
    eprintln!("LUCENT_OIDN not set: denoising not tested");
    false
}

/// The Cornell box at W×H, written into `dir`.
fn small_scene(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(format!(
        "{}/scenes/cornell.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace(
        "resolution = [512, 512]",
        &format!("resolution = [{W}, {H}]"),
    );
    assert!(text.contains(&format!("[{W}, {H}]")));
    let p = dir.join("small.toml");
    std::fs::write(&p, text).unwrap();
    p
}

pub(crate) fn run(args: &[&str]) -> Output {
    let out = lucent().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "lucent {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The renders the tests share: a noisy denoised frame and a reference.
struct Frames {
    _dir: tempfile::TempDir,
    scene: PathBuf,
    noisy: PathBuf,
    reference: PathBuf,
}

fn frames() -> &'static Frames {
    static F: OnceLock<Frames> = OnceLock::new();
    F.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let scene = small_scene(dir.path());
        let (noisy, reference) = (dir.path().join("noisy.exr"), dir.path().join("ref.exr"));
        let s = scene.to_str().unwrap();
        let n = NOISY.to_string();
        run(&["render", s, "--threads", "1", "--denoise", "-q"]
            .iter()
            .chain(&["-o", noisy.to_str().unwrap(), "--spp", &n])
            .copied()
            .collect::<Vec<_>>());
        let r = REFERENCE.to_string();
        let args = ["render", s, "-o", reference.to_str().unwrap(), "--spp", &r];
        run(&[&args[..], &["--seed", "7", "-q", "--threads", "2"]].concat());
        Frames {
            _dir: dir,
            scene,
            noisy,
            reference,
        }
    })
}

/// The three channels `names` as pixels.
pub(crate) fn rgb(ch: &BTreeMap<String, Vec<f32>>, names: [&str; 3]) -> Vec<Vec3> {
    let [r, g, b] = names.map(|n| &ch[n]);
    (0..r.len()).map(|i| Vec3::new(r[i], g[i], b[i])).collect()
}

/// Relative MSE against `reference` (mean over pixels and channels of
/// (x - r)² / (r² + 0.01)).
pub(crate) fn rel_mse(x: &[Vec3], reference: &[Vec3]) -> f64 {
    let mut s = 0.0;
    for (a, r) in x.iter().zip(reference) {
        for c in 0..3 {
            let (a, r) = (a[c] as f64, r[c] as f64);
            s += (a - r).powi(2) / (r * r + 0.01);
        }
    }
    s / (3 * x.len()) as f64
}

#[test]
fn the_denoised_layer_is_closer_to_the_reference_than_the_noisy_beauty() {
    if !have_oidn() {
        return;
    }
    let f = frames();
    let noisy = channels(&f.noisy);
    let reference = rgb(&channels(&f.reference), ["R", "G", "B"]);
    let before = rel_mse(&rgb(&noisy, ["R", "G", "B"]), &reference);
    let clean = rgb(&noisy, ["denoised.R", "denoised.G", "denoised.B"]);
    let after = rel_mse(&clean, &reference);
    eprintln!("relMSE noisy {before:.5}, denoised {after:.5}");
    assert!(after < 0.3 * before, "noisy {before}, denoised {after}");
    assert!(clean
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
}

#[test]
fn a_flipped_or_swapped_guide_denoises_worse() {
    if !have_oidn() {
        return;
    }
    let f = frames();
    // the pseudo-random stream: a wrong guide's cost grows with the noise
    // the denoiser removes, and on this nearly symmetric box the
    // sequence's cleaner 8 samples leave a mirrored albedo within 2 % of
    // the right one
    let dir = tempfile::tempdir().unwrap();
    let noisy = dir.path().join("noisy.exr");
    let (s, n) = (f.scene.to_str().unwrap(), NOISY.to_string());
    let args = [
        "render",
        s,
        "--threads",
        "1",
        "--denoise",
        "-q",
        "--spp",
        &n,
    ];
    run(&[
        &args[..],
        &["--sampler", "random", "-o", noisy.to_str().unwrap()],
    ]
    .concat());
    let ch = channels(&noisy);
    let reference = rgb(&channels(&f.reference), ["R", "G", "B"]);
    let color = rgb(&ch, ["R", "G", "B"]);
    let albedo = rgb(&ch, ["albedo.R", "albedo.G", "albedo.B"]);
    let normal = rgb(&ch, ["N.X", "N.Y", "N.Z"]);
    let (w, h) = (W as usize, H as usize);
    // left-right mirrored, and read column by column (a stride mistake)
    let mirror = |v: &[Vec3]| -> Vec<Vec3> {
        v.chunks(w)
            .flat_map(|row| row.iter().rev())
            .copied()
            .collect()
    };
    let transpose =
        |v: &[Vec3]| -> Vec<Vec3> { (0..w * h).map(|i| v[(i % h) * w + i / h]).collect() };
    let err = |albedo: &[Vec3], normal: &[Vec3]| {
        let input = DenoiseInput {
            width: W,
            height: H,
            color: &color,
            albedo,
            normal,
        };
        rel_mse(
            &denoise(&input, &DenoiseOptions::with_threads(Some(1))).unwrap(),
            &reference,
        )
    };
    let right = err(&albedo, &normal);
    let noisy = rel_mse(&color, &reference);
    let abs: Vec<Vec3> = normal.iter().map(|n| n.abs()).collect();
    let wrong = [
        ("albedo mirrored", err(&mirror(&albedo), &normal)),
        ("albedo transposed", err(&transpose(&albedo), &normal)),
        ("normal transposed", err(&albedo, &transpose(&normal))),
        ("albedo and normal swapped", err(&abs, &albedo)),
    ];
    eprintln!("relMSE noisy {noisy:.5}, right guides {right:.5}, wrong: {wrong:?}");
    for (what, e) in wrong {
        // OIDN leans on the noisy beauty where a guide disagrees with it,
        // so a wrong guide costs little on this scene (4 to 10 %, and
        // 2× for a swap): the margin is small but the runs are exact
        // repeats (same input, same threads), so it cannot flicker
        assert!(
            right < 0.97 * e,
            "{what}: {e} against {right} with the right guides"
        );
    }
}

#[test]
fn the_denoised_layer_is_named_as_documented_beside_the_unchanged_beauty() {
    if !have_oidn() {
        return;
    }
    let f = frames();
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain.exr");
    let s = f.scene.to_str().unwrap();
    let n = NOISY.to_string();
    let args = [
        "render",
        s,
        "-o",
        plain.to_str().unwrap(),
        "--spp",
        &n,
        "-q",
    ];
    run(&[&args[..], &["--aov", "albedo,N"]].concat());
    let (with, without) = (channels(&f.noisy), channels(&plain));
    let names: Vec<&String> = with.keys().collect();
    for c in ["denoised.R", "denoised.G", "denoised.B", "albedo.R", "N.X"] {
        assert!(with.contains_key(c), "{c} missing from {names:?}");
    }
    assert_eq!(with.len(), without.len() + 3, "{names:?}");
    for (name, v) in &without {
        assert_eq!(v, &with[name], "{name} changed by --denoise");
    }
}

/// `lucent denoise` on a merged frame, and `merge --denoise`, give the
/// single render's denoised layer bit for bit (same threads).
#[test]
fn denoising_after_a_merge_equals_denoising_the_single_render() {
    if !have_oidn() {
        return;
    }
    let f = frames();
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let s = f.scene.to_str().unwrap();
    let n = NOISY.to_string();
    for t in ["0/2", "1/2"] {
        let out = p(&format!("part{}.exr", &t[..1]));
        run(&[
            "render", s, "--tile", t, "--spp", &n, "-q", "--aov", "albedo,N", "-o", &out,
        ]);
    }
    run(&[
        "merge",
        &p("part0.exr"),
        &p("part1.exr"),
        "-o",
        &p("m.exr"),
        "-q",
    ]);
    run(&[
        "denoise",
        &p("m.exr"),
        "-o",
        &p("d.exr"),
        "--threads",
        "1",
        "-q",
    ]);
    let (parts, merged) = ([p("part0.exr"), p("part1.exr")], p("md.exr"));
    let args = [
        "merge",
        &parts[0],
        &parts[1],
        "-o",
        &merged,
        "-q",
        "--denoise",
    ];
    run(&[&args[..], &["--threads", "1"]].concat());
    let single = channels(&f.noisy);
    for file in [p("d.exr"), merged] {
        let other = channels(Path::new(&file));
        for c in ["denoised.R", "denoised.G", "denoised.B"] {
            assert!(
                single[c] == other[c],
                "{file}: {c} differs from the single render's"
            );
        }
    }
}

#[test]
fn denoise_refuses_bad_input_with_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = small_scene(dir.path());
    let s = scene.to_str().unwrap();
    let plain = dir.path().join("plain.exr");
    let pl = plain.to_str().unwrap();
    let out = lucent()
        .args(["render", s, "-o", pl, "--spp", "1", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let libm = ["/lib/x86_64-linux-gnu", "/lib/aarch64-linux-gnu"]
        .iter()
        .map(|d| format!("{d}/libm.so.6"))
        .find(|p| Path::new(p).exists())
        .unwrap();
    let cases: Vec<(Option<&str>, Vec<&str>, String)> = vec![
        (
            Some("/nonexistent/libOpenImageDenoise.so.2"),
            vec!["render", s, "--spp", "1", "--denoise"],
            "LUCENT_OIDN=/nonexistent/libOpenImageDenoise.so.2: cannot load it".into(),
        ),
        (
            Some(&libm),
            vec!["denoise", pl],
            format!("{libm} is not an Open Image Denoise 2 library: it has no oidnNewDevice"),
        ),
        (
            None,
            vec!["render", s, "--spp", "1", "--denoise", "--tile", "0/2"],
            "--denoise: a part is not denoised".into(),
        ),
        (
            None,
            vec!["denoise", pl],
            format!("{pl}: field `channels`: no albedo.R channel"),
        ),
    ];
    for (lib, args, needle) in cases {
        // a frame's channels are checked once the library is loaded
        if lib.is_none() && args[0] == "denoise" && !have_oidn() {
            continue;
        }
        let out_dir = tempfile::tempdir().unwrap();
        let o = out_dir.path().join("o.exr");
        let mut cmd = lucent();
        cmd.args(&args).args(["-o", o.to_str().unwrap(), "-q"]);
        if let Some(l) = lib {
            cmd.env("LUCENT_OIDN", l);
        }
        let r = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(&needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(std::fs::read_dir(out_dir.path()).unwrap().count(), 0);
    }
}

#[test]
fn a_frame_with_nan_is_refused_naming_the_channel_and_pixel() {
    if !have_oidn() {
        return;
    }
    let f = frames();
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("nan.exr");
    let mut image = crate::common::exr_file::first_layer(&f.noisy);
    for c in image.layer_data.channel_data.list.iter_mut() {
        if c.name.to_string() == "G" {
            if let FlatSamples::F32(v) = &mut c.sample_data {
                v[W as usize * 3 + 5] = f32::NAN;
            }
        }
    }
    use exr::prelude::WritableImage;
    image.write().to_file(&bad).unwrap();
    let o = dir.path().join("o.exr");
    let r = lucent()
        .args(["denoise", bad.to_str().unwrap(), "-o", o.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("field `G`: not finite at pixel (5, 3): NaN"),
        "{err}"
    );
    assert!(!o.exists() && !dir.path().join("o.png").exists());
}

/// `lucent info` names the OIDN it loaded and its version, or says why
/// there is none.
#[test]
fn info_names_the_denoiser_or_why_there_is_none() {
    let info = |lib: &str| {
        let out = lucent()
            .env("LUCENT_OIDN", lib)
            .arg("info")
            .output()
            .unwrap();
        assert!(out.status.success());
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let text = info("/nonexistent/libOpenImageDenoise.so.2");
    assert!(
        text.contains("denoiser: unavailable (cannot denoise: LUCENT_OIDN=/nonexistent/"),
        "{text}"
    );
    if !have_oidn() {
        return;
    }
    let lib = std::env::var("LUCENT_OIDN").unwrap();
    let text = info(&lib);
    let line = text.lines().find(|l| l.starts_with("denoiser:")).unwrap();
    assert!(
        line.starts_with("denoiser: Open Image Denoise 2."),
        "{line}"
    );
    assert!(line.ends_with(&format!("({lib})")), "{line}");
}
