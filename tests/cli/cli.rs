//! The `lucent` command line end to end: render the Cornell box, check the
//! outputs, determinism across thread counts at the file level, and `info`.

use std::path::Path;
use std::process::Command;

fn lucent() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
}

fn scene(name: &str) -> String {
    format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn render(args: &[&str]) -> std::process::Output {
    let out = lucent().arg("render").args(args).output().unwrap();
    assert!(
        out.status.success(),
        "lucent render {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn renders_the_cornell_box_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("cornell.exr");
    let out = render(&[
        &scene("cornell.toml"),
        "-o",
        exr.to_str().unwrap(),
        "--spp",
        "2",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    // the closing summary: time, samples/s and rays/s
    assert!(
        stderr.contains(" s wall") && stderr.contains("Msamples/s") && stderr.contains("Mrays/s"),
        "{stderr}"
    );
    let film = lucent::film::Film::read_exr(&exr).unwrap();
    assert_eq!((film.width, film.height), (512, 512));
    // lit, finite, and the light itself is the brightest thing in view
    let mean: f32 = film
        .pixels
        .iter()
        .map(|p| p.element_sum() / 3.0)
        .sum::<f32>()
        / film.pixels.len() as f32;
    assert!(
        mean > 0.05
            && film
                .pixels
                .iter()
                .all(|p| p.is_finite() && p.min_element() >= 0.0),
        "mean {mean}"
    );
    let png = image::open(dir.path().join("cornell.png")).unwrap();
    assert_eq!((png.width(), png.height()), (512, 512));
    // exactly the two outputs: no temporary files left behind
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["cornell.exr", "cornell.png"]);
}

/// The EXR's bytes with the values of its run-dependent header attributes
/// blanked: `lucent/renderTime` (a 4-byte float) and `capDate` (the
/// 19-character UTC date and time the frame was made).
fn without_run_attributes(mut bytes: Vec<u8>) -> Vec<u8> {
    for (key, len) in [
        (&b"lucent/renderTime\0float\0\x04\0\0\0"[..], 4),
        (&b"capDate\0string\0\x13\0\0\0"[..], 19),
    ] {
        let at = bytes
            .windows(key.len())
            .position(|w| w == key)
            .unwrap_or_else(|| panic!("no {} attribute", String::from_utf8_lossy(key)))
            + key.len();
        bytes[at..at + len].fill(0);
    }
    bytes
}

#[test]
fn exr_is_bitwise_identical_for_one_and_two_threads() {
    // With subsurface scattering when the build has it.
    let name = if cfg!(feature = "subsurface") {
        "marble-bunny.toml"
    } else {
        "cornell.toml"
    };
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("t1.exr");
    let b = dir.path().join("t2.exr");
    for (path, threads) in [(&a, "1"), (&b, "2")] {
        render(&[
            &scene(name),
            "-o",
            path.to_str().unwrap(),
            "--spp",
            "1",
            "--threads",
            threads,
            "--quiet",
        ]);
    }
    let (fa, fb) = (
        without_run_attributes(std::fs::read(&a).unwrap()),
        without_run_attributes(std::fs::read(&b).unwrap()),
    );
    assert!(fa.len() > 1000);
    assert!(fa == fb, "EXRs differ between --threads 1 and --threads 2");
    // and a different seed really changes the image
    let c = dir.path().join("seed.exr");
    render(&[
        &scene(name),
        "-o",
        c.to_str().unwrap(),
        "--spp",
        "1",
        "--seed",
        "9",
        "--quiet",
    ]);
    assert!(std::fs::read(&c).unwrap() != fa);
}

#[test]
fn bad_arguments_exit_2_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("x.exr");
    for args in [
        vec![
            scene("cornell.toml"),
            "-o".into(),
            exr.to_str().unwrap().into(),
            "--spp".into(),
            "0".into(),
        ],
        vec![
            scene("cornell.toml"),
            "-o".into(),
            dir.path().join("x.png").to_str().unwrap().into(),
        ],
        vec![
            scene("cornell.toml"),
            "-o".into(),
            "/nonexistent-dir/x.exr".into(),
        ],
        vec![
            scene("marble-bunny.toml"),
            "-o".into(),
            exr.to_str().unwrap().into(),
            "--radius".into(),
            "table:1".into(),
        ],
        vec![
            scene("marble-bunny.toml"),
            "-o".into(),
            exr.to_str().unwrap().into(),
            "--rmax-quantile".into(),
            "1".into(),
        ],
        // the file options: out of range, lossy, unknown
        vec![
            scene("cornell.toml"),
            "-o".into(),
            exr.to_str().unwrap().into(),
            "--cryptomatte-ranks".into(),
            "0".into(),
        ],
        vec![
            scene("cornell.toml"),
            "-o".into(),
            exr.to_str().unwrap().into(),
            "--exr-compression".into(),
            "b44".into(),
        ],
        vec![
            scene("cornell.toml"),
            "-o".into(),
            exr.to_str().unwrap().into(),
            "--aov-precision".into(),
            "double".into(),
        ],
    ] {
        let out = lucent().arg("render").args(&args).output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn info_lists_the_backends() {
    let out = lucent().arg("info").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("backends: bvh"), "{text}");
    if cfg!(feature = "embree") {
        assert!(text.contains("embree3: Embree 3."), "{text}");
        assert!(text.contains("default backend: embree"), "{text}");
    } else {
        assert!(
            text.contains("built without the `embree` feature"),
            "{text}"
        );
    }
    if !cfg!(feature = "embree4") {
        assert!(
            text.contains("embree4: unavailable (this lucent was built without the `embree4`"),
            "{text}"
        );
    }
    if !cfg!(feature = "embree") && !cfg!(feature = "embree4") {
        assert!(text.contains("default backend: bvh"), "{text}");
    }
    assert!(Path::new(env!("CARGO_BIN_EXE_lucent")).exists());
}

/// Under scripts/test.sh (`LUCENT_EMBREE4` set to the wheel's 4.4.0),
/// `info` lists both Embrees with their versions and where Embree 4 came
/// from, and `--accel embree` means Embree 4.
#[cfg(all(feature = "embree", feature = "embree4"))]
#[test]
fn info_lists_both_embrees_with_versions() {
    let Some(lib) = std::env::var_os("LUCENT_EMBREE4") else {
        eprintln!("LUCENT_EMBREE4 not set: not tested");
        return;
    };
    let out = lucent().arg("info").output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("backends: bvh, embree3, embree4"), "{text}");
    let want = format!("embree4: Embree 4.4.0 ({})", lib.to_string_lossy());
    assert!(text.contains(&want), "{text}");
    assert!(text.contains("default backend: embree (embree4)"), "{text}");
}

/// A missing, wrong or unknown Embree 4 is bad input for `--accel embree4`
/// (exit 2, a message naming what was found and what is needed, nothing
/// written), and `--accel embree` falls back to Embree 3: never a crash.
#[cfg(all(feature = "embree", feature = "embree4"))]
#[test]
fn a_bad_embree4_library_is_refused_with_what_was_found() {
    let embree3 = ["/usr/lib/x86_64-linux-gnu", "/usr/lib/aarch64-linux-gnu"]
        .iter()
        .map(|d| format!("{d}/libembree3.so.3"))
        .find(|p| Path::new(p).exists())
        .expect("Embree 3 is installed (the `embree` feature links it)");
    let libm = ["/lib/x86_64-linux-gnu", "/lib/aarch64-linux-gnu"]
        .iter()
        .map(|d| format!("{d}/libm.so.6"))
        .find(|p| Path::new(p).exists())
        .unwrap();
    let cases = [
        (
            "/nonexistent/libembree4.so.4".to_string(),
            "LUCENT_EMBREE4=/nonexistent/libembree4.so.4: cannot load it".to_string(),
        ),
        (
            embree3.clone(),
            format!("{embree3} is Embree 3.13.5, not Embree 4: the embree4 backend needs Embree 4.3 to 4.4"),
        ),
        (
            libm.clone(),
            format!("{libm} is not an Embree 4 library: it has no rtcNewDevice"),
        ),
    ];
    for (lib, needle) in cases {
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("x.exr");
        let run = |accel: &str| {
            lucent()
                .env("LUCENT_EMBREE4", &lib)
                .arg("render")
                .args([&scene("cornell.toml"), "-o", exr.to_str().unwrap()])
                .args(["--spp", "1", "-q", "--accel", accel])
                .output()
                .unwrap()
        };
        let out = run("embree4");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{lib}: {err}");
        assert!(err.contains(&needle), "{lib}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let out = run("embree");
        assert!(out.status.success(), "{lib}: embree3 fallback failed");
        let info = lucent()
            .env("LUCENT_EMBREE4", &lib)
            .arg("info")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&info.stdout);
        assert!(info.status.success());
        assert!(text.contains("default backend: embree (embree3)"), "{text}");
        assert!(
            text.contains(&format!("embree4: unavailable ({needle}")),
            "{text}"
        );
    }
}

/// A BVH-only binary asked for Embree says it was built without the
/// `embree` feature and how to get it, exits 2 and writes nothing.
#[cfg(not(feature = "embree"))]
#[test]
fn accel_embree_without_the_feature_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("x.exr");
    let out = lucent()
        .arg("render")
        .args([&scene("cornell.toml"), "-o", exr.to_str().unwrap()])
        .args(["--spp", "1", "--accel", "embree"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("without the `embree` feature"), "{err}");
    assert!(
        err.contains("--accel bvh") && err.contains("libembree-dev"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// `render --help` offers every render flag of the option table with its
/// description and default, and none of the research variants (they stay
/// accepted, for studies and tests).
#[cfg(feature = "subsurface")]
#[test]
fn render_help_offers_the_option_table_without_research_variants() {
    let out = lucent().args(["render", "--help"]).output().unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    for row in lucent::materials::OPTIONS.iter().filter(|o| o.flag) {
        assert!(help.contains(&format!("--{}", row.flag_name())), "{help}");
        assert!(
            help.contains(row.description.split(':').next().unwrap()),
            "{help}"
        );
    }
    let words: Vec<&str> = help
        .split(|c: char| !(c.is_alphanumeric() || c == '-'))
        .collect();
    for research in [
        "normal",
        "single",
        "uniform",
        "table",
        "table-uniform",
        "force",
    ] {
        assert!(!words.contains(&research), "`{research}` offered:\n{help}");
    }
    assert!(!help.contains("the seed"), "{help}");
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("axes.exr");
    let mut args = vec![scene("smooth-sphere.toml"), "-o".into()];
    args.push(exr.to_str().unwrap().into());
    for a in [
        "--spp",
        "1",
        "--crop",
        "120,120,136,136",
        "--axes",
        "normal",
    ] {
        args.push(a.into());
    }
    let out = lucent().arg("render").args(&args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
