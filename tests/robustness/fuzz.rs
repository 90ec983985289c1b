//! A seeded mutation fuzzer over the real binary: scene TOML, OBJ text and
//! command-line arguments, damaged and run as `lucent render` in a child
//! process, so that an abort inside a C library (Embree) is a failed case,
//! not a dead test runner (`docs/testing.md`, "Input fuzzing", for the
//! inputs, the mutations and the environment variables).
//!
//! The property every case must hold (the README's promises): exit 0, with
//! an EXR whose every pixel is finite and its PNG beside it, and nothing
//! else new in the directory; or exit 2, with a message on stderr that
//! names the damaged file, and the directory exactly as it was; never a
//! signal, another exit code, a panic message, a hang or a temporary or
//! partial output left behind. Case `i` of seed `s` is a pure function of
//! `(s, i)`. [`corpus_replays`] replays `tests/fuzz-corpus/`; known
//! failures under `open/` are replayed only by [`open_corpus_replays`].

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

// --- random numbers: SplitMix64, so a case depends only on (seed, index)

struct Rng(u64);

impl Rng {
    fn new(seed: u64, index: u64) -> Rng {
        let mut r = Rng(seed ^ index.wrapping_mul(0xA076_1D64_78BD_642F));
        r.next();
        r
    }
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in 0..n (n > 0).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a, T>(&mut self, v: &'a [T]) -> &'a T {
        &v[self.below(v.len())]
    }
    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
}

// --- inputs

/// Small OBJ fixtures: normals, texture coordinates, polygons, negative
/// indices, groups, vertex colours, `w` weights.
const OBJ_FIXTURES: &[&str] = &[
    "# tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    "o quad\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
     f 1/1/1 2/2/1 3/3/1 4/4/1\n",
    "mtllib none.mtl\ng a\nv 0 0 0 1 0 0\nv 1 0 0\nv 1 1 0 0 0 1\nv 0 1 0 2\nusemtl x\n\
     f -4 -3 -2\ng b\nf 1//1 3//1 4//1\nvn 0 0 1\ns 1\n",
];

/// The render arguments every scene and OBJ case gets (the scene at
/// `scene.toml` and the output at `out.exr` in the case's directory, which
/// is the child's working directory).
const BASE_ARGS: &[&str] = &[
    "render",
    "scene.toml",
    "-o",
    "out.exr",
    "--quiet",
    "--spp",
    "1",
    "--threads",
    "1",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The shipped scenes, made cheap: every OBJ reference points at
/// `mesh.obj`, the resolution is 8×6, spheres at most 2 subdivisions.
fn seed_scenes() -> Vec<String> {
    let mut paths: Vec<PathBuf> = fs::read_dir(root().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no scenes/*.toml");
    paths
        .iter()
        .map(|p| {
            let text = fs::read_to_string(p).unwrap();
            text.lines()
                .map(|l| {
                    let t = l.trim_start();
                    if t.starts_with("resolution") {
                        "resolution = [8, 6]".to_string()
                    } else if t.starts_with("file") {
                        "file = \"mesh.obj\"".to_string()
                    } else if t.starts_with("subdivisions") {
                        "subdivisions = 2".to_string()
                    } else {
                        l.to_string()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n")
                + "\n"
        })
        .collect()
}

/// A small scene that uses `mesh.obj`, for the OBJ cases.
const OBJ_SCENE: &str =
    "[camera]\nlook_from = [0, 0.5, 3]\nlook_at = [0, 0, 0]\nresolution = [8, 6]\n\
     [materials.m]\ntype = \"subsurface\"\npreset = \"marble\"\n\
     [environment]\nradiance = [1, 1, 1]\n\
     [[shapes]]\ntype = \"obj\"\nfile = \"mesh.obj\"\nmaterial = \"m\"\nsmooth = true\n";

// --- a case

/// What a case runs: the scene and mesh bytes written into a fresh
/// directory, and the arguments (relative to it).
#[derive(Clone, Debug)]
struct Case {
    scene: Vec<u8>,
    mesh: Vec<u8>,
    args: Vec<String>,
    /// What was done to the seed input, for the report.
    what: String,
}

fn generate(seed: u64, index: u64, scenes: &[String]) -> Case {
    let mut rng = Rng::new(seed, index);
    let mut case = Case {
        scene: rng.pick(scenes).clone().into_bytes(),
        mesh: rng.pick(OBJ_FIXTURES).as_bytes().to_vec(),
        args: BASE_ARGS.iter().map(|s| s.to_string()).collect(),
        what: String::new(),
    };
    if rng.chance(30) {
        // (a build without Embree refuses `--accel embree` as bad input)
        let embree = cfg!(feature = "embree") && rng.chance(50);
        let accel = if embree { "embree" } else { "bvh" };
        case.args.extend(["--accel".into(), accel.into()]);
    }
    if rng.chance(15) {
        case.args
            .extend(["--integrator".into(), "randomwalk".into()]);
    }
    let mut what = Vec::new();
    match rng.below(12) {
        10..=11 => {
            // numbers only, each still a valid TOML number: most of these
            // load, and reach the renderer and the backends
            for _ in 0..1 + rng.below(3) {
                what.push(format!(
                    "toml {}",
                    replace_number_validly(&mut rng, &mut case.scene)
                ));
            }
        }
        0..=4 => {
            for _ in 0..1 + rng.below(3) {
                what.push(mutate_toml(&mut rng, &mut case.scene));
            }
        }
        5..=7 => {
            case.scene = OBJ_SCENE.as_bytes().to_vec();
            for _ in 0..1 + rng.below(3) {
                what.push(mutate_obj(&mut rng, &mut case.mesh));
            }
        }
        _ => {
            for _ in 0..1 + rng.below(3) {
                what.push(mutate_args(&mut rng, &mut case.args));
            }
        }
    }
    case.what = what.join("; ");
    case
}

// --- mutations

/// Numbers as they may be written in TOML, valid or not: extremes of f32
/// and f64, subnormals, signed zeros, NaN and infinity spellings, integers
/// beyond every width.
const NUMBER_SPELLINGS: &[&str] = &[
    "1e38",
    "-1e38",
    "1e-38",
    "-1e-38",
    "3.4028235e38",
    "-3.4028235e38",
    "3.4028236e38",
    "1.7976931348623157e308",
    "-1.7976931348623157e308",
    "1e308",
    "1e400",
    "-1e400",
    "1e-45",
    "1.4e-45",
    "5e-324",
    "2.2250738585072014e-308",
    "1e-400",
    "0",
    "-0",
    "-0.0",
    "+0.0",
    "nan",
    "+nan",
    "-nan",
    "NaN",
    "inf",
    "+inf",
    "-inf",
    "Infinity",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "-2147483649",
    "9223372036854775807",
    "-9223372036854775808",
    "9223372036854775808",
    "18446744073709551615",
    "99999999999999999999999999999",
    "-1",
    "65536",
    "16385",
    "1e10",
    "1e20",
    "1e25",
    "1e30",
    "0x7fffffff",
    "0xffffffffffffffff",
    "0b1",
    "0o777",
    "1_000_000",
    "1.",
    ".5",
    "1e",
    "+-1",
    "1e+38",
    "0.1e39",
];

/// Span of every number-like token (a digit, or a sign or dot followed by a
/// digit, and what follows it of `[0-9a-zA-Z._+-]`) outside quoted strings
/// and comments, line by line.
fn number_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut in_str = false;
    let mut in_comment = false;
    let mut i = 0;
    while i < text.len() {
        let c = text[i];
        if c == b'\n' {
            in_str = false;
            in_comment = false;
        } else if in_comment {
        } else if c == b'"' {
            in_str = !in_str;
        } else if !in_str && c == b'#' {
            in_comment = true;
        } else if !in_str
            && (c.is_ascii_digit()
                || ((c == b'-' || c == b'+' || c == b'.')
                    && text.get(i + 1).is_some_and(u8::is_ascii_digit)))
            && (i == 0 || !(text[i - 1].is_ascii_alphanumeric() || text[i - 1] == b'_'))
        {
            let start = i;
            i += 1;
            while i < text.len() && (text[i].is_ascii_alphanumeric() || b"._+-".contains(&text[i]))
            {
                i += 1;
            }
            spans.push((start, i));
            continue;
        }
        i += 1;
    }
    spans
}

fn replace_number(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    let spans = number_spans(text);
    if spans.is_empty() {
        return damage_bytes(rng, text);
    }
    let (a, b) = *rng.pick(&spans);
    let new = *rng.pick(NUMBER_SPELLINGS);
    let old = String::from_utf8_lossy(&text[a..b]).into_owned();
    text.splice(a..b, new.bytes());
    format!("number {old} -> {new} at byte {a}")
}

/// Valid TOML numbers of every magnitude (the loader must take or refuse
/// each by its range, never pass one on that breaks the renderer).
const VALID_NUMBERS: &[&str] = &[
    "1e38",
    "-1e38",
    "1e-38",
    "-1e-38",
    "3.4028235e38",
    "1e25",
    "-1e25",
    "1e10",
    "1e7",
    "9999999.0",
    "1e-7",
    "1e-20",
    "1e-45",
    "5e-324",
    "-0.0",
    "0.0",
    "nan",
    "inf",
    "-inf",
    "1e300",
    "0.999999",
    "1.000001",
    "2",
    "-2",
    "0.5",
    "100",
    "1e5",
    "-1e5",
    "1e-3",
];

fn replace_number_validly(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    let spans = number_spans(text);
    if spans.is_empty() {
        return "no number".into();
    }
    let (a, b) = *rng.pick(&spans);
    let old = String::from_utf8_lossy(&text[a..b]).into_owned();
    // an integer stays an integer (u32 fields), a float a float
    let new = if old.contains(['.', 'e', 'E']) {
        rng.pick(VALID_NUMBERS).to_string()
    } else {
        // (not 8 or 9: valid sphere subdivisions that only cost seconds)
        rng.pick(&["0", "1", "2", "3", "7", "10", "16", "-1", "4294967295"])
            .to_string()
    };
    text.splice(a..b, new.bytes());
    format!("number {old} -> {new} at byte {a}")
}

/// Values of every TOML type, for wrong-type edits.
fn wrong_value(rng: &mut Rng) -> toml::Value {
    use toml::Value;
    match rng.below(9) {
        0 => Value::String(
            rng.pick(&["", "x", "diffuse", "\u{7f}\u{0c}", "\"\n'"])
                .to_string(),
        ),
        1 => Value::Integer(*rng.pick(&[0, -1, 1, i64::MAX, i64::MIN, 4294967296])),
        2 => Value::Float(*rng.pick(&[
            1e38,
            -1e38,
            1e-38,
            f32::MAX as f64,
            f64::MAX,
            -f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            1e-45,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ])),
        3 => Value::Boolean(rng.chance(50)),
        4 => Value::Array(vec![]),
        5 => Value::Array(vec![Value::String("a".into()); 1 + rng.below(4)]),
        6 => Value::Table(toml::Table::new()),
        7 => Value::Datetime("1979-05-27T07:32:00Z".parse().unwrap()),
        _ => Value::Array(vec![Value::Float(1.0); rng.below(6)]),
    }
}

/// Every path to a value in the document (keys and array indices).
#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

fn value_paths(v: &toml::Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match v {
        toml::Value::Table(t) => {
            for (k, x) in t {
                prefix.push(Step::Key(k.clone()));
                out.push(prefix.clone());
                value_paths(x, prefix, out);
                prefix.pop();
            }
        }
        toml::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(Step::Index(i));
                out.push(prefix.clone());
                value_paths(x, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn show_path(p: &[Step]) -> String {
    p.iter()
        .map(|s| match s {
            Step::Key(k) => format!(".{k}"),
            Step::Index(i) => format!("[{i}]"),
        })
        .collect()
}

/// The container holding the last step of `path`.
fn parent_mut<'a>(root: &'a mut toml::Value, path: &[Step]) -> &'a mut toml::Value {
    let mut v = root;
    for s in &path[..path.len() - 1] {
        v = match s {
            Step::Key(k) => v.get_mut(k.as_str()).unwrap(),
            Step::Index(i) => v.get_mut(*i).unwrap(),
        };
    }
    v
}

/// One structural edit of the parsed document; the text is re-serialized.
fn structural(rng: &mut Rng, text: &mut Vec<u8>) -> Option<String> {
    let s = std::str::from_utf8(text).ok()?;
    let mut doc = toml::Value::Table(toml::from_str::<toml::Table>(s).ok()?);
    let mut paths = Vec::new();
    value_paths(&doc, &mut Vec::new(), &mut paths);
    if paths.is_empty() {
        return None;
    }
    let path = rng.pick(&paths).clone();
    let last = path.last().unwrap().clone();
    let parent = parent_mut(&mut doc, &path);
    let what = match (rng.below(6), parent, &last) {
        (0, toml::Value::Table(t), Step::Key(k)) => {
            t.remove(k);
            "dropped"
        }
        (0, toml::Value::Array(a), Step::Index(i)) => {
            a.remove(*i);
            "dropped (array shorter)"
        }
        (1, toml::Value::Array(a), Step::Index(i)) => {
            let x = a[*i].clone();
            a.insert(*i, x);
            "duplicated (array longer)"
        }
        (1, toml::Value::Table(t), Step::Key(k)) => {
            // the same value under a misspelt or unknown key
            let x = t[k].clone();
            let name = match rng.below(3) {
                0 => format!("{k}_"),
                1 => k.to_uppercase(),
                _ => format!("{k}\n\"x"),
            };
            t.insert(name, x);
            "copied under another key"
        }
        (2, p, _) => {
            let x = wrong_value(rng);
            set(p, &last, x);
            "wrong type"
        }
        (3, p, _) => {
            let x = match get(p, &last) {
                toml::Value::Array(a) if !a.is_empty() && rng.chance(50) => {
                    let mut a = a.clone();
                    a.pop();
                    toml::Value::Array(a)
                }
                toml::Value::Array(a) => {
                    let mut a = a.clone();
                    let extra = a.last().cloned().unwrap_or(toml::Value::Integer(1));
                    a.push(extra);
                    toml::Value::Array(a)
                }
                _ => toml::Value::Array(vec![toml::Value::Float(0.5); rng.below(5)]),
            };
            set(p, &last, x);
            "array of another length"
        }
        (_, p, _) => {
            let x = match rng.below(2) {
                0 => toml::Value::Float(*rng.pick(&[
                    1e38,
                    -1e38,
                    1e-38,
                    -1e-38,
                    f32::MAX as f64,
                    f64::MAX,
                    1e-45,
                    5e-324,
                    -0.0,
                    f64::NAN,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    1e25,
                ])),
                _ => toml::Value::Integer(*rng.pick(&[
                    i64::MAX,
                    i64::MIN,
                    -1,
                    0,
                    4294967295,
                    4294967296,
                    1 << 31,
                    65536,
                ])),
            };
            set(p, &last, x);
            "numeric extreme"
        }
    };
    let toml::Value::Table(t) = doc else {
        unreachable!()
    };
    *text = toml::to_string(&t).ok()?.into_bytes();
    Some(format!("{what}: {}", show_path(&path)))
}

fn get<'a>(parent: &'a toml::Value, step: &Step) -> &'a toml::Value {
    match step {
        Step::Key(k) => &parent[k.as_str()],
        Step::Index(i) => &parent[*i],
    }
}

fn set(parent: &mut toml::Value, step: &Step, x: toml::Value) {
    match step {
        Step::Key(k) => parent[k.as_str()] = x,
        Step::Index(i) => parent[*i] = x,
    }
}

/// Line edits: drop, duplicate (duplicate keys and tables), swap, or cut a
/// line in the middle (an assignment without its value).
fn damage_lines(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    let mut lines: Vec<Vec<u8>> = text.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    let i = rng.below(lines.len());
    let what = match rng.below(4) {
        0 => {
            lines.remove(i);
            "dropped"
        }
        1 => {
            let l = lines[i].clone();
            let j = rng.below(lines.len() + 1);
            lines.insert(j, l);
            "duplicated"
        }
        2 => {
            let j = rng.below(lines.len());
            lines.swap(i, j);
            "swapped"
        }
        _ => {
            let n = lines[i].len();
            lines[i].truncate(rng.below(n + 1));
            "cut"
        }
    };
    *text = lines.join(&b'\n');
    format!("line {} {what}", i + 1)
}

/// Byte-level damage.
fn damage_bytes(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    let n = text.len();
    let at = rng.below(n + 1);
    match rng.below(8) {
        0 if n > 0 => {
            let i = rng.below(n);
            let bit = 1u8 << rng.below(8);
            text[i] ^= bit;
            format!("bit flip {bit:#04x} at byte {i}")
        }
        1 => {
            text.truncate(at);
            format!("truncated to {at} bytes")
        }
        2 => {
            let c = *rng.pick(&[0u8, 0x0c, 0x1b, 0x7f, b'\r', 0x08, 0x0b, 0x01]);
            text.insert(at, c);
            format!("control byte {c:#04x} at {at}")
        }
        3 => {
            const BAD: &[&[u8]] = &[
                &[0xff],
                &[0xc3],
                &[0xed, 0xa0, 0x80],
                &[0xf4, 0x90, 0x80, 0x80],
                &[0xef, 0xbb, 0xbf],
                &[0xc0, 0x80],
            ];
            let bad: &[u8] = BAD[rng.below(BAD.len())];
            text.splice(at..at, bad.iter().copied());
            format!("bytes {bad:02x?} at {at}")
        }
        4 if n > 0 => {
            let len = 1 + rng.below(n.min(64));
            let a = rng.below(n + 1 - len);
            text.drain(a..a + len);
            format!("deleted {len} bytes at {a}")
        }
        5 if n > 0 => {
            let len = 1 + rng.below(n.min(64));
            let a = rng.below(n + 1 - len);
            let span = text[a..a + len].to_vec();
            text.splice(at..at, span);
            format!("repeated {len} bytes from {a} at {at}")
        }
        6 => {
            let s = *rng.pick(&[
                "\"", "'", "[", "]", "[[", "=", "\n", "#", "{", "}", ",", "\\", "\"\"\"", "\r\n",
            ]);
            text.splice(at..at, s.bytes());
            format!("inserted {s:?} at {at}")
        }
        _ => {
            let c = *rng.pick(&[0u8, 0x0c]);
            // a control byte inside a comment
            text.splice(at..at, [b'#', b' ', c, b'\n']);
            format!("comment with byte {c:#04x} at {at}")
        }
    }
}

fn mutate_toml(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    match rng.below(10) {
        0..=2 => format!("toml {}", replace_number(rng, text)),
        3..=5 => match structural(rng, text) {
            Some(w) => format!("toml {w}"),
            None => format!("toml {}", damage_bytes(rng, text)),
        },
        6..=7 => format!("toml {}", damage_lines(rng, text)),
        _ => format!("toml {}", damage_bytes(rng, text)),
    }
}

fn mutate_obj(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    match rng.below(10) {
        0..=3 => format!("obj {}", replace_number(rng, text)),
        4..=5 => {
            let line = rng
                .pick(&[
                    "f 1 2 99999999999",
                    "f 0 1 2",
                    "f -9 -8 -7",
                    "f 1 2",
                    "f 1 1 1",
                    "f 1/1/1 2/2/2 3/3/3",
                    "v 1 2",
                    "v nan nan nan",
                    "v 1e38 1e38 1e38",
                    "v 1 1 1 0",
                    "vn 0 0 0",
                    "vn nan 0 1",
                    "vt",
                    "f",
                    "o",
                    "mtllib /dev/zero",
                ])
                .to_string();
            let at = rng.below(text.len() + 1);
            let at = text[..at]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1);
            text.splice(at..at, format!("{line}\n").bytes());
            format!("obj line {line:?} inserted")
        }
        6..=7 => format!("obj {}", damage_lines(rng, text)),
        _ => format!("obj {}", damage_bytes(rng, text)),
    }
}

/// Option values that are wrong for some option or all.
const HOSTILE_VALUES: &[&str] = &[
    "",
    "-1",
    "0",
    "1",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e38",
    "-1e38",
    "1e400",
    "5e-324",
    "-0",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "0x10",
    " 1",
    "1 ",
    "é",
    "--",
    "-",
    "true",
    "maybe",
    "table:0",
    "table:4294967296",
    "table:",
    "table-uniform:1",
    "mixture",
    "mis3",
    "mis",
    "tabulated",
    "burley",
    "sobol",
    "randomwalk",
    "bvh",
    "clamp",
    "0.5",
    "1.0",
];

const OPTIONS: &[&str] = &[
    "--spp",
    "--threads",
    "--seed",
    "--accel",
    "--tonemap",
    "--exposure",
    "--integrator",
    "--radius",
    "--rmax-quantile",
    "--axes",
    "--channel",
    "--renormalize",
    "--exit-sw",
    "--specular",
    "--profile",
    "--regularize",
    "--sampler",
    "--control-variate",
    "--probe-pair",
    "--pair-paths",
    "--boundary",
    "-o",
];

/// A value for `option`: hostile, but never a valid request that only
/// costs time (a large `--spp`).
fn option_value(rng: &mut Rng, option: &str) -> String {
    loop {
        let v = if rng.chance(10) {
            "9".repeat(1 + rng.below(5000))
        } else {
            rng.pick(HOSTILE_VALUES).to_string()
        };
        let costly = option == "--spp" && v.trim().parse::<u64>().is_ok_and(|n| n > 4);
        if !costly {
            return v;
        }
    }
}

fn mutate_args(rng: &mut Rng, args: &mut Vec<String>) -> String {
    let n = args.len();
    match rng.below(9) {
        0 => {
            // a hostile value for an option present
            let opts: Vec<usize> = (0..n - 1)
                .filter(|&i| args[i].starts_with('-') && args[i] != "--quiet")
                .collect();
            if opts.is_empty() {
                return mutate_args(rng, args);
            }
            let i = *rng.pick(&opts);
            let v = option_value(rng, &args[i].clone());
            args[i + 1] = v.clone();
            format!("args {} {v:?}", args[i])
        }
        1..=2 => {
            let o = *rng.pick(OPTIONS);
            let v = if o == "-o" {
                rng.pick(&[
                    "out.png",
                    "out",
                    "sub/out.exr",
                    ".",
                    "..",
                    "OUT.EXR",
                    ".exr",
                    "scene.toml",
                    "mesh.obj",
                    "out.exr/",
                    "/dev/null",
                    "a\nb.exr",
                ])
                .to_string()
            } else {
                option_value(rng, o)
            };
            args.extend([o.to_string(), v.clone()]);
            format!("args + {o} {v:?}")
        }
        3 => {
            let i = 1 + rng.below(n - 1);
            let a = args.remove(i);
            format!("args dropped {a:?}")
        }
        4 => {
            let i = 1 + rng.below(n - 1);
            let a = args[i].clone();
            args.insert(rng.below(n + 1).max(1), a.clone());
            format!("args repeated {a:?}")
        }
        5 => {
            let (i, j) = (1 + rng.below(n - 1), 1 + rng.below(n - 1));
            args.swap(i, j);
            format!("args swapped {i} {j}")
        }
        6 => {
            let s = rng
                .pick(&[
                    "missing.toml",
                    ".",
                    "/dev/null",
                    "/dev/zero",
                    "scene.toml/",
                    "",
                    "mesh.obj",
                    "-",
                ])
                .to_string();
            args[1] = s.clone();
            format!("args scene {s:?}")
        }
        7 => {
            let s = rng
                .pick(&["rendr", "", "info", "--help", "-h", "--version", "RENDER"])
                .to_string();
            args[0] = s.clone();
            format!("args command {s:?}")
        }
        _ => {
            let extra = rng
                .pick(&[
                    "--quiet",
                    "-q",
                    "--unknown",
                    "extra",
                    "-",
                    "--spp=1",
                    "--spp=",
                    "-o=",
                ])
                .to_string();
            args.insert(1 + rng.below(n), extra.clone());
            format!("args inserted {extra:?}")
        }
    }
}

// --- running and checking a case

/// The names in `dir`.
fn listing(dir: &Path) -> BTreeSet<String> {
    fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

struct Outcome {
    code: Option<i32>,
    signal: Option<i32>,
    stderr: String,
    timed_out: bool,
    before: BTreeSet<String>,
    after: BTreeSet<String>,
    /// Non-finite or unreadable EXR outputs, by name.
    bad_outputs: Vec<String>,
}

/// The binary under test: this build's, or `LUCENT_FUZZ_BIN` (another
/// build, or a copy that a rebuild during a long run does not replace).
fn binary() -> PathBuf {
    std::env::var_os("LUCENT_FUZZ_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_lucent")))
}

fn case_timeout() -> Duration {
    let s = std::env::var("LUCENT_FUZZ_CASE_TIMEOUT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(30);
    Duration::from_secs(s)
}

fn run(case: &Case) -> Outcome {
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("scene.toml"), &case.scene).unwrap();
    fs::write(dir.path().join("mesh.obj"), &case.mesh).unwrap();
    let before = listing(dir.path());
    let mut child = Command::new(binary())
        .args(&case.args)
        .current_dir(dir.path())
        .env_remove("RUST_BACKTRACE")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // read stderr on a thread so a chatty child never blocks on a full pipe
    let mut err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        let _ = std::io::Read::read_to_end(&mut err, &mut s);
        s
    });
    let start = Instant::now();
    let timeout = case_timeout();
    let mut timed_out = false;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > timeout {
            timed_out = true;
            let _ = child.kill();
            break child.wait().unwrap();
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr = String::from_utf8_lossy(&reader.join().unwrap()).into_owned();
    let after = listing(dir.path());
    let mut bad_outputs = Vec::new();
    if status.success() {
        for name in after.difference(&before) {
            if name.ends_with(".exr") || name.ends_with(".EXR") {
                match lucent::film::Film::read_exr(&dir.path().join(name)) {
                    Ok(f) if f.pixels.iter().all(|p| p.is_finite()) => {}
                    Ok(_) => bad_outputs.push(format!("{name}: non-finite pixels")),
                    Err(e) => bad_outputs.push(format!("{name}: {e}")),
                }
            }
        }
    }
    use std::os::unix::process::ExitStatusExt;
    Outcome {
        code: status.code(),
        signal: status.signal(),
        stderr,
        timed_out,
        before,
        after,
        bad_outputs,
    }
}

/// Whether the arguments are the render of `scene.toml` as [`generate`]
/// makes them before damaging any (then an exit 2 must name a file), or
/// were damaged (then any `error:` message will do).
fn args_intact(case: &Case) -> bool {
    let n = BASE_ARGS.len();
    if case.args.len() < n || case.args[..n] != *BASE_ARGS {
        return false;
    }
    let rest: Vec<&str> = case.args[n..].iter().map(String::as_str).collect();
    let mut seen = BTreeSet::new();
    rest.chunks(2).all(|p| {
        matches!(
            p,
            ["--accel", "bvh" | "embree"] | ["--integrator", "randomwalk"]
        ) && seen.insert(p[0])
    })
}

/// The property (module docs); `allowed` are the exit codes the case may end
/// with. `Err` says what broke it.
fn check(case: &Case, o: &Outcome, allowed: &[i32]) -> Result<&'static str, String> {
    if o.timed_out {
        return Err(format!("hang: killed after {:?}", case_timeout()));
    }
    if let Some(sig) = o.signal {
        return Err(format!("killed by signal {sig}"));
    }
    if o.stderr.contains("panicked at") {
        return Err("panic".into());
    }
    let code = o.code.unwrap_or(-1);
    if !allowed.contains(&code) {
        return Err(format!("exit {code} (expected {allowed:?})"));
    }
    let new: Vec<&String> = o.after.difference(&o.before).collect();
    let gone: Vec<&String> = o.before.difference(&o.after).collect();
    if !gone.is_empty() {
        return Err(format!("removed {gone:?}"));
    }
    if let Some(t) = new.iter().find(|n| n.ends_with(".tmp")) {
        return Err(format!("temporary file {t} left behind"));
    }
    match code {
        0 => {
            if !o.bad_outputs.is_empty() {
                return Err(format!("bad output: {:?}", o.bad_outputs));
            }
            let info_or_help = !case.args.iter().any(|a| a == "render")
                || case
                    .args
                    .iter()
                    .any(|a| ["--help", "-h", "--version", "-V"].contains(&a.as_str()));
            let exr = new
                .iter()
                .filter(|n| n.to_lowercase().ends_with(".exr"))
                .count();
            let png = new.iter().filter(|n| n.ends_with(".png")).count();
            if !(new.is_empty() && info_or_help) && (exr != 1 || png != 1 || new.len() != 2) {
                return Err(format!("exit 0 but new files {new:?}"));
            }
            Ok("ok")
        }
        _ => {
            if !new.is_empty() {
                return Err(format!("exit {code} but left {new:?}"));
            }
            let msg = o.stderr.trim();
            if msg.is_empty() {
                return Err(format!("exit {code} with an empty message"));
            }
            if args_intact(case) {
                if !(msg.contains("scene.toml") || msg.contains("mesh.obj")) {
                    return Err(format!("exit {code}: the message names no file"));
                }
                // the cause, not only the file: something after `file: `
                let last = msg.lines().last().unwrap_or("");
                if last.trim_end().ends_with(':') || last.trim_end().ends_with("`:") {
                    return Err(format!("exit {code}: the message ends before its cause"));
                }
            } else if !msg.contains("error") {
                return Err(format!("exit {code}: no error message"));
            }
            Ok("input error")
        }
    }
}

fn show(case: &Case) -> String {
    format!(
        "args: {:?}\nmutations: {}\n--- scene.toml\n{}\n--- mesh.obj\n{}",
        case.args,
        case.what,
        String::from_utf8_lossy(&case.scene),
        String::from_utf8_lossy(&case.mesh)
    )
}

// --- the corpus

fn save(dir: &Path, name: &str, case: &Case, found: &str, o: &Outcome) {
    let d = dir.join(name);
    fs::create_dir_all(&d).unwrap();
    fs::write(d.join("scene.toml"), &case.scene).unwrap();
    fs::write(d.join("mesh.obj"), &case.mesh).unwrap();
    fs::write(d.join("args"), case.args.join("\n") + "\n").unwrap();
    fs::write(
        d.join("expect"),
        format!(
            "0|2\n# found: {found}\n# mutations: {}\n# stderr: {}\n",
            case.what,
            o.stderr.trim().replace('\n', "\n#   ")
        ),
    )
    .unwrap();
}

fn load_case(d: &Path) -> (Case, Vec<i32>) {
    let read = |n: &str| fs::read(d.join(n)).unwrap_or_default();
    let args = String::from_utf8(read("args")).unwrap();
    let expect = String::from_utf8(read("expect")).unwrap();
    let allowed = expect
        .lines()
        .next()
        .unwrap_or("0|2")
        .split('|')
        .map(|c| c.trim().parse().expect("expect: exit codes such as 0|2"))
        .collect();
    let case = Case {
        scene: read("scene.toml"),
        mesh: read("mesh.obj"),
        args: args.lines().map(str::to_string).collect(),
        what: format!("corpus case {}", d.display()),
    };
    (case, allowed)
}

fn replay(dir: &Path) -> (usize, Vec<String>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return (0, Vec::new());
    };
    let mut cases: Vec<PathBuf> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("args").is_file())
        .collect();
    cases.sort();
    let mut failures = Vec::new();
    for d in &cases {
        let (case, allowed) = load_case(d);
        let o = run(&case);
        if let Err(e) = check(&case, &o, &allowed) {
            failures.push(format!(
                "{}: {e}\nstderr: {}\n{}",
                d.display(),
                o.stderr.trim(),
                show(&case)
            ));
        }
    }
    (cases.len(), failures)
}

/// Every case found so far ends as its `expect` file says.
#[test]
fn corpus_replays() {
    let (n, failures) = replay(&root().join("tests/fuzz-corpus"));
    eprintln!("fuzz corpus: {n} cases replayed");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Known failures not fixed yet (run with `--ignored`).
#[test]
#[ignore]
fn open_corpus_replays() {
    let (n, failures) = replay(&root().join("tests/fuzz-corpus/open"));
    eprintln!("open fuzz corpus: {n} cases replayed");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Mutated cases until the time budget is spent; fails with every case that
/// broke the property, each reproducible from its seed and index.
#[test]
fn mutated_inputs_end_in_an_image_or_a_clear_error() {
    let budget = Duration::from_secs(env_u64("LUCENT_FUZZ_SECONDS", 60));
    let seed = env_u64("LUCENT_FUZZ_SEED", 1);
    let jobs = env_u64("LUCENT_FUZZ_JOBS", 2).max(1);
    let corpus = std::env::var_os("LUCENT_FUZZ_CORPUS").map(PathBuf::from);
    let scenes = seed_scenes();
    let next = AtomicU64::new(0);
    let start = Instant::now();
    let stats = Mutex::new((0usize, 0usize, Vec::<String>::new()));
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| {
                while start.elapsed() < budget {
                    let index = next.fetch_add(1, Ordering::Relaxed);
                    let case = generate(seed, index, &scenes);
                    let o = run(&case);
                    let r = check(&case, &o, &[0, 2]);
                    let mut st = stats.lock().unwrap();
                    match r {
                        Ok("ok") => st.0 += 1,
                        Ok(_) => st.1 += 1,
                        Err(e) => {
                            if let Some(dir) = &corpus {
                                save(dir, &format!("s{seed}-c{index}"), &case, &e, &o);
                            }
                            st.2.push(format!(
                                "case {index} of seed {seed}: {e}\nstderr: {}\n{}",
                                o.stderr.trim(),
                                show(&case)
                            ));
                        }
                    }
                }
            });
        }
    });
    let (ok, input, failures) = stats.into_inner().unwrap();
    eprintln!(
        "fuzz: {} cases in {:.0?} (seed {seed}): {ok} rendered, {input} refused as input, {} failed",
        ok + input + failures.len(),
        start.elapsed(),
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} failing cases:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}
