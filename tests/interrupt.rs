//! SIGINT and SIGTERM (issue 14, class 8): a render stops at the next
//! pixel, nothing is committed, no temporary file remains, and the exit
//! code is 128 + the signal (130, 143); outputs staged when the signal
//! came are not committed. Its own test binary: the library test sets the
//! process-wide flag of `lucent::interrupt`.

use std::fs;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

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
fn a_signal_stops_a_render_with_its_exit_code_and_leaves_nothing() {
    for (signal, code, name) in [("-INT", 130, "SIGINT"), ("-TERM", 143, "SIGTERM")] {
        let dir = tempfile::tempdir().unwrap();
        let child = start_render(dir.path());
        // well into the render (loading takes milliseconds)
        std::thread::sleep(Duration::from_millis(700));
        kill(&child, signal);
        let (status, e) = finish(child, Duration::from_secs(10));
        assert_eq!(status, Some(code), "{signal}: {e}");
        assert!(
            e.contains(&format!(
                "interrupted by {name}: stopped, no output written"
            )),
            "{e}"
        );
        assert_eq!(names(dir.path()), ["scene.toml"], "{signal}");
    }
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
    assert_eq!(names(dir.path()), ["scene.toml"]);
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
