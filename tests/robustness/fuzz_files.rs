//! A seeded fuzzer over the files lucent reads and writes besides the
//! scene (`docs/testing.md`, "Input fuzzing"): part files (bit flips
//! anywhere, header fields set to hostile values, pixel words set to values
//! no render makes) given to `merge` and to `--resume`, and output-path
//! setups (planted symlinks and set-aside files at the temporary names,
//! symlinked and special outputs, names at the file system's limit).
//!
//! The property: exit 0 with the output written, or exit 1/2 with a
//! message naming the file at fault and no output; never a signal, a panic
//! (101), a hang, a file lucent did not create changed, or a temporary left
//! behind. Case `i` of seed `s` is a pure function of `(s, i)`; a failing
//! case is saved (its part file and arguments) under
//! `$LUCENT_FUZZ_CORPUS/files/`, which [`file_corpus_replays`] runs.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use crate::part_forgery::Parts;

/// SplitMix64: a case depends only on (seed, index).
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64, index: u64) -> Rng {
        Rng(seed ^ index.wrapping_mul(0xA076_1D64_78BD_642F))
    }
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    pub(crate) fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
}

const SCENE: &str = "[camera]\nlook_from = [0, 0, 3]\nlook_at = [0, 0, 0]\nresolution = [16, 8]\n\
                     [render]\nspp = 2\n\
                     [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
                     [materials.red]\ntype = \"diffuse\"\nalbedo = [0.8, 0.2, 0.2]\n\
                     [environment]\nradiance = [1, 1, 1]\n\
                     [[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n\
                     [[shapes]]\ntype = \"sphere\"\nmaterial = \"red\"\nsubdivisions = 1\nscale = 0.4\n";

const AOV: &str = "Z,object_id,crypto_object";

pub(crate) fn binary() -> PathBuf {
    std::env::var_os("LUCENT_FUZZ_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_lucent")))
}

/// Runs `program ARGS` in `dir`; `None` if it had to be killed after
/// `limit`. Its output is read while it runs (a long message must not fill
/// the pipe and stall it).
pub(crate) fn run_limited(
    dir: &Path,
    program: &Path,
    args: &[String],
    limit: Duration,
) -> Option<Output> {
    let mut child = Command::new(program)
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let drain = |r: Option<Box<dyn std::io::Read + Send>>| {
        std::thread::spawn(move || {
            let mut v = Vec::new();
            if let Some(mut r) = r {
                let _ = r.read_to_end(&mut v);
            }
            v
        })
    };
    let out = drain(child.stdout.take().map(|r| Box::new(r) as _));
    let err = drain(child.stderr.take().map(|r| Box::new(r) as _));
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Some(Output {
        status,
        stdout: out.join().unwrap(),
        stderr: err.join().unwrap(),
    })
}

/// [`run_limited`] with the cases' 10 s.
fn run_in(dir: &Path, program: &Path, args: &[String]) -> Option<Output> {
    run_limited(dir, program, args, Duration::from_secs(10))
}

/// The two intact band parts every part case starts from (rendered once).
fn base_parts() -> &'static (Vec<u8>, Vec<u8>) {
    static PARTS: OnceLock<(Vec<u8>, Vec<u8>)> = OnceLock::new();
    PARTS.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        fs::write(d.join("scene.toml"), SCENE).unwrap();
        for (i, p) in ["p0.exr", "p1.exr"].iter().enumerate() {
            let args: Vec<String> = [
                "render",
                "scene.toml",
                "--quiet",
                "--aov",
                AOV,
                "--tile",
                &format!("{i}/2"),
                "-o",
                p,
            ]
            .map(String::from)
            .to_vec();
            let o = run_in(d, &binary(), &args).expect("a part renders");
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        (
            fs::read(d.join("p0.exr")).unwrap(),
            fs::read(d.join("p1.exr")).unwrap(),
        )
    })
}

/// The kinds of cases, each a class of the closing figures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    /// 1 to 4 bits of `p0.exr` flipped.
    PartBits,
    /// A header attribute of `p0.exr` set to a hostile value.
    PartFields,
    /// A word of a pixel channel of `p0.exr` set to a hostile value.
    PartValues,
    /// An output path prepared against the writer.
    OutputPath,
}

const CLASSES: [Class; 4] = [
    Class::PartBits,
    Class::PartFields,
    Class::PartValues,
    Class::OutputPath,
];

/// A damaged part: its bytes and what was done.
fn damaged_part(rng: &mut Rng, class: Class) -> (Vec<u8>, String) {
    let base = &base_parts().0;
    let mut b = base.clone();
    match class {
        Class::PartBits => {
            let header = Parts::split(base).offsets[0] as usize;
            let mut what = Vec::new();
            for _ in 0..1 + rng.below(4) {
                // half the flips in the header, where the sizes are
                let at = if rng.below(2) == 0 {
                    rng.below(header)
                } else {
                    rng.below(b.len())
                };
                let bit = rng.below(8);
                b[at] ^= 1 << bit;
                what.push(format!("byte {at} bit {bit}"));
            }
            (b, format!("flipped {}", what.join(", ")))
        }
        Class::PartFields => {
            let mut p = Parts::split(base);
            let k = rng.below(p.attrs.len());
            let a = &mut p.attrs[k];
            let what = match a.kind.as_str() {
                "string" => {
                    let v = rng.pick(HOSTILE_TEXT).to_string();
                    let v = if v == "LONG" { "9".repeat(100_000) } else { v };
                    a.value = v.clone().into_bytes();
                    format!("{} = {:.60}", a.name, v)
                }
                _ => {
                    let n = a.value.len().max(1);
                    let mut v = a.value.clone();
                    v.resize(n, 0);
                    let at = rng.below(n / 4 * 4 + 1).min(n.saturating_sub(4));
                    let w = *rng.pick(HOSTILE_WORDS);
                    for (j, byte) in w.to_le_bytes().iter().enumerate() {
                        if let Some(x) = v.get_mut(at + j) {
                            *x = *byte;
                        }
                    }
                    a.value = v;
                    format!("{} word at {at} = {w:#x}", a.name)
                }
            };
            (p.join(), what)
        }
        Class::PartValues => {
            let names = Parts::split(base).channel_names();
            let name = rng.pick(&names).clone();
            let pixel = rng.below(64);
            let w = *rng.pick(HOSTILE_WORDS);
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("p.exr");
            fs::write(&path, &b).unwrap();
            crate::part_forgery::edit_channel(&path, &name, |v| {
                let n = v.len();
                v[pixel % n] = w;
            });
            let what = format!("channel {name} pixel {pixel} = {w:#x}");
            (fs::read(&path).unwrap(), what)
        }
        Class::OutputPath => unreachable!(),
    }
}

const HOSTILE_TEXT: &[&str] = &[
    "",
    "LONG",
    "[8192,8192]",
    "[4294967295,4294967295]",
    "[0,0]",
    r#"{"x0":0,"y0":0,"x1":4294967295,"y1":4294967295}"#,
    r#"{"x0":0,"y0":0,"x1":16,"y1":8}"#,
    r#"{"start":0,"end":4294967295}"#,
    r#"{"start":1,"end":0}"#,
    "4294967295",
    "-1",
    "1e308",
    "NaN",
    "null",
    "[]",
    "{}",
    "Z,object_id,crypto_object,crypto_material,P,N",
    r#"{"groups":[],"objects":[],"materials":[]}"#,
    "precision=float compression=pxr24 split=false ranks=64",
    "\u{7f}\u{1b}[2J",
];

const HOSTILE_WORDS: &[u32] = &[
    0,
    1,
    u32::MAX,
    0x8000_0000,
    0x7fff_ffff,
    0x7fc0_0000, // f32 NaN
    0x7f80_0000, // f32 +inf
    0xff80_0000, // f32 -inf
    8191,
    65535,
    4_000_000_000,
    1_000_000_000,
];

/// What a case found: `Ok(exit code)` if it kept the property.
fn check_part_case(d: &Path, o: Option<Output>, named: &str, out: &str) -> Result<i32, String> {
    let Some(o) = o else {
        return Err("hang: killed after 10 s".into());
    };
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    let left: Vec<String> = fs::read_dir(d)
        .unwrap()
        .map(|x| x.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    if !left.is_empty() {
        return Err(format!("temporaries left: {left:?}"));
    }
    match o.status.code() {
        Some(0) if d.join(out).is_file() => Ok(0),
        Some(2) if e.contains(named) && !d.join(out).exists() => Ok(2),
        Some(1) if e.contains("error:") && !d.join(out).exists() => Ok(1),
        c => Err(format!("exit {c:?} ({:?}): {}", o.status, e.trim())),
    }
}

/// Runs part case (`bytes` as p0.exr) through merge and --resume.
fn run_part_case(bytes: &[u8]) -> Result<i32, String> {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("scene.toml"), SCENE).unwrap();
    fs::write(d.join("p0.exr"), bytes).unwrap();
    fs::write(d.join("p1.exr"), &base_parts().1).unwrap();
    let args = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let merged = run_in(
        d,
        &binary(),
        &args(&["merge", "p0.exr", "p1.exr", "-o", "m.exr", "--quiet"]),
    );
    let a = check_part_case(d, merged, "p0.exr", "m.exr")?;
    let resumed = run_in(
        d,
        &binary(),
        &args(&[
            "render",
            "scene.toml",
            "--quiet",
            "--aov",
            AOV,
            "--tile",
            "0/2",
            "--resume",
            "p0.exr",
            "-o",
            "r.exr",
        ]),
    );
    let b = check_part_case(d, resumed, "p0.exr", "r.exr")?;
    for f in ["p0.exr", "p1.exr"] {
        if fs::read(d.join(f)).unwrap()
            != if f == "p0.exr" {
                bytes
            } else {
                &base_parts().1[..]
            }
        {
            return Err(format!("{f} was changed"));
        }
    }
    Ok(a.max(b))
}

/// An output-path setup and its check.
fn run_output_case(rng: &mut Rng) -> (String, Result<i32, String>) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("scene.toml"), SCENE).unwrap();
    fs::write(d.join("victim"), b"not lucent's").unwrap();
    let name_len = 240 + rng.below(16);
    let long = format!("{}.exr", "n".repeat(name_len - 4));
    let setups: [(&str, String); 8] = [
        ("symlink at the temporary name", "out.exr".into()),
        ("symlink at the set-aside name", "out.exr".into()),
        ("output is a symlink to a file", "link.exr".into()),
        ("output is a directory", "dir.exr".into()),
        ("output is a FIFO", "fifo.exr".into()),
        ("preview is a directory", "pv.exr".into()),
        ("long output name", long),
        ("output ends in /", "slash.exr/".into()),
    ];
    let (what, out) = rng.pick(&setups).clone();
    let key_path = |n: &str| lucent::film::temporary_path(&d.join(n), 0);
    let prefix = |p: PathBuf| {
        p.file_name()
            .unwrap()
            .to_str()
            .unwrap()
            .trim_end_matches("0.tmp")
            .to_string()
    };
    let mut pre = String::new();
    match what {
        "symlink at the temporary name" => {
            pre = format!("ln -s victim {}$$.tmp && ", prefix(key_path("out.exr")));
        }
        "symlink at the set-aside name" => {
            pre = format!("ln -s victim {}$$.old.tmp && ", prefix(key_path("out.exr")));
            fs::write(d.join("out.exr"), b"previous").unwrap();
        }
        "output is a symlink to a file" => {
            std::os::unix::fs::symlink("victim", d.join("link.exr")).unwrap();
        }
        "output is a directory" => fs::create_dir(d.join("dir.exr")).unwrap(),
        "output is a FIFO" => {
            Command::new("mkfifo")
                .arg(d.join("fifo.exr"))
                .status()
                .unwrap();
        }
        "preview is a directory" => fs::create_dir(d.join("pv.png")).unwrap(),
        _ => {}
    }
    let script = format!(
        "{pre}exec {} render scene.toml -o '{out}' --quiet",
        binary().display()
    );
    let o = run_in(d, Path::new("sh"), &["-c".to_string(), script]);
    let r = match o {
        None => Err("hang".to_string()),
        Some(o) => {
            let e = String::from_utf8_lossy(&o.stderr).into_owned();
            let victim = fs::read(d.join("victim")).unwrap();
            // temporaries lucent wrote (a planted symlink is the case's own)
            let tmps: Vec<String> = fs::read_dir(d)
                .unwrap()
                .map(|x| x.unwrap().file_name().into_string().unwrap())
                .filter(|n| n.ends_with(".tmp"))
                .filter(|n| fs::symlink_metadata(d.join(n)).is_ok_and(|m| m.is_file()))
                .collect();
            if victim != b"not lucent's" {
                Err("the symlink's target was written".into())
            } else if !tmps.is_empty() {
                Err(format!("temporaries left: {tmps:?}"))
            } else {
                match o.status.code() {
                    Some(c @ 0..=2) if c == 0 || e.contains("error:") => Ok(c),
                    c => Err(format!("exit {c:?} ({:?}): {}", o.status, e.trim())),
                }
            }
        }
    };
    (what.to_string(), r)
}

/// Saves a failing part case under `corpus/files/NAME/`.
fn save(corpus: &Path, name: &str, bytes: &[u8], what: &str, found: &str) {
    let d = corpus.join("files").join(name);
    fs::create_dir_all(&d).unwrap();
    fs::write(d.join("p0.exr"), bytes).unwrap();
    fs::write(d.join("case.txt"), format!("{what}\nfound: {found}\n")).unwrap();
}

pub(crate) fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Cases until `LUCENT_FUZZ_FILE_CASES` (default 24: a few seconds) have
/// run; prints the cases and outcomes per class and fails with every case
/// that broke the property.
#[test]
fn damaged_files_and_hostile_output_paths_end_cleanly() {
    let cases = env_u64("LUCENT_FUZZ_FILE_CASES", 24);
    let seed = env_u64("LUCENT_FUZZ_SEED", 1);
    let corpus = std::env::var_os("LUCENT_FUZZ_CORPUS").map(PathBuf::from);
    // per class: cases, exit 0, exit 1, exit 2
    let mut counts = [[0usize; 4]; 4];
    let mut failures = Vec::new();
    for index in 0..cases {
        let mut rng = Rng::new(seed, index);
        let k = index as usize % CLASSES.len();
        let class = CLASSES[k];
        let (what, r, bytes) = if class == Class::OutputPath {
            let (what, r) = run_output_case(&mut rng);
            (what, r, Vec::new())
        } else {
            let (bytes, what) = damaged_part(&mut rng, class);
            let r = run_part_case(&bytes);
            (what, r, bytes)
        };
        counts[k][0] += 1;
        match r {
            Ok(code) => counts[k][1 + code as usize] += 1,
            Err(e) => {
                if let (Some(c), false) = (&corpus, bytes.is_empty()) {
                    save(c, &format!("s{seed}-c{index}"), &bytes, &what, &e);
                }
                failures.push(format!(
                    "case {index} of seed {seed} ({class:?}: {what}): {e}"
                ));
            }
        }
    }
    for (k, c) in CLASSES.iter().zip(counts) {
        eprintln!(
            "fuzz files {k:?}: {} cases: {} exit 0, {} exit 1, {} exit 2",
            c[0], c[1], c[2], c[3]
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every saved part case of `tests/fuzz-corpus/files/` keeps the property.
#[test]
fn file_corpus_replays() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz-corpus/files");
    let Ok(entries) = fs::read_dir(&root) else {
        return;
    };
    let mut failures = Vec::new();
    for e in entries.flatten() {
        let bytes = fs::read(e.path().join("p0.exr")).unwrap();
        if let Err(f) = run_part_case(&bytes) {
            failures.push(format!("{}: {f}", e.path().display()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
