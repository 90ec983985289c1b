//! Hostile input through the real binary: thread counts beyond
//! any machine, outputs that cannot all be written, OBJ files that mix
//! coloured and plain vertices, and special files (FIFOs, directories) given
//! as the scene or a mesh. Each must end promptly with a clear error (exit 2
//! for input, 1 for output) and leave nothing behind, or load.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const SCENE: &str = "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n\
                     [render]\nspp = 1\n\
                     [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
                     [environment]\nradiance = [1, 1, 1]\n\
                     [[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n";

/// A scene with one OBJ shape, `mesh.obj` beside it.
const OBJ_SCENE: &str =
    "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n\
                         [render]\nspp = 1\n\
                         [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
                         [environment]\nradiance = [1, 1, 1]\n\
                         [[shapes]]\ntype = \"obj\"\nfile = \"mesh.obj\"\nmaterial = \"white\"\n";

/// Runs `lucent ARGS`, killing it and failing the test if it has not ended
/// within 10 s (a FIFO opened for reading blocks forever).
fn lucent(args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > Duration::from_secs(10) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("lucent {args:?} did not end within 10 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `lucent render SCENE -o EXR --quiet`.
fn render_scene(scene: &Path, exr: &Path) -> Output {
    lucent(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--quiet",
    ])
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn write_scene(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("scene.toml");
    fs::write(&p, text).unwrap();
    p
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

// --- (2) thread counts

#[test]
fn thread_counts_beyond_the_bound_are_rejected_before_anything_starts() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), SCENE);
    let exr = dir.path().join("out.exr");
    for n in [
        "100000",
        "1025",
        "18446744073709551615",
        "18446744073709551616",
        "0",
    ] {
        let o = lucent(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
            "--quiet",
            "--threads",
            n,
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "--threads {n}: {e}");
        assert!(e.contains("--threads") && e.contains("1 to 1024"), "{e}");
        assert!(!exr.exists());
        let o = lucent(&[
            "study",
            scene.to_str().unwrap(),
            "-o",
            dir.path().join("study").to_str().unwrap(),
            "--threads",
            n,
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "study --threads {n}: {e}");
        assert!(e.contains("--threads") && e.contains("1 to 1024"), "{e}");
    }
    assert_eq!(names(dir.path()), ["scene.toml"]);
    // the bound itself is accepted
    let o = lucent(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--quiet",
        "--threads",
        "3",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn the_library_refuses_unbounded_thread_counts_too() {
    use lucent::render::{self, RenderOptions, MAX_THREADS};
    let scene = lucent::scene::load_str(SCENE, Path::new("mem.toml")).unwrap();
    let accel = lucent::accel::build(&scene.meshes, lucent::accel::Backend::Bvh).unwrap();
    for n in [MAX_THREADS + 1, usize::MAX] {
        let opts = RenderOptions {
            threads: Some(n),
            ..RenderOptions::default()
        };
        let e = render::render(&scene, accel.as_ref(), &opts).unwrap_err();
        assert!(e.is_input() && e.to_string().contains("1 to 1024"), "{e}");
    }
}

// --- (4) outputs committed together

#[test]
fn an_unwritable_png_leaves_no_exr_and_keeps_the_previous_one() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), SCENE);
    let exr = dir.path().join("out.exr");
    // the preview's path is a directory: the PNG cannot be written
    fs::create_dir(dir.path().join("out.png")).unwrap();
    let o = render_scene(&scene, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("out.png") && e.contains("directory"), "{e}");
    assert_eq!(names(dir.path()), ["out.png", "scene.toml"]);
    assert!(dir.path().join("out.png").is_dir());

    // an EXR from an earlier render stays as it was
    fs::write(&exr, b"earlier render").unwrap();
    let o = render_scene(&scene, &exr);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(fs::read(&exr).unwrap(), b"earlier render");
    assert_eq!(names(dir.path()), ["out.exr", "out.png", "scene.toml"]);
}

// --- (5) OBJ vertex colours

#[test]
fn obj_files_mixing_coloured_and_plain_vertices_load() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), OBJ_SCENE);
    for obj in [
        // some vertices coloured, some not
        "v -1 -1 0 1 0 0\nv 1 -1 0\nv 1 1 0 0 0 1\nv -1 1 0\nf 1 2 3\nf 1 3 4\n",
        // all coloured
        "v -1 -1 0 1 0 0\nv 1 -1 0 0 1 0\nv 1 1 0 0 0 1\nv -1 1 0 1 1 1\nf 1 2 3\nf 1 3 4\n",
        // coloured after plain, with a weight elsewhere
        "v -1 -1 0\nv 1 -1 0 0.5 0.5 0.5\nv 2 2 0 2\nv -1 1 0\nf 1 2 3 4\n",
    ] {
        fs::write(dir.path().join("mesh.obj"), obj).unwrap();
        let s = lucent::scene::load(&scene).unwrap_or_else(|e| panic!("{obj}: {e}"));
        assert_eq!(s.triangle_count(), 2, "{obj}");
        let m = &s.meshes[0];
        assert_eq!(m.positions().len(), 4, "{obj}");
        // positions, not colours: the square spans [-1, 1] in x and y
        assert!(
            m.positions()
                .iter()
                .all(|p| p.z.abs() < 1e-6 && p.x.abs() <= 1.0 + 1e-6 && p.y.abs() <= 1.0 + 1e-6),
            "{obj}: {:?}",
            m.positions()
        );
    }
    let o = render_scene(&scene, &dir.path().join("out.exr"));
    assert!(o.status.success(), "{}", stderr(&o));
}

// --- (7) special files

#[test]
fn a_fifo_as_the_scene_is_refused_promptly() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("scene.toml");
    mkfifo(&fifo);
    let exr = dir.path().join("out.exr");
    let o = render_scene(&fifo, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("scene.toml") && e.contains("not a regular file") && e.contains("FIFO"),
        "{e}"
    );
    assert!(!exr.exists());
    // through a symlink too (followed)
    let link = dir.path().join("link.toml");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    let o = render_scene(&link, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("link.toml") && e.contains("FIFO"), "{e}");
}

#[test]
fn a_fifo_as_an_obj_mesh_is_refused_promptly_at_its_scene_line() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), OBJ_SCENE);
    mkfifo(&dir.path().join("mesh.obj"));
    let exr = dir.path().join("out.exr");
    let o = render_scene(&scene, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    let line = OBJ_SCENE
        .lines()
        .position(|l| l.starts_with("file ="))
        .unwrap()
        + 1;
    assert!(e.contains(&format!("scene.toml:{line}:")), "{e}");
    assert!(
        e.contains("shapes[0].file") && e.contains("mesh.obj") && e.contains("FIFO"),
        "{e}"
    );
    assert!(!exr.exists());
}

/// The image files a scene names: a FIFO as the environment map, a
/// texture or an OBJ's material library is refused at once, naming the
/// file and the field (or the OBJ line), nothing written. Caught: the
/// environment image opened without the regular-file check (the loader
/// blocks in `open` until the test kills it).
#[test]
fn a_fifo_as_an_environment_texture_or_mtl_file_is_refused_promptly() {
    let env = SCENE.replace("radiance = [1, 1, 1]", "file = \"sky.exr\"\nintensity = 1");
    let texture = SCENE.replace(
        "albedo = [0.8, 0.8, 0.8]",
        "albedo_texture = \"t\"\n[textures.t]\nfile = \"t.png\"",
    );
    let mtl = OBJ_SCENE.replace("material = \"white\"\n", "");
    for (scene, fifo, field) in [
        (env.as_str(), "sky.exr", "environment.file"),
        (texture.as_str(), "t.png", "textures.t.file"),
        (mtl.as_str(), "m.mtl", "mesh.obj:1"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let path = write_scene(dir.path(), scene);
        fs::write(
            dir.path().join("mesh.obj"),
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        mkfifo(&dir.path().join(fifo));
        let exr = dir.path().join("out.exr");
        let o = render_scene(&path, &exr);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{fifo}: {e}");
        assert!(
            e.contains(fifo) && e.contains(field) && e.contains("FIFO"),
            "{fifo}: {e}"
        );
        assert!(!exr.exists(), "{fifo}: output written");
    }
}

#[test]
fn a_directory_or_device_as_the_scene_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("scenes.toml");
    fs::create_dir(&sub).unwrap();
    let exr = dir.path().join("out.exr");
    let o = render_scene(&sub, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("scenes.toml") && e.contains("a directory"),
        "{e}"
    );
    // /dev/zero never ends: refused without reading it
    if Path::new("/dev/zero").exists() {
        let o = lucent(&[
            "render",
            "/dev/zero",
            "-o",
            exr.to_str().unwrap(),
            "--quiet",
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(
            e.contains("/dev/zero") && e.contains("character device"),
            "{e}"
        );
    }
    assert!(!exr.exists());
}

// --- (6) unclear messages

#[test]
fn bytes_that_are_not_toml_or_not_utf8_are_named_at_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("out.exr");
    let scene = dir.path().join("scene.toml");
    let without_render = SCENE.replace("[render]\nspp = 1\n", "");
    let n = without_render.lines().count();
    // (text before the scene, after it, what the first line must contain)
    let cases: [(&[u8], &[u8], String); 4] = [
        (
            b"# caf\xe9\n",
            b"",
            "scene.toml:1: byte 0xe9 at column 6 is not valid UTF-8".into(),
        ),
        (
            b"# a \x0c form feed\n",
            b"",
            "scene.toml:1: control character U+000C (form feed)".into(),
        ),
        (
            b"",
            b"[render]\nspp = 1 # \x00\n",
            format!(
                "scene.toml:{}: field `render.spp`: control character U+0000 (NUL)",
                n + 2
            ),
        ),
        (
            b"",
            b"[render]\nseed =",
            format!(
                "scene.toml:{}: field `render.seed`: the file ends in the middle of an assignment",
                n + 2
            ),
        ),
    ];
    for (before, after, want) in cases {
        let text = [before, without_render.as_bytes(), after].concat();
        fs::write(&scene, &text).unwrap();
        let o = render_scene(&scene, &exr);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        let first = e.lines().next().unwrap_or("");
        assert!(first.contains(&want), "{first:?} lacks {want:?}");
        assert_eq!(names(dir.path()), ["scene.toml"]);
    }
    // an OBJ that is not UTF-8: its line and column
    fs::write(&scene, OBJ_SCENE).unwrap();
    fs::write(
        dir.path().join("mesh.obj"),
        b"v 0 0 0\nv 1 0 0 # \xff\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let o = render_scene(&scene, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("mesh.obj") && e.contains("byte 0xff at line 2, column 11"),
        "{e}"
    );
}

#[test]
fn a_scene_without_a_camera_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let no_camera = SCENE.replace(
        "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n",
        "",
    );
    assert!(!no_camera.contains("camera"));
    let scene = write_scene(dir.path(), &no_camera);
    let o = render_scene(&scene, &dir.path().join("out.exr"));
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("scene.toml: field `camera`: missing table `[camera]`"),
        "{e}"
    );
}

// --- (9) memory: requests that cannot fit fail before allocating

#[test]
fn images_meshes_and_files_beyond_the_bounds_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("out.exr");
    // 16384² pixels: each side is allowed, the product is not
    let scene = write_scene(
        dir.path(),
        &SCENE.replace("resolution = [8, 8]", "resolution = [16384, 16384]"),
    );
    let e = stderr(&render_scene(&scene, &exr));
    assert!(
        e.contains("scene.toml:4: field `camera.resolution`: [16384, 16384] is 268435456 pixels"),
        "{e}"
    );
    // seven spheres of 20·4⁹ triangles: refused before the first is built
    let sphere = "[[shapes]]\ntype = \"sphere\"\nmaterial = \"white\"\nsubdivisions = 9\n";
    let scene = write_scene(dir.path(), &format!("{SCENE}{}", sphere.repeat(7)));
    let start = Instant::now();
    let o = render_scene(&scene, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains(
            "field `shapes[7].subdivisions`: the scene's meshes add up to 36700162 triangles"
        ),
        "{e}"
    );
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
    // files too large to be scenes or meshes (sparse: no disk used)
    fs::File::create(dir.path().join("mesh.obj"))
        .unwrap()
        .set_len((512 << 20) + 1)
        .unwrap();
    let scene = write_scene(dir.path(), OBJ_SCENE);
    let e = stderr(&render_scene(&scene, &exr));
    assert!(
        e.contains("mesh.obj")
            && e.contains("the file is 536870913 bytes, more than the 536870912 supported"),
        "{e}"
    );
    let big = dir.path().join("big.toml");
    fs::File::create(&big)
        .unwrap()
        .set_len((16 << 20) + 1)
        .unwrap();
    let o = render_scene(&big, &exr);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("big.toml") && e.contains("more than the 16777216 supported"),
        "{e}"
    );
    assert_eq!(names(dir.path()), ["big.toml", "mesh.obj", "scene.toml"]);
    // a benchmark's query sets
    let out = dir.path().join("bench");
    let o = lucent(&["bench", "--rays", "1e9", "-o", out.to_str().unwrap()]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("1 to 20M"), "{e}");
    assert!(!out.exists());
}

#[test]
fn a_film_that_cannot_be_allocated_is_an_error_not_an_abort() {
    let e = lucent::film::Film::try_new(u32::MAX, u32::MAX).unwrap_err();
    assert!(!e.is_input());
    assert!(
        e.to_string().starts_with("out of memory: cannot allocate"),
        "{e}"
    );
    let f = lucent::film::Film::try_new(3, 2).unwrap();
    assert_eq!(f, lucent::film::Film::new(3, 2));
}

// --- (4) bench and study leave their output directory as it was

#[cfg(feature = "subsurface")]
#[test]
fn a_study_refuses_a_directory_it_cannot_resume_before_writing_in_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/slab-uniform.toml");
    let out = dir.path().join("study");
    fs::create_dir(&out).unwrap();
    let header = lucent_tools::study::results::HEADER;
    for (csv, want) in [
        ("not,our,header\n1,2,3\n".to_string(), "unexpected header"),
        (
            format!("{header}\nsome row\n"),
            "has rows but no results.key",
        ),
    ] {
        fs::write(out.join("results.csv"), &csv).unwrap();
        let o = lucent(&[
            "study",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--quick",
            "--quiet",
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains(want), "{e}");
        // no state/, no cached reference: as it was
        assert_eq!(names(&out), ["results.csv"]);
        assert_eq!(fs::read_to_string(out.join("results.csv")).unwrap(), csv);
    }
}

#[test]
fn a_benchmark_stopped_before_its_results_are_written_leaves_no_directory() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bench");
    let mut child = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args([
            "bench",
            "-o",
            out.to_str().unwrap(),
            "--sizes",
            "20",
            "--rays",
            "50000",
        ])
        .args(["--accel", "bvh", "--threads", "1", "--quiet"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let ok = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok);
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "bench still running"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = child.wait_with_output().unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{e}");
    assert!(e.contains("interrupted by SIGINT"), "{e}");
    assert!(!out.exists(), "{:?}", names(&out));
    assert_eq!(names(dir.path()), Vec::<String>::new());
    // an output path under a file is refused before anything is measured
    fs::write(dir.path().join("file"), b"").unwrap();
    let o = lucent(&[
        "bench",
        "-o",
        dir.path().join("file/out").to_str().unwrap(),
        "--sizes",
        "20",
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("exists and is not a directory"), "{e}");
}

#[test]
fn control_characters_from_the_input_are_escaped_in_messages() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), OBJ_SCENE);
    // an escape sequence (ESC [31m) inside a face index
    fs::write(
        dir.path().join("mesh.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\u{1b}[31m 3\n",
    )
    .unwrap();
    let o = render_scene(&scene, &dir.path().join("out.exr"));
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(!e.contains('\u{1b}'), "{e:?}");
    assert!(
        e.contains("mesh.obj:4:") && e.contains("2\\u{1b}[31m"),
        "{e:?}"
    );
}
