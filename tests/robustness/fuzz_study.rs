//! A seeded fuzzer over the study's directory (`docs/testing.md`, "Input
//! fuzzing"): a finished `lucent study --quick` directory, one of its
//! files damaged (bits flipped, cut short, a CSV field or key line set to
//! a hostile value) or replaced (a FIFO, a link to `/dev/zero`, a
//! directory, a link to a file outside the study), then the study run
//! again on it, as a resumed study is.
//!
//! The property: exit 0, or exit 1/2 with an error message; never a
//! signal, a panic (101) or a hang, and never a write through a link to
//! a file outside the study. Case `i` of seed `s` is a pure function of
//! `(s, i)`.

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

use crate::fuzz_files::{run_limited, Rng as FuzzRng};

/// A small subsurface scene: the study needs one subsurface material.
const SCENE: &str = "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\nresolution = [16, 8]\n\
                     [render]\nspp = 2\n\
                     [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
                     [materials.marble]\ntype = \"subsurface\"\npreset = \"marble\"\n\
                     [environment]\nradiance = [1, 1, 1]\n\
                     [[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n\
                     [[shapes]]\ntype = \"sphere\"\nmaterial = \"marble\"\nsubdivisions = 1\nscale = 0.4\n";

/// Values no study writes, for a CSV field or a key line.
const HOSTILE: &[&str] = &[
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-1",
    "0",
    "18446744073709551616",
    "",
    ",,,,",
    "\"",
    "9999999999",
    "1e-320",
    "x",
];

/// The finished study every case starts from (run once): its files, by
/// path relative to the study directory.
fn base_study() -> &'static Vec<(PathBuf, Vec<u8>)> {
    static BASE: OnceLock<Vec<(PathBuf, Vec<u8>)>> = OnceLock::new();
    BASE.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        fs::write(d.join("scene.toml"), SCENE).unwrap();
        let o = study(d).expect("the base study finishes");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mut files = Vec::new();
        collect(&d.join("study"), Path::new(""), &mut files);
        files.sort();
        assert!(files.iter().any(|(p, _)| p == Path::new("results.csv")));
        files
    })
}

fn collect(root: &Path, rel: &Path, out: &mut Vec<(PathBuf, Vec<u8>)>) {
    for e in fs::read_dir(root.join(rel)).unwrap().flatten() {
        let r = rel.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            collect(root, &r, out);
        } else {
            out.push((r.clone(), fs::read(root.join(&r)).unwrap()));
        }
    }
}

/// `lucent study scene.toml -o study --quick` in `d`, killed after 60 s.
fn study(d: &Path) -> Option<std::process::Output> {
    let args = ["study", "scene.toml", "-o", "study", "--quick"].map(String::from);
    run_limited(
        d,
        &crate::fuzz_files::binary(),
        &args,
        Duration::from_secs(60),
    )
}

/// Damages `path` (holding `bytes`) in `d`'s study; says what was done.
fn damage(rng: &mut FuzzRng, d: &Path, path: &Path, bytes: &[u8]) -> String {
    let at = d.join("study").join(path);
    let text = path.extension().is_some_and(|e| e == "csv" || e == "key");
    match rng.below(if text { 5 } else { 4 }) {
        0 => {
            let mut b = bytes.to_vec();
            let n = 1 + rng.below(4);
            for _ in 0..n {
                let i = rng.below(b.len().max(1));
                if let Some(x) = b.get_mut(i) {
                    *x ^= 1 << rng.below(8);
                }
            }
            fs::write(&at, b).unwrap();
            format!("{n} bits of {} flipped", path.display())
        }
        1 => {
            let n = rng.below(bytes.len().max(1));
            fs::write(&at, &bytes[..n]).unwrap();
            format!("{} cut to {n} bytes", path.display())
        }
        2 => {
            fs::remove_file(&at).unwrap();
            let how = match rng.below(4) {
                0 => {
                    let ok = std::process::Command::new("mkfifo").arg(&at).status();
                    assert!(ok.unwrap().success());
                    "a FIFO"
                }
                1 => {
                    std::os::unix::fs::symlink("/dev/zero", &at).unwrap();
                    "a link to /dev/zero"
                }
                2 => {
                    fs::create_dir(&at).unwrap();
                    "a directory"
                }
                _ => {
                    std::os::unix::fs::symlink(d.join("victim"), &at).unwrap();
                    "a link to a file outside the study"
                }
            };
            format!("{} replaced by {how}", path.display())
        }
        3 => {
            // a large file of one repeated byte
            let n = 1 << (10 + rng.below(14));
            fs::write(&at, vec![b'9'; n]).unwrap();
            format!("{} replaced by {n} bytes of '9'", path.display())
        }
        _ => {
            let s = String::from_utf8_lossy(bytes).into_owned();
            let mut lines: Vec<String> = s.lines().map(String::from).collect();
            let bad = *rng.pick(HOSTILE);
            if lines.is_empty() {
                lines.push(bad.to_string());
            } else {
                let l = rng.below(lines.len());
                let mut fields: Vec<String> = lines[l].split(',').map(String::from).collect();
                let f = rng.below(fields.len());
                fields[f] = bad.to_string();
                lines[l] = fields.join(",");
            }
            fs::write(&at, lines.join("\n") + "\n").unwrap();
            format!("a field of {} set to {bad:?}", path.display())
        }
    }
}

/// Runs case `index` of `seed`: what was done, and the exit code or what
/// broke the property.
fn run_case(seed: u64, index: u64) -> (String, Result<i32, String>) {
    let mut rng = FuzzRng::new(seed, index);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("scene.toml"), SCENE).unwrap();
    fs::write(d.join("victim"), b"not lucent's").unwrap();
    let base = base_study();
    for (p, b) in base {
        let at = d.join("study").join(p);
        fs::create_dir_all(at.parent().unwrap()).unwrap();
        fs::write(at, b).unwrap();
    }
    let (path, bytes) = rng.pick(base);
    let what = damage(&mut rng, d, path, bytes);
    let r = match study(d) {
        None => Err("hang: killed after 60 s".to_string()),
        Some(o) => {
            let e = String::from_utf8_lossy(&o.stderr).into_owned();
            if fs::read(d.join("victim")).unwrap() != b"not lucent's" {
                Err("the file outside the study was written".into())
            } else {
                match o.status.code() {
                    Some(0) => Ok(0),
                    Some(c @ 1..=2) if e.contains("error:") => Ok(c),
                    c => Err(format!("exit {c:?} ({:?}): {}", o.status, e.trim())),
                }
            }
        }
    };
    (what, r)
}

/// Cases until `LUCENT_FUZZ_STUDY_CASES` (default 16: a few seconds) have
/// run; prints the outcomes and fails with every case that broke the
/// property.
#[test]
fn damaged_study_directories_end_cleanly() {
    let cases = crate::fuzz_files::env_u64("LUCENT_FUZZ_STUDY_CASES", 16);
    let seed = crate::fuzz_files::env_u64("LUCENT_FUZZ_SEED", 1);
    let mut counts = [0usize; 3];
    let mut failures = Vec::new();
    for index in 0..cases {
        let (what, r) = run_case(seed, index);
        match r {
            Ok(c) => counts[c as usize] += 1,
            Err(e) => failures.push(format!("case {index} of seed {seed} ({what}): {e}")),
        }
    }
    eprintln!(
        "fuzz study directories: {cases} cases: {} exit 0, {} exit 1, {} exit 2",
        counts[0], counts[1], counts[2]
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
