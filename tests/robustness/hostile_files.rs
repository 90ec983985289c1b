//! Every file lucent reads or writes outside the scene, attacked through
//! the real binary: damaged and forged parts and checkpoints, special files
//! where parts and study files belong, planted symlinks and set-aside
//! files at the temporary names, another render's checkpoint, closed
//! output streams, allocation failures under `prlimit`, and inputs at the
//! edge of their ranges. Each case must end promptly with exit 2 (bad
//! input) or 1 (a failure while working), naming what is wrong, and harm
//! no file lucent did not create; an abort or a hang fails the test.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use crate::part_forgery::{edit_channel, edit_header, set_words};

/// Two objects (a quad and a sphere) of two materials, 16×8 at 2 spp.
const SCENE: &str = "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\nresolution = [16, 8]\n\
                     [render]\nspp = 2\n\
                     [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
                     [materials.red]\ntype = \"diffuse\"\nalbedo = [0.8, 0.2, 0.2]\n\
                     [environment]\nradiance = [1, 1, 1]\n\
                     [[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n\
                     [[shapes]]\ntype = \"sphere\"\nmaterial = \"red\"\nsubdivisions = 1\nscale = 0.4\n";

/// The passes the forged parts carry: depth (the nearest hit) and object
/// IDs with their Cryptomatte coverage.
const AOV: &str = "Z,object_id,crypto_object";

/// How long a case may take before it counts as a hang (generous: the
/// machine may be shared; a hang never ends).
const LIMIT: Duration = Duration::from_secs(60);

/// Runs `program ARGS` in `dir`, killing it and failing the test if it has
/// not ended within [`LIMIT`].
fn run_in(dir: &Path, program: &str, args: &[&str]) -> Output {
    let owned: Vec<String> = args.iter().map(|a| a.to_string()).collect();
    crate::fuzz_files::run_limited(dir, Path::new(program), &owned, LIMIT)
        .unwrap_or_else(|| panic!("{program} {args:?} did not end within {LIMIT:?}"))
}

/// The binary under test: `LUCENT_FUZZ_BIN` if set (another build, to see
/// these cases fail on it), else this build's.
fn binary() -> String {
    std::env::var("LUCENT_FUZZ_BIN").unwrap_or_else(|_| env!("CARGO_BIN_EXE_lucent").into())
}

/// `lucent ARGS` in `dir`.
fn lucent(dir: &Path, args: &[&str]) -> Output {
    run_in(dir, &binary(), args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// That `o` exited with `code` (not a signal: an abort has no code) and its
/// message names every one of `names`.
#[track_caller]
fn assert_exit(o: &Output, code: i32, names: &[&str]) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{:?}: {e}", o.status);
    for n in names {
        assert!(e.contains(n), "the message does not name {n:?}: {e}");
    }
}

/// A directory with the scene and its two band parts `p0.exr`, `p1.exr`
/// (with [`AOV`]'s passes).
fn parts() -> (tempfile::TempDir, [PathBuf; 2]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("scene.toml"), SCENE).unwrap();
    for (i, p) in ["p0.exr", "p1.exr"].iter().enumerate() {
        let tile = format!("{i}/2");
        let o = lucent(
            d,
            &[
                "render",
                "scene.toml",
                "--quiet",
                "--aov",
                AOV,
                "--tile",
                &tile,
                "-o",
                p,
            ],
        );
        assert_exit(&o, 0, &[]);
    }
    let paths = [d.join("p0.exr"), d.join("p1.exr")];
    (dir, paths)
}

/// `lucent merge p0.exr p1.exr -o out.exr` in `d`.
fn merge(d: &Path) -> Output {
    lucent(
        d,
        &["merge", "p0.exr", "p1.exr", "-o", "out.exr", "--quiet"],
    )
}

/// The mistake: sizing buffers from a part's header before checking it,
/// so two 3 kB parts that claim an 8192² frame make `merge` allocate and
/// zero gigabytes (or abort), and a flipped bit in the data window makes
/// the EXR reader ask for 51 GB.
#[test]
fn parts_claiming_a_huge_frame_are_refused_before_anything_is_allocated() {
    let (dir, [p0, p1]) = parts();
    let d = dir.path();
    for (i, p) in [&p0, &p1].iter().enumerate() {
        edit_header(p, |h| {
            let y = 4096 * i as i32;
            h.set_text("lucent.frame", "[8192,8192]");
            let region = format!(r#"{{"x0":0,"y0":{y},"x1":8192,"y1":{}}}"#, y + 4096);
            h.set_text("lucent.region", &region);
            h.set_box("displayWindow", [0, 0, 8191, 8191]);
            h.set_box("dataWindow", [0, y, 8191, y + 4095]);
            h.set_chunks(4096 / 16);
        });
    }
    // under 1 GB: the 3 GB of the claimed frame's sums must never be asked for
    let args = ["merge", "p0.exr", "p1.exr", "-o", "out.exr", "--quiet"];
    let o = limited(d, "--as=1000000000", &args);
    assert_exit(&o, 2, &["p0.exr", "truncated or forged"]);
    assert!(!d.join("out.exr").exists());
    // one bit of the data window's ymax flipped (the EXR reader itself
    // refuses the chunk count, or lucent the region)
    let (dir, [p0, _]) = parts();
    let d = dir.path();
    edit_header(&p0, |h| {
        let mut w = h.get("dataWindow").to_vec();
        w[15] ^= 0x40;
        h.set("dataWindow", "box2i", w);
    });
    assert_exit(&merge(d), 2, &["p0.exr"]);
    fs::rename(&p0, d.join("out.partial.exr")).unwrap();
    let o = lucent(
        d,
        &[
            "render",
            "scene.toml",
            "--quiet",
            "--aov",
            AOV,
            "--tile",
            "0/2",
            "-o",
            "out.exr",
            "--resume",
            "out.partial.exr",
        ],
    );
    assert_exit(&o, 2, &["out.partial.exr"]);
}

/// The mistake: opening a part, a checkpoint or a study file without
/// checking it is a regular file: a FIFO blocks forever, /dev/zero is read
/// until memory runs out.
#[test]
fn special_files_as_parts_checkpoints_and_study_files_fail_at_once() {
    let (dir, [p0, _]) = parts();
    let d = dir.path();
    fs::remove_file(&p0).unwrap();
    mkfifo(&p0);
    assert_exit(&merge(d), 2, &["p0.exr", "FIFO"]);
    let o = lucent(
        d,
        &["merge", "/dev/zero", "p1.exr", "-o", "out.exr", "--quiet"],
    );
    assert_exit(&o, 2, &["/dev/zero", "character device"]);
    let o = lucent(
        d,
        &[
            "render",
            "scene.toml",
            "--quiet",
            "--aov",
            AOV,
            "--tile",
            "0/2",
            "-o",
            "x.exr",
            "--resume",
            "p0.exr",
        ],
    );
    assert_exit(&o, 2, &["p0.exr", "FIFO"]);
}

/// The study's directory: a FIFO as results.csv or results.key, and
/// results.csv linked to /dev/zero, are refused at once.
#[cfg(feature = "subsurface")]
#[test]
fn special_files_in_a_study_directory_fail_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let marble = SCENE.replace(
        "type = \"diffuse\"\nalbedo = [0.8, 0.2, 0.2]",
        "type = \"subsurface\"\npreset = \"marble\"",
    );
    fs::write(d.join("scene.toml"), marble).unwrap();
    for (name, how) in [
        ("results.csv", "fifo"),
        ("results.key", "fifo"),
        ("results.csv", "zero"),
    ] {
        let out = d.join(format!("study-{name}-{how}"));
        fs::create_dir(&out).unwrap();
        let target = out.join(name);
        if how == "fifo" {
            mkfifo(&target);
        } else {
            std::os::unix::fs::symlink("/dev/zero", &target).unwrap();
        }
        let o = lucent(
            d,
            &[
                "study",
                "scene.toml",
                "-o",
                out.to_str().unwrap(),
                "--quick",
            ],
        );
        assert_exit(&o, 2, &[name]);
    }
}

/// A forgery: the field and pixel its message must name, and how the part
/// is forged.
type Forgery = (&'static str, &'static str, fn(&Path));

/// The mistake: trusting a part's pixel values: another compression than
/// the writer's (PXR24 mangles u32 words into −2.3e18 radiance), sums no
/// number of samples adds up to, a high word stored above a missing one
/// (read as if the missing one were zero), NaN depth, IDs past the scene's objects,
/// coverage above one, an ID of 0 wrapping a counter. Each is refused
/// naming the file, the channel and the pixel.
#[test]
fn forged_part_values_are_refused_naming_file_channel_and_pixel() {
    let cases: [Forgery; 7] = [
        ("compression", "PXR24", |p| {
            edit_header(p, |h| h.set("compression", "compression", vec![5]))
        }),
        ("beauty.R", "pixel (2, 0)", |p| {
            set_words(p, "beauty.R", [true; 4], |w| w[3][2] = 0x4000_0000)
        }),
        ("beauty.G", "beauty.G.w3 without beauty.G.w2", |p| {
            set_words(p, "beauty.G", [true, true, false, true], |_| {})
        }),
        ("nearest.depth", "pixel (0, 1)", |p| {
            edit_channel(p, "nearest.depth", |v| v[16] = f32::NAN.to_bits())
        }),
        ("nearest.object", "pixel (5, 0)", |p| {
            edit_channel(p, "nearest.object", |v| v[5] = 4_000_000_000)
        }),
        ("coverage.object", "pixel (1, 1)", |p| {
            edit_channel(p, "coverage.object.n0", |v| v[17] = 1_000_000_000)
        }),
        ("coverage.object.id0", "pixel (8, 3)", |p| {
            edit_channel(p, "coverage.object.id0", |v| v[56] = 0)
        }),
    ];
    for (field, pixel, forge) in cases {
        let (dir, [p0, _]) = parts();
        forge(&p0);
        eprintln!("forged {field} at {pixel}");
        let o = merge(dir.path());
        assert_exit(&o, 2, &["p0.exr", field, pixel]);
        assert!(!dir.path().join("out.exr").exists(), "{field}");
    }
}

/// The mistake: opening the temporary file by a predictable name without
/// O_EXCL, so a symlink planted there makes lucent overwrite its target;
/// and moving a planted `.old.tmp` into place as if it were a previous
/// output.
#[test]
fn planted_symlinks_and_set_aside_files_are_never_followed_or_moved() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("scene.toml"), SCENE).unwrap();
    fs::write(d.join("victim"), b"not lucent's").unwrap();
    // `exec` keeps the shell's PID, the one the temporary name carries
    let tmp = lucent::film::temporary_path(&d.join("out.exr"), 0);
    let prefix = tmp
        .file_name()
        .unwrap()
        .to_str()
        .unwrap()
        .trim_end_matches("0.tmp");
    let script = format!(
        "ln -s victim {prefix}$$.tmp && exec {} render scene.toml -o out.exr --quiet",
        binary()
    );
    let o = run_in(d, "sh", &["-c", &script]);
    assert_exit(&o, 1, &["out.exr", "in the way"]);
    assert_eq!(fs::read(d.join("victim")).unwrap(), b"not lucent's");
    assert!(!d.join("out.exr").exists());
    // a set-aside file of a process that no longer runs stays where it is
    let dead = {
        let mut c = Command::new("true").spawn().unwrap();
        let pid = c.id();
        c.wait().unwrap();
        pid
    };
    let aside = lucent::film::set_aside_path(&d.join("out.partial.exr"), dead);
    fs::write(&aside, b"planted").unwrap();
    let o = lucent(d, &["render", "scene.toml", "-o", "out.exr", "--quiet"]);
    assert_exit(&o, 0, &[]);
    assert!(!d.join("out.partial.exr").exists());
    assert_eq!(fs::read(&aside).unwrap(), b"planted");
}

/// The mistake: deleting `OUT.partial.exr` without checking whose it is:
/// a quick render removed another render's 800 finished samples. And
/// `merge -o` writing over one of its own parts.
#[test]
fn another_renders_checkpoint_and_merge_inputs_are_kept() {
    let (dir, [p0, p1]) = parts();
    let d = dir.path();
    // a part of the same scene at other settings, where out.exr keeps its
    // checkpoint
    let o = lucent(
        d,
        &[
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "64",
            "--samples",
            "0..1",
            "-o",
            "out.partial.exr",
        ],
    );
    assert_exit(&o, 0, &[]);
    let foreign = fs::read(d.join("out.partial.exr")).unwrap();
    let o = lucent(
        d,
        &[
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "1",
            "-o",
            "out.exr",
        ],
    );
    assert_exit(&o, 2, &["out.partial.exr", "another render", "lucent.spp"]);
    assert_eq!(fs::read(d.join("out.partial.exr")).unwrap(), foreign);
    assert!(!d.join("out.exr").exists());
    // a file that is not a part at all
    fs::write(d.join("out.partial.exr"), b"notes").unwrap();
    let o = lucent(d, &["render", "scene.toml", "--quiet", "-o", "out.exr"]);
    assert_exit(&o, 2, &["out.partial.exr", "not a part"]);
    assert_eq!(fs::read(d.join("out.partial.exr")).unwrap(), b"notes");
    // merge's output is one of its inputs
    let before = fs::read(&p0).unwrap();
    let o = lucent(d, &["merge", "p0.exr", "p1.exr", "-o", "p0.exr", "--quiet"]);
    assert_exit(&o, 2, &["p0.exr", "input"]);
    assert_eq!(fs::read(&p0).unwrap(), before);
    assert!(p1.exists());
}

/// A pipe whose reading end is closed: a write to it fails with EPIPE
/// (Rust ignores SIGPIPE).
fn closed_pipe() -> Stdio {
    let mut fds = [0; 2];
    // SAFETY: `fds` has room for the two descriptors pipe() writes.
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
    // SAFETY: fds[0] is the reading end just opened, closed once here.
    unsafe { libc::close(fds[0]) };
    // SAFETY: fds[1] is an open descriptor this process owns and hands on.
    Stdio::from(unsafe { <std::os::fd::OwnedFd as std::os::fd::FromRawFd>::from_raw_fd(fds[1]) })
}

/// `lucent ARGS` in `dir` with stdout and/or stderr a closed pipe.
fn with_closed(dir: &Path, args: &[&str], out: bool, err: bool) -> Output {
    let pipe = |closed: bool| {
        if closed {
            closed_pipe()
        } else {
            Stdio::piped()
        }
    };
    let child = Command::new(binary())
        .args(args)
        .current_dir(dir)
        .stdout(pipe(out))
        .stderr(pipe(err))
        .spawn()
        .unwrap();
    child.wait_with_output().unwrap()
}

/// The mistake: `println!` on a closed stdout panics (exit 101, "failed
/// printing to stdout: Broken pipe"): `lucent info | head -0`, a render
/// whose stdout and stderr are gone after its outputs are written, and a
/// bad scene whose error cannot be shown must keep their exit status.
#[test]
fn closed_output_streams_end_quietly_with_the_commands_status() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert_eq!(
        with_closed(d, &["info"], true, false).status.code(),
        Some(0)
    );
    fs::write(d.join("scene.toml"), SCENE).unwrap();
    let o = with_closed(d, &["render", "scene.toml", "-o", "out.exr"], true, true);
    assert_eq!(o.status.code(), Some(0));
    assert!(d.join("out.exr").is_file());
    fs::write(d.join("bad.toml"), "[camera]\nlook_from = 1\n").unwrap();
    let o = with_closed(d, &["render", "bad.toml", "-o", "bad.exr"], true, true);
    assert_eq!(o.status.code(), Some(2));
}

/// `lucent ARGS` in `dir` with its address space limited to `limit`.
fn limited(dir: &Path, limit: &str, args: &[&str]) -> Output {
    let bin = binary();
    let mut a = vec![limit, "--", bin.as_str()];
    a.extend_from_slice(args);
    run_in(dir, "prlimit", &a)
}

/// The mistake: an infallible allocation failing inside documented bounds
/// aborts (SIGABRT, "memory allocation of N bytes failed") instead of
/// ending with "out of memory" and exit 1: a sphere at subdivision 9 (5.2 M
/// triangles) under 400 MB of address space with either backend, and a
/// part read under a limit its pixels do not fit.
#[test]
fn allocation_failures_end_with_a_message_and_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let big = SCENE.replace("subdivisions = 1", "subdivisions = 9");
    fs::write(d.join("big.toml"), big).unwrap();
    for accel in ["bvh", "embree"] {
        let args = [
            "render", "big.toml", "-o", "big.exr", "--quiet", "--accel", accel,
        ];
        let o = limited(d, "--as=400000000", &args);
        assert_exit(&o, 1, &["out of memory"]);
    }
    // a 1024×1024 part (48 MB of words in the EXR) merged under 200 MB
    let wide = SCENE
        .replace("[16, 8]", "[1024, 1024]")
        .replace("spp = 2", "spp = 1");
    fs::write(d.join("wide.toml"), wide).unwrap();
    let o = lucent(
        d,
        &[
            "render",
            "wide.toml",
            "--samples",
            "0..1",
            "-o",
            "w.exr",
            "--quiet",
        ],
    );
    assert_exit(&o, 0, &[]);
    let o = limited(
        d,
        "--as=200000000",
        &["merge", "w.exr", "-o", "m.exr", "--quiet"],
    );
    assert_exit(&o, 1, &["out of memory: cannot allocate"]);
    let left: Vec<_> = fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| {
            n.ends_with(".tmp") || n.ends_with(".png") || n.starts_with("m.") || n == "big.exr"
        })
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// The mistakes at the edges of ranges: a max_depth no render finishes; a
/// light group name whose channels OpenEXR refuses; an output name whose
/// temporary name is too long; a non-finite or absurd exposure writing a
/// black preview with exit 0; `-o out.exr/` failing late with exit 1; a
/// UTF-8 byte-order mark hiding an OBJ's first vertex; a 10 MB value
/// quoted whole in a message.
#[test]
fn inputs_at_the_edges_of_their_ranges_are_refused_up_front_or_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |name: &str, text: &str| fs::write(d.join(name), text).unwrap();
    write(
        "deep.toml",
        &SCENE.replace("spp = 2", "spp = 2\nmax_depth = 4294967295"),
    );
    let o = lucent(d, &["render", "deep.toml", "-o", "deep.exr", "--quiet"]);
    assert_exit(&o, 2, &["render.max_depth", "1024"]);
    let group = "g".repeat(249);
    write(
        "group.toml",
        &format!("{SCENE}emission = [1, 1, 1]\nlight_group = \"{group}\"\n"),
    );
    let o = lucent(d, &["render", "group.toml", "-o", "group.exr", "--quiet"]);
    assert_exit(&o, 2, &["light_group", "255 bytes"]);
    write("scene.toml", SCENE);
    let long = format!("{}.exr", "n".repeat(250));
    let o = lucent(d, &["render", "scene.toml", "-o", &long, "--quiet"]);
    assert_exit(&o, 0, &[]);
    assert!(d.join(&long).is_file());
    for e in ["nan", "inf", "1e6"] {
        let o = lucent(
            d,
            &[
                "render",
                "scene.toml",
                "-o",
                "e.exr",
                "--quiet",
                "--exposure",
                e,
            ],
        );
        assert_exit(&o, 2, &["--exposure", "finite"]);
    }
    let o = lucent(d, &["render", "scene.toml", "-o", "slash.exr/", "--quiet"]);
    assert_exit(&o, 2, &["slash.exr/"]);
    // an append-only directory (root only: chattr), refused before any
    // temporary file is made there
    fs::create_dir(d.join("append")).unwrap();
    let chattr = |flag: &str| {
        Command::new("chattr")
            .arg(flag)
            .arg(d.join("append"))
            .status()
    };
    if chattr("+a").is_ok_and(|s| s.success()) {
        let o = lucent(
            d,
            &["render", "scene.toml", "-o", "append/a.exr", "--quiet"],
        );
        let left = fs::read_dir(d.join("append")).unwrap().count();
        chattr("-a").unwrap();
        assert_exit(&o, 2, &["append", "append-only"]);
        assert_eq!(left, 0);
    }
    // an OBJ of one triangle, with and without a byte-order mark
    let tri = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
    let obj_scene = |mesh: &str| {
        SCENE.split("[[shapes]]").next().unwrap().to_string()
            + &format!("[[shapes]]\ntype = \"obj\"\nfile = \"{mesh}\"\nmaterial = \"white\"\n")
    };
    write("plain.obj", tri);
    write("bom.obj", &format!("\u{feff}{tri}"));
    write("plain.toml", &obj_scene("plain.obj"));
    write("bom.toml", &obj_scene("bom.obj"));
    for s in ["plain", "bom"] {
        let o = lucent(
            d,
            &[
                "render",
                &format!("{s}.toml"),
                "-o",
                &format!("{s}.exr"),
                "--quiet",
            ],
        );
        assert_exit(&o, 0, &[]);
    }
    let pixels = |n: &str| lucent::film::Film::read_exr(&d.join(n)).unwrap();
    assert_eq!(pixels("plain.exr"), pixels("bom.exr"));
    let huge = SCENE.replace("spp = 2", &format!("spp = \"{}\"", "x".repeat(10 << 20)));
    write("huge.toml", &huge);
    let o = lucent(d, &["render", "huge.toml", "-o", "huge.exr", "--quiet"]);
    assert_exit(&o, 2, &["render.spp", "more characters not shown"]);
    assert!(o.stderr.len() < 2000, "{} bytes of message", o.stderr.len());
}

fn mkfifo(path: &Path) {
    let s = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(s.success());
}
