//! One frame split into parts and merged (docs/farm.md): the
//! merged frame is bitwise the uncut render for random splits by pixels,
//! by sample indices and both, on every backend of the build; the CLI's
//! `render --tile/--crop/--samples` in separate processes and `merge` give
//! the same file; and every bad set of parts is refused with exit 2, a
//! message naming the file and the problem, and nothing written.

use crate::common;
use crate::common::exr_file::all_layers_bits;

use std::fs;
use std::ops::Range;
use std::path::Path;
use std::process::{Command, Output};

use lucent::accel;
use lucent::farm::part::{self, Header, Identity};
use lucent::film::layers::{Coverage, Layer};
use lucent::film::pass_layout::Layout;
use lucent::film::passes::PassSet;
use lucent::film::region::Region;
use lucent::integrator::aov;
use lucent::render::{self, Job, RenderOptions};
use lucent::scene::Scene;

const FIXTURE: &str = "tests/fixtures/marble-ball.toml";

/// A small deterministic generator (xorshift) for the splits.
struct Rand(u64);
impl Rand {
    fn below(&mut self, n: u32) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as u32
    }
    /// `k` distinct sorted cut points strictly inside `0..n`, plus the ends.
    fn cuts(&mut self, n: u32, k: u32) -> Vec<u32> {
        let mut v = vec![0, n];
        for _ in 0..k {
            v.push(1 + self.below(n - 1));
        }
        v.sort_unstable();
        v.dedup();
        v
    }
}

fn identity(scene: &Scene, spp: u32, layout: Option<&Layout>) -> Identity {
    Identity {
        passes: part::passes_text(layout),
        names: part::names_text(layout),
        output: part::output_text(&Default::default()),
        version: "test".into(),
        scene_hash: "0".into(),
        seed: scene.settings.seed,
        spp,
        options: String::new(),
        frame: (scene.camera.width, scene.camera.height),
    }
}

/// Renders `region` × `samples` through the library and writes its part.
fn render_part(
    scene: &Scene,
    accel: &dyn accel::Accel,
    spp: u32,
    region: Region,
    samples: Range<u32>,
    passes: PassSet,
    path: &Path,
) {
    let opts = RenderOptions {
        spp: Some(spp),
        threads: Some(2),
        ..RenderOptions::default()
    };
    let job = Job {
        region,
        samples: samples.clone(),
        // passes of one sample: the pass boundaries fall everywhere
        pass_seconds: 0.0,
        passes,
    };
    let layout = (!passes.is_empty()).then(|| aov::layout(scene, passes));
    let r = render::render_job(scene, accel, &opts, &job, None, &mut |_| Ok(())).unwrap();
    assert_eq!((r.sums.start, r.sums.done), (samples.start, samples.end));
    let header = Header {
        identity: identity(scene, spp, layout.as_ref()),
        scene: "marble-ball.toml".into(),
        region,
        samples: samples.clone(),
        requested: samples,
        layers: part::layers_of(layout.as_ref()),
        counters: r.sums.counters,
        frame: Default::default(),
    };
    lucent::film::commit_all(vec![part::stage(path, &header, &r.sums).unwrap()]).unwrap();
}

fn bits(f: &lucent::film::Film) -> Vec<u32> {
    f.pixels
        .iter()
        .flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

/// Every layer's name, channels and value bits.
fn layer_bits(layers: &[Layer]) -> Vec<(String, Vec<String>, Vec<u32>)> {
    layers
        .iter()
        .map(|l| {
            let v = l.values.iter().map(|x| x.to_bits()).collect();
            (l.name.clone(), l.channels.clone(), v)
        })
        .collect()
}

/// A coverage's kind, names, and per pixel (ID, fraction bits).
type CoverageBits = (String, Vec<String>, Vec<Vec<(u32, u32)>>);

/// Every coverage list, fractions as bits.
fn coverage_bits(cov: &[Coverage]) -> Vec<CoverageBits> {
    cov.iter()
        .map(|c| {
            let px = c
                .pixels
                .iter()
                .map(|p| p.iter().map(|&(i, f)| (i, f.to_bits())).collect())
                .collect();
            (c.kind.clone(), c.names.clone(), px)
        })
        .collect()
}

#[test]
fn merged_parts_are_bitwise_the_uncut_render_for_random_splits() {
    let scene = lucent::scene::load(Path::new(FIXTURE)).unwrap();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let spp = 6;
    let dir = tempfile::tempdir().unwrap();
    let mut rand = Rand(0x5eed_f00d);
    for backend in common::backends() {
        let accel = accel::build(&scene.meshes, backend).unwrap();
        let opts = RenderOptions {
            spp: Some(spp),
            ..RenderOptions::default()
        };
        let (plain, _) = render::render(&scene, accel.as_ref(), &opts).unwrap();
        for passes in [PassSet::EMPTY, PassSet::all()] {
            let uncut = render::render_passes(&scene, accel.as_ref(), &opts, passes).unwrap();
            // passes leave the beauty as it is without them
            assert!(bits(&uncut.film) == bits(&plain));
            // the merge would be vacuous over a black image, or passes
            // without contents
            assert!(uncut.film.pixels.iter().filter(|p| p.x > 0.0).count() > (w * h / 2) as usize);
            if !passes.is_empty() {
                let l = |n: &str| uncut.layers.iter().find(|l| l.name == n).unwrap();
                assert!(l("sss_direct").values.iter().any(|v| *v > 0.0));
                for name in ["diffuse_direct", "albedo", "N", "Z", "variance"] {
                    let distinct: std::collections::BTreeSet<u32> =
                        l(name).values.iter().map(|v| v.to_bits()).collect();
                    assert!(distinct.len() > 10, "{name}");
                }
                // pixels seen by two objects (edges): coverage fractions to rank
                assert!(uncut.coverage[0].pixels.iter().any(|p| p.len() >= 2));
            }
            for kind in ["tiles", "samples", "both"] {
                let (xs, ys, ss) = match kind {
                    "tiles" => (rand.cuts(w, 3), rand.cuts(h, 2), vec![0, spp]),
                    "samples" => (vec![0, w], vec![0, h], rand.cuts(spp, 3)),
                    _ => (rand.cuts(w, 2), rand.cuts(h, 1), rand.cuts(spp, 2)),
                };
                let mut parts = Vec::new();
                for y in ys.windows(2) {
                    for x in xs.windows(2) {
                        for s in ss.windows(2) {
                            let region = Region {
                                x0: x[0],
                                y0: y[0],
                                x1: x[1],
                                y1: y[1],
                            };
                            let p = dir.path().join(format!("{kind}-{}.exr", parts.len()));
                            render_part(
                                &scene,
                                accel.as_ref(),
                                spp,
                                region,
                                s[0]..s[1],
                                passes,
                                &p,
                            );
                            parts.push(p);
                        }
                    }
                }
                // in any order
                parts.reverse();
                let merged = lucent::farm::merge::merge(&parts, false).unwrap();
                let what = format!("{backend:?} {kind}: x {xs:?} y {ys:?} samples {ss:?}");
                assert!(bits(&merged.film) == bits(&uncut.film), "{what}");
                assert_eq!(merged.film.width, w);
                assert_eq!(merged.layers.len(), uncut.layers.len(), "{what}");
                assert!(
                    layer_bits(&merged.layers) == layer_bits(&uncut.layers),
                    "{what}"
                );
                assert!(
                    coverage_bits(&merged.coverage) == coverage_bits(&uncut.coverage),
                    "{what}"
                );
            }
        }
    }
}

fn lucent(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A directory holding the fixture scene (and a copy under another name).
fn scene_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let text = fs::read_to_string(FIXTURE).unwrap();
    fs::write(dir.path().join("scene.toml"), &text).unwrap();
    dir
}

#[test]
fn separate_processes_split_and_merge_to_the_uncut_file() {
    let dir = scene_dir();
    let d = dir.path();
    let base = [
        "render",
        "scene.toml",
        "--quiet",
        "--spp",
        "5",
        "--threads",
        "1",
    ];
    let run = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        let o = lucent(d, &a);
        assert!(
            o.status.success(),
            "{a:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    run(&["-o", "uncut.exr"]);
    // three bands, each rendered by its own process at the same time
    let children: Vec<_> = (0..3)
        .map(|i| {
            let tile = format!("{i}/3");
            let out = format!("band{i}.exr");
            let mut a = base.to_vec();
            a.extend_from_slice(&["--tile", &tile, "-o", &out]);
            Command::new(env!("CARGO_BIN_EXE_lucent"))
                .args(&a)
                .current_dir(d)
                .spawn()
                .unwrap()
        })
        .collect();
    for mut c in children {
        assert!(c.wait().unwrap().success());
    }
    // and a crop × samples split of the same frame
    run(&["--crop", "0,0,10,16", "--samples", "0..2", "-o", "c0.exr"]);
    run(&["--crop", "0,0,10,16", "--samples", "2..5", "-o", "c1.exr"]);
    run(&["--crop", "10,0,24,16", "-o", "c2.exr"]);
    for (parts, out) in [
        (vec!["band2.exr", "band0.exr", "band1.exr"], "bands.exr"),
        (vec!["c1.exr", "c2.exr", "c0.exr"], "crops.exr"),
    ] {
        let mut a = vec!["merge", "--quiet", "-o", out];
        a.extend_from_slice(&parts);
        let o = lucent(d, &a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        // the same pixels bit for bit (the uncut render's EXR also carries
        // its header attributes: render time, scene path), and the preview's
        // bytes
        let pixels = |p: &str| bits(&lucent::film::Film::read_exr(&d.join(p)).unwrap());
        assert!(pixels(out) == pixels("uncut.exr"));
        let png = |p: &str| fs::read(d.join(p).with_extension("png")).unwrap();
        assert!(png(out) == png("uncut.exr"));
    }
}

/// Runs a failing `lucent` command: exit 2, the message, and that nothing
/// appeared in the directory.
fn refused(d: &Path, args: &[&str]) -> String {
    let before = names(d);
    let o = lucent(d, args);
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert_eq!(names(d), before, "{args:?} wrote something");
    e
}

/// Passes ride in parts: `--aov all` rendered as bands and as
/// crops × sample ranges in separate processes merges to every channel of
/// every layer of the uncut render (light paths, groups, data, IDs,
/// Cryptomatte, variance), and the same PNG; with file options from the
/// parts (half precision, split files).
#[test]
fn passes_split_and_merge_to_the_uncut_file() {
    let dir = scene_dir();
    let d = dir.path();
    for (opts, files) in [
        (&[][..], &[""][..]),
        (
            &["--aov-precision", "half", "--aov-split"][..],
            &["", ".sss_direct", ".Z", ".CryptoObject", ".variance"][..],
        ),
    ] {
        let mut base = vec![
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "5",
            "--threads",
            "2",
            "--aov",
            "all",
        ];
        base.extend_from_slice(opts);
        let run = |extra: &[&str]| {
            let mut a = base.clone();
            a.extend_from_slice(extra);
            let o = lucent(d, &a);
            assert!(
                o.status.success(),
                "{a:?}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        };
        run(&["-o", "uncut.exr"]);
        run(&["--tile", "0/2", "-o", "band0.exr"]);
        run(&["--tile", "1/2", "-o", "band1.exr"]);
        run(&["--crop", "0,0,10,16", "--samples", "0..2", "-o", "c0.exr"]);
        run(&["--crop", "0,0,10,16", "--samples", "2..5", "-o", "c1.exr"]);
        run(&["--crop", "10,0,24,16", "--samples", "0..3", "-o", "c2.exr"]);
        run(&["--crop", "10,0,24,16", "--samples", "3..5", "-o", "c3.exr"]);
        for (parts, out) in [
            (vec!["band1.exr", "band0.exr"], "bands.exr"),
            (vec!["c3.exr", "c1.exr", "c2.exr", "c0.exr"], "crops.exr"),
        ] {
            let mut a = vec!["merge", "--quiet", "-o", out];
            a.extend_from_slice(&parts);
            let o = lucent(d, &a);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            for f in files {
                let path = |p: &str| d.join(p.replace(".exr", &format!("{f}.exr")));
                let (merged, uncut) = (
                    all_layers_bits(&path(out)),
                    all_layers_bits(&path("uncut.exr")),
                );
                // not vacuous: channels that vary over the image (the
                // beauty, the passes, Cryptomatte's ranks)
                let lively = uncut
                    .iter()
                    .filter(|c| c.1.iter().collect::<std::collections::BTreeSet<_>>().len() > 2)
                    .count();
                let one_file = f.is_empty() && opts.is_empty();
                assert!(
                    lively >= if one_file { 30 } else { 1 },
                    "{out}{f}: {lively}"
                );
                assert_eq!(
                    merged.iter().map(|c| &c.0).collect::<Vec<_>>(),
                    uncut.iter().map(|c| &c.0).collect::<Vec<_>>(),
                    "{out}{f}"
                );
                for (m, u) in merged.iter().zip(&uncut) {
                    assert!(m == u, "{out}{f}: channel {} differs", m.0);
                }
            }
            let png = |p: &str| fs::read(d.join(p).with_extension("png")).unwrap();
            assert!(png(out) == png("uncut.exr"));
        }
    }
}

/// Parts whose passes differ, or one without passes, or with other file
/// options, do not merge: exit 2, naming the file, the field and the
/// problem, nothing written.
#[test]
fn parts_with_other_passes_are_refused() {
    let dir = scene_dir();
    let d = dir.path();
    let part = |extra: &[&str], out: &str| {
        let mut a = vec![
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "2",
            "--threads",
            "1",
        ];
        a.extend_from_slice(extra);
        a.extend_from_slice(&["-o", out]);
        let o = lucent(d, &a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    part(&["--tile", "0/2", "--aov", "all"], "a.exr");
    part(&["--tile", "1/2", "--aov", "all"], "b.exr");
    part(&["--tile", "1/2", "--aov", "Z"], "z.exr");
    part(&["--tile", "1/2"], "none.exr");
    part(
        &["--tile", "1/2", "--aov", "all", "--exr-compression", "piz"],
        "piz.exr",
    );
    let o = lucent(d, &["merge", "-o", "good.exr", "a.exr", "b.exr", "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (other, field, problem) in [
        ("z.exr", "lucent.passes", "different passes"),
        ("none.exr", "lucent.passes", "different passes"),
        ("piz.exr", "lucent.output", "file options"),
    ] {
        let e = refused(d, &["merge", "-o", "out.exr", "a.exr", other]);
        assert!(
            e.contains(other) && e.contains(field) && e.contains(problem),
            "{other}: {e}"
        );
    }
    // a part whose layer list does not match its passes (edited)
    let bytes = fs::read(d.join("z.exr")).unwrap();
    let key = b"lucent.passes\0string\0";
    let at = key.len() + 4 + bytes.windows(key.len()).position(|w| w == key).unwrap();
    assert_eq!(bytes[at], b'Z');
    let mut forged = bytes.clone();
    forged[at] = b'N';
    fs::write(d.join("forged.exr"), &forged).unwrap();
    let e = refused(d, &["merge", "-o", "out.exr", "forged.exr"]);
    assert!(
        e.contains("forged.exr") && e.contains("lucent.layers"),
        "{e}"
    );
}

#[test]
fn bad_sets_of_parts_are_refused_naming_the_file_and_the_problem() {
    let dir = scene_dir();
    let d = dir.path();
    let part = |extra: &[&str], out: &str| {
        let mut a = vec![
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "3",
            "--threads",
            "1",
        ];
        a.extend_from_slice(extra);
        a.extend_from_slice(&["-o", out]);
        let o = lucent(d, &a);
        assert!(
            o.status.success(),
            "{a:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    part(&["--tile", "0/2"], "a.exr");
    part(&["--tile", "1/2"], "b.exr");
    let merge = |parts: &[&str]| {
        let mut a = vec!["merge", "-o", "out.exr"];
        a.extend_from_slice(parts);
        refused(d, &a)
    };
    // the good pair merges (so each failure below is the one change)
    let o = lucent(d, &["merge", "-o", "good.exr", "a.exr", "b.exr", "--quiet"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    fs::remove_file(d.join("good.exr")).unwrap();
    fs::remove_file(d.join("good.png")).unwrap();

    // another seed, other options, another scene
    part(&["--tile", "1/2", "--seed", "9"], "seed.exr");
    let e = merge(&["a.exr", "seed.exr"]);
    assert!(e.contains("seed.exr") && e.contains("lucent.seed"), "{e}");
    part(&["--tile", "1/2", "--accel", "bvh"], "bvh.exr");
    part(&["--tile", "0/2", "--radius", "uniform"], "opt.exr");
    let e = merge(&["opt.exr", "b.exr"]);
    assert!(e.contains("b.exr") && e.contains("lucent.options"), "{e}");
    // another accuracy budget: another choice of estimator
    part(&["--tile", "1/2", "--accuracy", "5%"], "budget.exr");
    let e = merge(&["a.exr", "budget.exr"]);
    assert!(
        e.contains("budget.exr") && e.contains("lucent.options"),
        "{e}"
    );
    // another sampler: other images, refused by the options
    part(&["--tile", "1/2", "--sampler", "random"], "random.exr");
    let e = merge(&["a.exr", "random.exr"]);
    assert!(
        e.contains("random.exr") && e.contains("lucent.options"),
        "{e}"
    );
    let text = fs::read_to_string(d.join("scene.toml")).unwrap();
    fs::write(d.join("other.toml"), text.replace("[8, 8, 8]", "[9, 9, 9]")).unwrap();
    let o = lucent(
        d,
        &[
            "render",
            "other.toml",
            "--quiet",
            "--spp",
            "3",
            "--tile",
            "1/2",
            "-o",
            "other.exr",
        ],
    );
    assert!(o.status.success());
    let e = merge(&["a.exr", "other.exr"]);
    assert!(
        e.contains("other.exr") && e.contains("lucent.scene_hash"),
        "{e}"
    );
    // another spp
    let o = lucent(
        d,
        &[
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "4",
            "--tile",
            "1/2",
            "-o",
            "spp.exr",
        ],
    );
    assert!(o.status.success());
    let e = merge(&["a.exr", "spp.exr"]);
    assert!(e.contains("spp.exr") && e.contains("lucent.spp"), "{e}");
    // another lucent version (a part edited to say so: same length)
    let bytes = fs::read(d.join("b.exr")).unwrap();
    // name, type, 4-byte size, then the text
    let key = b"lucent.version\0string\0";
    let at = key.len()
        + 4
        + bytes
            .windows(key.len())
            .position(|w| w == key)
            .expect("the version attribute");
    assert_eq!(bytes[at], env!("CARGO_PKG_VERSION").as_bytes()[0]);
    let mut forged = bytes.clone();
    forged[at] = if forged[at] == b'9' { b'8' } else { b'9' };
    fs::write(d.join("version.exr"), &forged).unwrap();
    let e = merge(&["a.exr", "version.exr"]);
    assert!(
        e.contains("version.exr") && e.contains("lucent.version"),
        "{e}"
    );

    // a gap, an overlap
    let e = merge(&["a.exr"]);
    assert!(e.contains("gap") && e.contains("y 8..16"), "{e}");
    part(&["--crop", "0,7,24,9"], "mid.exr");
    let e = merge(&["a.exr", "b.exr", "mid.exr"]);
    assert!(
        e.contains("mid.exr") && e.contains("overlaps a.exr") && e.contains("y 7..8"),
        "{e}"
    );
    // a part whose samples stop short (as an interrupted one does)
    part(&["--tile", "1/2", "--samples", "0..2"], "short.exr");
    let e = merge(&["a.exr", "short.exr"]);
    assert!(e.contains("gap") && e.contains("samples 2..3"), "{e}");

    // a truncated part, at several lengths
    for cut in [bytes.len() / 3, bytes.len() - 40, bytes.len() - 1] {
        fs::write(d.join("cut.exr"), &bytes[..cut]).unwrap();
        let e = merge(&["a.exr", "cut.exr"]);
        assert!(e.contains("cut.exr"), "{cut}: {e}");
    }
    // not lucent's: a frame EXR, a text file, a missing file
    part(&[], "frame.exr");
    let e = merge(&["a.exr", "frame.exr"]);
    assert!(
        e.contains("frame.exr") && e.contains("not a lucent part"),
        "{e}"
    );
    fs::write(d.join("notes.exr"), "not an image").unwrap();
    let e = merge(&["a.exr", "notes.exr"]);
    assert!(
        e.contains("notes.exr") && e.contains("not a lucent part"),
        "{e}"
    );
    let e = merge(&["a.exr", "missing.exr"]);
    assert!(e.contains("missing.exr"), "{e}");

    // bad split arguments
    for (args, what) in [
        (vec!["--tile", "2/2"], "--tile"),
        (vec!["--tile", "0/17"], "--tile"),
        (vec!["--crop", "0,0,25,16"], "--crop"),
        (vec!["--crop", "4,4,4,8"], "--crop"),
        (vec!["--samples", "2..4"], "--samples"),
        (vec!["--samples", "2..2"], "--samples"),
        (vec!["--checkpoint", "0"], "--checkpoint"),
    ] {
        let mut a = vec![
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "3",
            "-o",
            "x.exr",
        ];
        a.extend_from_slice(&args);
        let e = refused(d, &a);
        assert!(e.contains(what), "{args:?}: {e}");
    }
    // resuming from a part of another render
    let e = refused(
        d,
        &[
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "3",
            "--resume",
            "seed.exr",
            "-o",
            "x.exr",
        ],
    );
    assert!(e.contains("seed.exr") && e.contains("lucent.seed"), "{e}");
    let e = refused(
        d,
        &[
            "render",
            "scene.toml",
            "--quiet",
            "--spp",
            "3",
            "--resume",
            "a.exr",
            "-o",
            "x.exr",
        ],
    );
    assert!(e.contains("a.exr") && e.contains("lucent.region"), "{e}");
}
