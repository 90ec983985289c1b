//! `lucent bench` end to end: the quick run writes a CSV with one row per
//! (mesh, backend, query, threads), positive throughputs, the same hit
//! counts on every backend, and decodable plots; bad flags exit with 2.

use std::collections::{BTreeMap, BTreeSet};
use std::process::Command;

fn lucent() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
}

/// Backends of this build, from `lucent info`.
fn backends() -> BTreeSet<String> {
    let out = lucent().arg("info").output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("backends: "))
        .expect("backends line");
    line.split(", ")
        .map(|b| b.split_whitespace().next().unwrap().to_string())
        .collect()
}

#[derive(Debug)]
struct Row {
    mesh: String,
    triangles: usize,
    backend: String,
    query: String,
    threads: usize,
    rays: usize,
    hits: u64,
    mrays: f64,
    ns: f64,
    build_s: f64,
}

fn parse_csv(text: &str) -> Vec<Row> {
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (cm, ct, cb, cq, cth, cr, ch, cmr, cns, cbs) = (
        col("mesh"),
        col("triangles"),
        col("backend"),
        col("query"),
        col("threads"),
        col("rays"),
        col("hits"),
        col("mrays_per_s"),
        col("ns_per_ray"),
        col("build_s"),
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), head.len(), "{l}");
            Row {
                mesh: f[cm].into(),
                triangles: f[ct].parse().unwrap(),
                backend: f[cb].into(),
                query: f[cq].into(),
                threads: f[cth].parse().unwrap(),
                rays: f[cr].parse().unwrap(),
                hits: f[ch].parse().unwrap(),
                mrays: f[cmr].parse().unwrap(),
                ns: f[cns].parse().unwrap(),
                build_s: f[cbs].parse().unwrap(),
            }
        })
        .collect()
}

#[test]
fn quick_bench_writes_consistent_csv_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out = lucent()
        .args(["bench", "--quick", "--threads", "1,2", "-q", "-o"])
        .arg(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("Mrays/s"), "{stdout}");

    let rows = parse_csv(&std::fs::read_to_string(dir.path().join("bench.csv")).unwrap());
    let backends = backends();
    assert!(backends.contains("bvh"));
    let queries = ["camera", "incoherent", "shadow", "probe"];
    // Quick sizes 1k, 20k, 80k → displaced spheres of 20·4^level triangles.
    let spheres = [1280usize, 20480, 81920];
    let mut count: BTreeMap<(String, usize, String, String, usize), usize> = BTreeMap::new();
    for r in &rows {
        *count
            .entry((
                r.mesh.clone(),
                r.triangles,
                r.backend.clone(),
                r.query.clone(),
                r.threads,
            ))
            .or_default() += 1;
        assert!(r.mrays > 0.0 && r.mrays.is_finite(), "{r:?}");
        assert!(r.ns > 0.0 && r.build_s > 0.0, "{r:?}");
        assert!((r.mrays * r.ns - 1000.0).abs() < 5.0, "{r:?}");
        assert_eq!(r.rays, 16_384, "{r:?}");
    }
    assert!(count.values().all(|&c| c == 1), "duplicate rows");
    for b in &backends {
        for &n in &spheres {
            for q in queries {
                for t in [1, 2] {
                    let k = ("sphere".to_string(), n, b.clone(), q.to_string(), t);
                    assert!(count.contains_key(&k), "no row for {k:?}");
                }
            }
        }
        // The bunny and the soup too, once each.
        for mesh in ["bunny", "soup"] {
            assert_eq!(
                rows.iter()
                    .filter(|r| r.mesh == mesh && &r.backend == b)
                    .count(),
                8,
                "{mesh} {b}"
            );
        }
    }
    assert_eq!(
        rows.len(),
        backends.len() * (spheres.len() + 2) * queries.len() * 2
    );

    // Same rays, same hits: every backend and thread count agrees up to the
    // odd ray through a shared edge.
    let mut hits: BTreeMap<(String, usize, String), Vec<u64>> = BTreeMap::new();
    for r in &rows {
        hits.entry((r.mesh.clone(), r.triangles, r.query.clone()))
            .or_default()
            .push(r.hits);
    }
    for (k, v) in &hits {
        let (lo, hi) = (v.iter().min().unwrap(), v.iter().max().unwrap());
        assert!(hi - lo <= 5, "{k:?}: {v:?}");
    }
    // And the hits are plausible: most incoherent rays hit a sphere (they
    // aim into its bounding ball, of radius √3 for the unit sphere), every
    // probe segment crosses the surface about once, a fair share of shadow
    // segments between two points of the bumpy sphere is blocked.
    for &n in &spheres {
        let h = |q: &str| hits[&("sphere".to_string(), n, q.to_string())][0] as f64 / 16_384.0;
        assert!(
            h("incoherent") > 0.3 && h("incoherent") < 0.7,
            "{n}: {}",
            h("incoherent")
        );
        assert!(
            h("camera") > 0.15 && h("camera") < 0.5,
            "{n}: {}",
            h("camera")
        );
        assert!(h("probe") > 0.9 && h("probe") < 1.5, "{n}: {}", h("probe"));
        assert!(
            h("shadow") > 0.01 && h("shadow") < 0.5,
            "{n}: {}",
            h("shadow")
        );
    }

    for q in queries.iter().copied().chain(["build"]) {
        let p = dir.path().join(format!("bench-{q}.png"));
        let img = image::open(&p)
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
            .to_rgb8();
        assert!(img.width() >= 640 && img.height() >= 480);
        // Lines in colour were drawn (the palette's blue or orange).
        let coloured = img
            .pixels()
            .filter(|p| {
                let [r, g, b] = p.0;
                r.max(g).max(b) as i32 - r.min(g).min(b) as i32 > 80
            })
            .count();
        assert!(
            coloured > 500,
            "{}: {coloured} coloured pixels",
            p.display()
        );
    }
    assert!(dir.path().join("report.txt").is_file());
}

#[test]
fn bad_flags_exit_with_2_and_say_why() {
    let dir = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (vec!["--sizes", "1x"], "triangle count"),
        (vec!["--sizes", "5"], "out of range"),
        (vec!["--threads", "0"], "thread count"),
        (vec!["--rays", "0"], "ray count"),
        (vec!["--frobnicate"], "--frobnicate"),
    ] {
        let out = lucent()
            .arg("bench")
            .args(&args)
            .arg("-o")
            .arg(dir.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    assert!(!dir.path().join("bench.csv").exists());
}
