//! Huge but finite numbers: geometry, camera or
//! subsurface radii that end up far beyond the supported range
//! (docs/scene-format.md, "Supported ranges") must fail at load time with
//! exit code 2, naming the file, the line and the field that put the value
//! out of range, and write nothing. Unchecked, these scenes would pass the
//! loader and Embree would abort the process (SIGABRT in its `ray.valid()`
//! assertion), so each case runs the real binary as a child process: an
//! abort shows up as a failed test, not a dead test runner.

use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Output};

const BASE: &str = "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 0, 0]\nresolution = [16, 16]\n\
[environment]\nradiance = [1, 1, 1]\n\
[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
[materials.s]\ntype = \"subsurface\"\nalbedo = [0.8, 0.8, 0.8]\ndmfp = [1, 1, 1]\n";

struct Case {
    name: &'static str,
    /// Text before the base scene (top-level keys).
    head: &'static str,
    /// Text after it (shapes, materials).
    tail: &'static str,
    /// Written as `mesh.obj` next to the scene.
    obj: Option<&'static str>,
    /// The error's prefix: `FILE:LINE: field `F`` with LINE the first line
    /// of FILE (`scene.toml` or `mesh.obj`) containing `line_of`.
    file: &'static str,
    line_of: &'static str,
    field: Option<&'static str>,
}

fn cases() -> Vec<Case> {
    let shape = |extra| Case {
        name: "",
        head: "",
        tail: extra,
        obj: None,
        file: "scene.toml",
        line_of: "",
        field: None,
    };
    vec![
        Case {
            name: "OBJ vertex near 1e30",
            obj: Some("v -1e30 -1e30 -1e30\nv 1e30 -1e30 -1e30\nv 0 1e30 -1e30\nf 1 2 3\n"),
            file: "mesh.obj",
            line_of: "v -1e30",
            tail: "[[shapes]]\ntype = \"obj\"\nfile = \"mesh.obj\"\nmaterial = \"m\"\n",
            ..shape("")
        },
        Case {
            name: "scale 1e30",
            line_of: "scale",
            field: Some("shapes[0].scale"),
            ..shape("[[shapes]]\ntype = \"box\"\nmaterial = \"m\"\nscale = 1e30\n")
        },
        Case {
            name: "scale 1e25 on an OBJ within range",
            obj: Some("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            line_of: "scale",
            field: Some("shapes[0].scale"),
            ..shape(
                "[[shapes]]\ntype = \"obj\"\nfile = \"mesh.obj\"\nmaterial = \"m\"\nscale = [1, 1e25, 1]\n",
            )
        },
        Case {
            name: "translate 1e25 in view",
            line_of: "translate",
            field: Some("shapes[0].translate"),
            ..shape(
                "[[shapes]]\ntype = \"box\"\nmaterial = \"m\"\nscale = 5\ntranslate = [0, 0, -1e25]\n",
            )
        },
        Case {
            name: "camera look_from 1e20",
            line_of: "look_from",
            field: Some("camera.look_from"),
            ..shape("[[shapes]]\ntype = \"box\"\nmaterial = \"m\"\n")
        },
        Case {
            name: "dmfp 1e30",
            line_of: "dmfp = [1e30",
            field: Some("materials.h.dmfp"),
            ..shape(
                "[materials.h]\ntype = \"subsurface\"\nalbedo = [0.8, 0.8, 0.8]\ndmfp = [1e30, 1, 1]\n\
                 [[shapes]]\ntype = \"sphere\"\nsubdivisions = 1\nmaterial = \"h\"\n",
            )
        },
        Case {
            name: "tiny sigma_a: a huge measured radius",
            line_of: "sigma_a",
            field: Some("materials.h.sigma_a"),
            ..shape(
                "[materials.h]\ntype = \"subsurface\"\nalbedo = [0.8, 0.8, 0.8]\n\
                 sigma_s_prime = [1e-20, 1, 1]\nsigma_a = [1e-20, 1, 1]\n\
                 [[shapes]]\ntype = \"sphere\"\nsubdivisions = 1\nmaterial = \"h\"\n",
            )
        },
        Case {
            name: "units_per_mm near f32::MAX",
            head: "units_per_mm = 3.4e38\n",
            line_of: "units_per_mm",
            field: Some("units_per_mm"),
            ..shape("[[shapes]]\ntype = \"sphere\"\nsubdivisions = 1\nmaterial = \"s\"\n")
        },
        Case {
            name: "units_per_mm 1e20 with a preset",
            head: "units_per_mm = 1e20\n",
            line_of: "units_per_mm",
            field: Some("units_per_mm"),
            ..shape(
                "[materials.h]\ntype = \"subsurface\"\npreset = \"marble\"\n\
                 [[shapes]]\ntype = \"sphere\"\nsubdivisions = 1\nmaterial = \"h\"\n",
            )
        },
    ]
}

fn scene_text(c: &Case) -> String {
    let base = if c.name.starts_with("camera") {
        BASE.replace("look_from = [0, 1, 5]", "look_from = [1e20, 1, 5]")
    } else {
        BASE.to_string()
    };
    format!("{}{base}{}", c.head, c.tail)
}

fn render(dir: &Path, accel: Option<&str>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_lucent"));
    cmd.arg("render")
        .arg(dir.join("scene.toml"))
        .arg("-o")
        .arg(dir.join("out.exr"))
        .args(["--spp", "1", "--threads", "1"]);
    if let Some(a) = accel {
        cmd.args(["--accel", a]);
    }
    cmd.output().expect("run lucent")
}

/// The backends to try: the default (Embree in a default build) and each
/// one this build has.
fn backends() -> Vec<Option<&'static str>> {
    let mut b = vec![None, Some("bvh")];
    if cfg!(feature = "embree") {
        b.push(Some("embree"));
    }
    b
}

#[test]
fn out_of_range_inputs_exit_2_with_file_line_and_field() {
    let mut failures = Vec::new();
    for c in cases() {
        let dir = tempfile::tempdir().unwrap();
        let text = scene_text(&c);
        std::fs::write(dir.path().join("scene.toml"), &text).unwrap();
        if let Some(obj) = c.obj {
            std::fs::write(dir.path().join("mesh.obj"), obj).unwrap();
        }
        let named = if c.file == "mesh.obj" {
            c.obj.unwrap()
        } else {
            &text
        };
        let line = 1 + named
            .lines()
            .position(|l| l.contains(c.line_of))
            .unwrap_or_else(|| panic!("{}: no line with {:?}", c.name, c.line_of));
        let mut want = format!("{}:{line}: ", dir.path().join(c.file).display());
        if let Some(f) = c.field {
            want.push_str(&format!("field `{f}`: "));
        }
        for accel in backends() {
            let out = render(dir.path(), accel);
            let stderr = String::from_utf8_lossy(&out.stderr);
            let label = format!("{} (--accel {})", c.name, accel.unwrap_or("default"));
            if let Some(sig) = out.status.signal() {
                failures.push(format!("{label}: killed by signal {sig}; stderr: {stderr}"));
                continue;
            }
            if out.status.code() != Some(2) {
                failures.push(format!(
                    "{label}: exit {:?}, expected 2; stderr: {stderr}",
                    out.status.code()
                ));
                continue;
            }
            if !stderr.contains(&want) || !stderr.contains("Supported ranges") {
                failures.push(format!(
                    "{label}: expected `{want}…Supported ranges…`, got: {stderr}"
                ));
            }
            if dir.path().join("out.exr").exists() || dir.path().join("out.png").exists() {
                failures.push(format!("{label}: wrote output on failure"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Numbers that are large as written but land in range after the transform
/// still render, on every backend, with no refused queries.
#[test]
fn in_range_after_the_transform_renders() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("mesh.obj"),
        "v -5e9 -5e9 -5e9\nv 5e9 -5e9 -5e9\nv 0 5e9 -5e9\nf 1 2 3\n",
    )
    .unwrap();
    let text = format!(
        "{BASE}[[shapes]]\ntype = \"obj\"\nfile = \"mesh.obj\"\nmaterial = \"m\"\nscale = 1e-3\n\
         [[shapes]]\ntype = \"box\"\nmaterial = \"s\"\nscale = 1e6\ntranslate = [0, -1e6, 0]\n"
    );
    std::fs::write(dir.path().join("scene.toml"), text).unwrap();
    for accel in backends() {
        let out = render(dir.path(), accel);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.signal(), None, "{accel:?}: {stderr}");
        assert_eq!(out.status.code(), Some(0), "{accel:?}: {stderr}");
        assert!(!stderr.contains("warning"), "{accel:?}: {stderr}");
        std::fs::remove_file(dir.path().join("out.exr")).unwrap();
    }
}
