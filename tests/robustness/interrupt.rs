//! SIGINT, SIGTERM and SIGHUP: a render stops at the
//! next pixel, drops the pass under way, keeps the finished samples in
//! OUT.partial.exr and commits nothing else, no temporary file remains, and
//! the exit code is 128 + the signal (130, 143, 129); outputs staged when
//! the signal came are not committed. A render killed at a random moment,
//! or while it writes a checkpoint, and resumed from what it kept is
//! bitwise the uninterrupted render. Its own
//! test binary: the library test sets the process-wide flag of
//! `lucent::interrupt`.

use std::fs;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::exr_file::all_layers_bits;

/// A render that takes minutes: 256² pixels at 100 000 spp.
const SCENE: &str =
    "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\nresolution = [256, 256]\n\
                     [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
                     [environment]\nradiance = [1, 1, 1]\n\
                     [[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n";

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn start_render(dir: &Path) -> Child {
    fs::write(dir.join("scene.toml"), SCENE).unwrap();
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args([
            "render",
            "scene.toml",
            "-o",
            "out.exr",
            "--quiet",
            "--spp",
            "100000",
            "--threads",
            "2",
        ])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn kill(child: &Child, signal: &str) {
    let ok = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok, "kill {signal}");
}

/// Waits for the child, at most `limit`; its exit code and stderr.
fn finish(mut child: Child, limit: Duration) -> (Option<i32>, String) {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("still running {limit:?} after the signal");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let o = child.wait_with_output().unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn a_signal_stops_a_render_with_its_exit_code_keeping_only_the_finished_samples() {
    for (signal, code, name) in [
        ("-INT", 130, "SIGINT"),
        ("-TERM", 143, "SIGTERM"),
        ("-HUP", 129, "SIGHUP"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let child = start_render(dir.path());
        // well into the render (loading takes milliseconds)
        std::thread::sleep(Duration::from_millis(700));
        kill(&child, signal);
        let (status, e) = finish(child, Duration::from_secs(10));
        assert_eq!(status, Some(code), "{signal}: {e}");
        // the first pass (one sample a pixel) is done by now: kept
        assert!(
            e.contains(&format!("interrupted by {name}: stopped; samples 0..")),
            "{e}"
        );
        assert!(e.contains("of 0..100000 kept in out.partial.exr"), "{e}");
        assert_eq!(
            names(dir.path()),
            ["out.partial.exr", "scene.toml"],
            "{signal}"
        );
    }
}

/// The uninterrupted render, a render killed at a random moment (SIGTERM,
/// or SIGKILL after checkpoints) and resumed from what it left: the same
/// image, bitwise.
#[test]
fn a_render_killed_at_a_random_moment_and_resumed_is_bitwise_the_uninterrupted_one() {
    killed_and_resumed(&[]);
}

/// The same with every pass: the kept part carries the passes' sums, and
/// every channel of every layer (Cryptomatte, variance included) of the
/// resumed render is bitwise the uninterrupted one's.
#[test]
fn passes_killed_and_resumed_are_bitwise_the_uninterrupted_ones() {
    killed_and_resumed(&["--aov", "all"]);
}

fn killed_and_resumed(options: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(
        d.join("scene.toml"),
        SCENE.replace("[256, 256]", "[64, 48]"),
    )
    .unwrap();
    let render = |out: &str, extra: &[&str]| {
        let mut a = vec![
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "6000",
            "--threads",
            "2",
            "-o",
            out,
        ];
        a.extend_from_slice(options);
        a.extend_from_slice(extra);
        Command::new(env!("CARGO_BIN_EXE_lucent"))
            .args(a)
            .current_dir(d)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let start = Instant::now();
    let (status, e) = finish(render("whole.exr", &[]), Duration::from_secs(120));
    assert_eq!(status, Some(0), "{e}");
    // the render's own length on this machine, idle or loaded: the moments
    // below are fractions of it, so a signal never comes after the end
    let length = start.elapsed().as_millis() as u32;
    // every channel bit for bit (the EXR's header also records the render
    // time)
    let pixels = |p: &str| all_layers_bits(&d.join(p));
    let whole = pixels("whole.exr");
    // RGBA, or every pass too; not vacuous: channels besides the beauty's
    // that vary over the image
    assert_eq!(whole.len(), if options.is_empty() { 4 } else { 75 });
    let lively = whole
        .iter()
        .filter(|c| c.1.iter().collect::<std::collections::BTreeSet<_>>().len() > 2)
        .count();
    assert!(
        lively >= if options.is_empty() { 3 } else { 12 },
        "{lively}"
    );
    // a seeded "random" moment: reproducible, yet not a round number
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    for (k, signal) in [(0u32, "-TERM"), (1, "-KILL")] {
        // between 15 % and 60 % of the uninterrupted render's time
        let wait = length * (15 + (nanos / 7 + k * 337) % 46) / 100;
        let child = render("cut.exr", &["--checkpoint", "0.1"]);
        std::thread::sleep(Duration::from_millis(wait as u64));
        if signal == "-KILL" {
            // after a checkpoint (written beside the render, it commits
            // when its thread is done): SIGKILL keeps what was committed
            let start = Instant::now();
            while !d.join("cut.partial.exr").exists() && start.elapsed() < Duration::from_secs(60) {
                std::thread::sleep(Duration::from_millis(5));
            }
        }
        kill(&child, signal);
        let pid = child.id();
        let (status, e) = finish(child, Duration::from_secs(10));
        if signal == "-TERM" {
            assert_eq!(status, Some(143), "{e}");
        } else {
            // SIGKILL cannot be caught: a checkpoint being written at that
            // moment leaves its temporary (never the part itself, which is
            // renamed into place whole); the resumed render removes it
            // (film::stale), checked below. A stand-in for the moment the
            // kill does not always hit:
            let tmp = lucent::film::temporary_path(&d.join("cut.partial.exr"), pid);
            fs::write(tmp, b"cut").unwrap();
        }
        assert!(
            d.join("cut.partial.exr").is_file(),
            "{signal} after {wait} ms: nothing kept: {e}"
        );
        assert!(!d.join("cut.exr").exists());
        let (status, e) = finish(
            render("cut.exr", &["--resume", "cut.partial.exr"]),
            Duration::from_secs(120),
        );
        assert_eq!(status, Some(0), "{signal} after {wait} ms: {e}");
        assert!(
            pixels("cut.exr") == whole,
            "{signal} after {wait} ms: resumed image differs"
        );
        // done: what was kept to resume from is gone, and what the killed
        // process was writing
        assert!(!d.join("cut.partial.exr").exists());
        assert!(!lucent::film::temporary_path(&d.join("cut.partial.exr"), pid).exists());
        fs::remove_file(d.join("cut.exr")).unwrap();
        fs::remove_file(d.join("cut.png")).unwrap();
    }
    let left: Vec<String> = names(d)
        .into_iter()
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// SIGTERM while a checkpoint is being written (its temporary file seen
/// in the directory): the process still keeps every finished sample, at
/// least the checkpoint's, exits 143 within the bound, and the render
/// resumed from it is bitwise the uninterrupted one. Caught: a checkpoint
/// whose commit, refused after the signal, drops the sums with it
/// ("stopped, no output written").
#[test]
fn a_signal_during_a_checkpoint_write_keeps_the_samples_and_resumes_bitwise() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // big enough (every pass, 160×120) that a part takes a while to write
    fs::write(
        d.join("scene.toml"),
        SCENE.replace("[256, 256]", "[160, 120]"),
    )
    .unwrap();
    let render = |out: &str, extra: &[&str]| {
        let mut a = vec![
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "40",
            "--threads",
            "2",
            "--aov",
            "all",
            "-o",
            out,
        ];
        a.extend_from_slice(extra);
        Command::new(env!("CARGO_BIN_EXE_lucent"))
            .args(a)
            .current_dir(d)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (status, e) = finish(render("whole.exr", &[]), Duration::from_secs(300));
    assert_eq!(status, Some(0), "{e}");
    let whole = all_layers_bits(&d.join("whole.exr"));
    let mut caught = 0;
    for _ in 0..5 {
        let child = render("cut.exr", &["--checkpoint", "0.05"]);
        let tmp = lucent::film::temporary_path(&d.join("cut.partial.exr"), child.id());
        // the first checkpoint's write under way
        let start = Instant::now();
        while !tmp.exists() && start.elapsed() < Duration::from_secs(60) {
            std::thread::sleep(Duration::from_micros(200));
        }
        kill(&child, "-TERM");
        let signalled = Instant::now();
        let (status, e) = finish(child, Duration::from_secs(30));
        if status == Some(0) {
            // finished before the signal landed: no test, try again
            fs::remove_file(d.join("cut.exr")).unwrap();
            fs::remove_file(d.join("cut.png")).unwrap();
            continue;
        }
        caught += 1;
        assert_eq!(status, Some(143), "{e}");
        assert!(
            signalled.elapsed() < Duration::from_secs(10),
            "{:?} from SIGTERM to exit",
            signalled.elapsed()
        );
        assert!(e.contains("kept in cut.partial.exr"), "{e}");
        let (status, e) = finish(
            render("cut.exr", &["--resume", "cut.partial.exr"]),
            Duration::from_secs(300),
        );
        assert_eq!(status, Some(0), "{e}");
        assert!(
            all_layers_bits(&d.join("cut.exr")) == whole,
            "resumed image differs"
        );
        let left: Vec<String> = names(d)
            .into_iter()
            .filter(|n| n.ends_with(".tmp") || n.contains("partial"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        fs::remove_file(d.join("cut.exr")).unwrap();
        fs::remove_file(d.join("cut.png")).unwrap();
        break;
    }
    assert_eq!(caught, 1, "no signal landed during a checkpoint write");
}

#[test]
fn a_second_signal_ends_the_process_at_once_leaving_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let child = start_render(dir.path());
    std::thread::sleep(Duration::from_millis(700));
    kill(&child, "-INT");
    kill(&child, "-TERM");
    // the first stops the render, unless the second ends the process first
    let (status, e) = finish(child, Duration::from_secs(10));
    assert!(
        status == Some(130) || status == Some(143),
        "{status:?}: {e}"
    );
    // the kept part, if the first signal's write finished; never a
    // temporary file
    let left = names(dir.path());
    assert!(
        left == ["scene.toml"] || left == ["out.partial.exr", "scene.toml"],
        "{left:?}"
    );
}

#[test]
fn outputs_staged_when_a_signal_came_are_not_committed() {
    use lucent::film::{commit_all, Film, ToneMap};
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("a.exr");
    fs::write(&exr, b"earlier").unwrap();
    let f = Film::new(4, 4);
    let a = f.stage_exr(&exr).unwrap();
    let b = f
        .stage_png(&dir.path().join("a.png"), ToneMap::Clamp, 0.0)
        .unwrap();
    assert_eq!(names(dir.path()).len(), 3, "two temporaries and a.exr");
    lucent::interrupt::request(lucent::interrupt::SIGTERM);
    let e = commit_all(vec![a, b]).unwrap_err();
    assert!(matches!(e, lucent::Error::Interrupted(15)), "{e}");
    assert!(!e.is_input());
    assert_eq!(names(dir.path()), ["a.exr"]);
    assert_eq!(fs::read(&exr).unwrap(), b"earlier");
}
