//! `[environment] file`: an OpenEXR and a Radiance `.hdr` image light the
//! render with their texels, and an image that cannot be used is a scene
//! error (exit 2) naming the file, the field and why, with nothing written.

use std::path::Path;
use std::process::Command;

const CAM: &str = "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\n\
                   [render]\nspp = 2\n";

/// A `w` × `h` RGB float OpenEXR whose texel (x, y) is `f(x, y)`.
fn write_exr(path: &Path, w: usize, h: usize, f: impl Fn(usize, usize) -> (f32, f32, f32) + Sync) {
    exr::prelude::write_rgb_file(path, w, h, f).unwrap();
}

/// An uncompressed Radiance RGBE file (flat scanlines: width < 8) of one
/// colour `rgbe`.
fn write_hdr(path: &Path, w: usize, h: usize, rgbe: [u8; 4]) {
    let mut bytes = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    for _ in 0..w * h {
        bytes.extend_from_slice(&rgbe);
    }
    std::fs::write(path, bytes).unwrap();
}

/// Renders `scene` (written beside whatever `setup` puts in the directory):
/// exit code, stderr, and the output's mean pixel if one was written.
fn render(scene: &str, setup: impl FnOnce(&Path)) -> (Option<i32>, String, Option<[f32; 3]>) {
    let dir = tempfile::tempdir().unwrap();
    setup(dir.path());
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out.exr");
    let res = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .arg("render")
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run lucent");
    let mean = out.exists().then(|| {
        let film = lucent::film::Film::read_exr(&out).unwrap();
        let n = film.pixels.len() as f32;
        let mut m = [0.0; 3];
        for p in &film.pixels {
            for (mc, pc) in m.iter_mut().zip([p.x, p.y, p.z]) {
                *mc += pc / n;
            }
        }
        m
    });
    (
        res.status.code(),
        String::from_utf8_lossy(&res.stderr).into_owned(),
        mean,
    )
}

/// With nothing in the scene every pixel sees the image: a uniform EXR of
/// (1, 0.5, 0.25) × intensity 2 × 2^−1, and a uniform `.hdr` of RGBE
/// (128, 64, 32, 129) ≈ (1, 0.5, 0.25). Catches a reader that swaps
/// channels or drops the exposure.
#[test]
fn exr_and_hdr_images_light_the_render() {
    let exr = format!("{CAM}[environment]\nfile = \"env.exr\"\nintensity = 2\nexposure = -1\n");
    let (code, stderr, mean) = render(&exr, |d| {
        write_exr(&d.join("env.exr"), 8, 4, |_, _| (1.0, 0.5, 0.25))
    });
    assert_eq!(code, Some(0), "{stderr}");
    let m = mean.unwrap();
    for (got, want) in m.iter().zip([1.0, 0.5, 0.25]) {
        assert!((got - want).abs() < 1e-5, "{m:?}");
    }
    // Negative channels (lossy compression's ringing) read as 0.
    let exr = format!("{CAM}[environment]\nfile = \"neg.exr\"\n");
    let (code, stderr, mean) = render(&exr, |d| {
        write_exr(&d.join("neg.exr"), 8, 4, |_, _| (1.0, -0.5, 0.25))
    });
    assert_eq!(code, Some(0), "{stderr}");
    let m = mean.unwrap();
    assert!(
        (m[0] - 1.0).abs() < 1e-5 && m[1] == 0.0 && (m[2] - 0.25).abs() < 1e-5,
        "{m:?}"
    );
    let hdr = format!("{CAM}[environment]\nfile = \"env.hdr\"\nrotation = 45\n");
    let (code, stderr, mean) = render(&hdr, |d| {
        write_hdr(&d.join("env.hdr"), 6, 3, [128, 64, 32, 129])
    });
    assert_eq!(code, Some(0), "{stderr}");
    let m = mean.unwrap();
    for (got, want) in m.iter().zip([1.0, 0.5, 0.25]) {
        assert!((got / want - 1.0).abs() < 0.01, "{m:?}");
    }
}

#[test]
fn unusable_images_exit_2_naming_file_field_and_reason() {
    let env = |file: &str| format!("{CAM}[environment]\nfile = \"{file}\"\n");
    type Setup = Box<dyn FnOnce(&Path)>;
    let rows: Vec<(String, Setup, &str)> = vec![
        (
            env("absent.exr"),
            Box::new(|_| {}),
            "absent.exr: cannot read it",
        ),
        (
            env("env.png"),
            Box::new(|d| std::fs::write(d.join("env.png"), b"\x89PNG").unwrap()),
            "unsupported image format \"png\"",
        ),
        (
            env("env.exr"),
            Box::new(|d| std::fs::write(d.join("env.exr"), b"not an exr").unwrap()),
            "env.exr: cannot read it",
        ),
        (
            env("big.hdr"),
            // The header alone: the size is refused before any texel is read.
            Box::new(|d| {
                std::fs::write(
                    d.join("big.hdr"),
                    b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 8192\n",
                )
                .unwrap()
            }),
            "the image is 8192×8192 = 67108864 texels, more than the 33554432",
        ),
        (
            env("nan.exr"),
            Box::new(|d| {
                write_exr(&d.join("nan.exr"), 4, 2, |x, y| {
                    let g = if (x, y) == (2, 1) { f32::NAN } else { 1.0 };
                    (1.0, g, 1.0)
                })
            }),
            "texel (column 2, row 1) has G = NaN",
        ),
        (
            format!("{CAM}[environment]\nfile = \"e.exr\"\nradiance = [1, 1, 1]\n"),
            Box::new(|_| {}),
            "field `environment.radiance`: `radiance` and `file` are two forms",
        ),
        (
            format!("{CAM}[environment]\nradiance = [1, 1, 1]\nrotation = 10\n"),
            Box::new(|_| {}),
            "field `environment.rotation`",
        ),
        (
            format!("{CAM}[environment]\nfile = \"e.exr\"\nexposure = 100\n"),
            Box::new(|_| {}),
            "field `environment.exposure`",
        ),
    ];
    for (scene, setup, fragment) in rows {
        let (code, stderr, mean) = render(&scene, setup);
        assert_eq!(code, Some(2), "{fragment:?}: {stderr}");
        assert!(
            stderr.contains(fragment),
            "stderr lacks {fragment:?}: {stderr}"
        );
        assert!(
            stderr.contains("scene.toml:") && stderr.contains("environment."),
            "no line or field: {stderr}"
        );
        assert!(mean.is_none(), "output written for {fragment:?}");
    }
}
