//! `lucent bench`: the ray-query backends side by side, on the same meshes
//! and the same rays in one run.
//!
//! For every mesh (a displaced sphere per requested size, the Stanford bunny
//! and a random triangle soup) and every available backend it measures
//!
//! - the build: wall time (inside a rayon pool of the largest thread count;
//!   Embree builds on its own threads, sized from that pool) and memory, as
//!   the growth of the resident set (`/proc/self/statm`) from just before
//!   to just after the build, with freed heap returned to the kernel first
//!   (neither backend reports its structure size, so this is an estimate
//!   that includes allocator slack and, for our BVH, the whole of any huge
//!   page it touches);
//! - the throughput of four queries ([`rays`]): camera rays (coherent),
//!   incoherent rays, shadow segments and BSSRDF probe segments, with each
//!   requested thread count (one rayon pool per count, the ray set split
//!   into chunks of [`measure::CHUNK`]), as the fastest of several passes.
//!
//! Both backends must find the same number of hits on the same rays; a
//! difference beyond rays that graze an edge is an error. Results go to
//! `DIR/bench.csv`, a table on stdout (also `DIR/report.txt`) and log-log
//! plots `DIR/bench-<query>.png` of time per ray against triangle count.
//!
//! With a scene ([`replay`], `lucent bench --scene`) it measures instead the
//! renderer's end-to-end ray rate against the backend's raw rate on the
//! very queries that render issued (recorded, then replayed).

pub mod measure;
pub mod plot;
pub mod rays;
pub mod replay;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::accel::{self, Backend};
use crate::geometry::Mesh;
use crate::scene::shapes;
pub use measure::QueryKind;

/// Probe segments have half-length up to Rmax = this fraction of the
/// mesh's bounding-box diagonal.
pub const RMAX_FRACTION: f32 = 0.02;

/// Sizes of the full run: displaced spheres of 1.3k to 5.2M triangles.
pub const FULL_SIZES: [usize; 6] = [1_000, 20_000, 80_000, 330_000, 1_300_000, 5_200_000];
/// Sizes of `--quick`.
pub const QUICK_SIZES: [usize; 3] = [1_000, 20_000, 80_000];

/// What `lucent bench` does.
#[derive(Clone, Debug)]
pub struct Settings {
    pub out: PathBuf,
    /// Requested triangle counts; each becomes the displaced sphere whose
    /// count (20·4^level) is nearest in ratio.
    pub sizes: Vec<usize>,
    /// Thread counts, one rayon pool each.
    pub threads: Vec<usize>,
    /// Queries per ray set.
    pub rays: usize,
    /// Timing: passes continue until this much time was spent...
    pub min_time: Duration,
    /// ...and at least this many ran.
    pub min_passes: u32,
    /// The OBJ of the bunny mesh (skipped, with a note, if missing).
    pub bunny: Option<PathBuf>,
    /// Triangles of the random soup (0: none).
    pub soup: usize,
    pub backends: Vec<Backend>,
    pub progress: bool,
}

impl Settings {
    /// Defaults of the full run, or of `--quick` (3 sizes up to 80k
    /// triangles, 16k rays, short timing): under a minute on two busy cores.
    pub fn new(out: impl Into<PathBuf>, quick: bool) -> Settings {
        let threads = default_threads();
        Settings {
            out: out.into(),
            sizes: if quick {
                QUICK_SIZES.to_vec()
            } else {
                FULL_SIZES.to_vec()
            },
            threads,
            rays: if quick { 16_384 } else { 500_000 },
            min_time: Duration::from_millis(if quick { 20 } else { 400 }),
            min_passes: if quick { 2 } else { 3 },
            bunny: default_bunny(),
            soup: if quick { 20_000 } else { 100_000 },
            backends: available_backends(),
            progress: true,
        }
    }
}

/// The bunny of the repository: `scenes/meshes/bunny.obj` under the
/// current directory, else under the source tree lucent was built from.
pub fn default_bunny() -> Option<PathBuf> {
    let rel = Path::new("scenes/meshes/bunny.obj");
    [
        rel.to_path_buf(),
        Path::new(env!("CARGO_MANIFEST_DIR")).join(rel),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// One thread and all cores (just `[1]` on a one-core machine).
pub fn default_threads() -> Vec<usize> {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut threads = vec![1, all];
    threads.dedup();
    threads
}

/// Our BVH, and Embree when lucent was built with it.
pub fn available_backends() -> Vec<Backend> {
    let mut v = vec![Backend::Bvh];
    if Backend::default_available() == Backend::Embree {
        v.push(Backend::Embree);
    }
    v
}

/// Parses a triangle count: `1000`, `16k`, `1.3M`.
pub fn parse_size(s: &str) -> Result<usize, String> {
    let t = s.trim();
    let (num, mul) = match t.chars().last() {
        Some('k' | 'K') => (&t[..t.len() - 1], 1e3),
        Some('m' | 'M') => (&t[..t.len() - 1], 1e6),
        _ => (t, 1.0),
    };
    let v: f64 = num
        .parse()
        .map_err(|_| format!("\"{s}\" is not a triangle count (examples: 1000, 16k, 1.3M)"))?;
    let n = (v * mul).round();
    if !(20.0..=25e6).contains(&n) {
        return Err(format!(
            "size \"{s}\" out of range: between 20 and 25M triangles"
        ));
    }
    Ok(n as usize)
}

/// Parses a thread count: 1 to 1024.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=1024).contains(&n) => Ok(n),
        _ => Err(format!("\"{s}\" is not a thread count (1 to 1024)")),
    }
}

/// Parses a ray count: a positive integer, `k`/`M` suffixes allowed.
pub fn parse_rays(s: &str) -> Result<usize, String> {
    let t = s.trim();
    let (num, mul) = match t.chars().last() {
        Some('k' | 'K') => (&t[..t.len() - 1], 1e3),
        Some('m' | 'M') => (&t[..t.len() - 1], 1e6),
        _ => (t, 1.0),
    };
    match num.parse::<f64>() {
        Ok(v) if (v * mul).round() >= 1.0 && v * mul <= 1e9 => Ok((v * mul).round() as usize),
        _ => Err(format!(
            "\"{s}\" is not a ray count (examples: 100000, 500k, 2M)"
        )),
    }
}

/// The subdivision level of the displaced sphere nearest (in ratio) to `n`
/// triangles: 20·4^level.
pub fn sphere_level(n: usize) -> u32 {
    ((n as f64 / 20.0).log(4.0).round().max(0.0) as u32).min(10)
}

/// A benchmarked mesh.
pub struct BenchMesh {
    /// "sphere", "bunny" or "soup".
    pub kind: &'static str,
    pub mesh: Arc<Vec<Mesh>>,
}

impl BenchMesh {
    pub fn triangles(&self) -> usize {
        self.mesh[0].triangle_count()
    }
}

/// One CSV row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub mesh: String,
    pub triangles: usize,
    pub backend: String,
    pub query: QueryKind,
    pub threads: usize,
    pub rays: usize,
    pub hits: u64,
    /// Fastest pass, seconds.
    pub seconds: f64,
    pub build_seconds: f64,
    /// RSS growth over the build, MiB (None where /proc is missing).
    pub build_mib: Option<f64>,
    /// Process CPU time / wall time over the timed passes
    /// ([`measure::Timing::cpu_per_wall`]).
    pub cpu_per_wall: Option<f64>,
}

impl Row {
    pub fn mrays(&self) -> f64 {
        self.rays as f64 / self.seconds / 1e6
    }
    pub fn ns_per_ray(&self) -> f64 {
        self.seconds / self.rays as f64 * 1e9
    }
}

pub const CSV_HEADER: &str = "mesh,triangles,backend,query,threads,rays,hits,seconds,mrays_per_s,ns_per_ray,build_s,build_mib,cpu_per_wall";

fn csv_line(r: &Row) -> String {
    format!(
        "{},{},{},{},{},{},{},{:.6},{:.4},{:.2},{:.4},{},{}",
        r.mesh,
        r.triangles,
        r.backend,
        r.query.name(),
        r.threads,
        r.rays,
        r.hits,
        r.seconds,
        r.mrays(),
        r.ns_per_ray(),
        r.build_seconds,
        r.build_mib.map_or(String::new(), |m| format!("{m:.1}")),
        r.cpu_per_wall.map_or(String::new(), |c| format!("{c:.2}"))
    )
}

/// The error of [`run`]: bad settings (exit 2) or a failure while running.
#[derive(Debug)]
pub enum BenchError {
    Input(String),
    Runtime(String),
}

/// What [`run`] produced.
pub struct Outcome {
    pub rows: Vec<Row>,
    pub csv: PathBuf,
    pub plots: Vec<PathBuf>,
    /// The text printed on stdout.
    pub report: String,
}

/// Hit counts of two backends on the same rays agree if they differ by at
/// most this many: a ray through a shared edge or vertex may count one
/// triangle, two or none depending on the intersection test.
pub fn hit_tolerance(rays: usize) -> u64 {
    2 + rays as u64 / 5_000
}

fn validate(s: &Settings) -> Result<(), BenchError> {
    let bad = |m: &str| Err(BenchError::Input(m.to_string()));
    if s.sizes.is_empty() {
        return bad("--sizes: give at least one size");
    }
    if s.threads.is_empty() || s.threads.contains(&0) {
        return bad("--threads: thread counts must be at least 1");
    }
    if s.rays == 0 {
        return bad("--rays must be at least 1");
    }
    if s.backends.is_empty() {
        return bad("no backend to measure");
    }
    Ok(())
}

fn make_meshes(s: &Settings, notes: &mut Vec<String>) -> Result<Vec<(String, u32)>, BenchError> {
    let mut levels: Vec<u32> = s.sizes.iter().map(|&n| sphere_level(n)).collect();
    levels.sort_unstable();
    levels.dedup();
    if levels.len() < s.sizes.len() {
        notes.push(format!(
            "sizes map to displaced spheres of 20·4^level triangles; {} requested sizes gave {} distinct meshes",
            s.sizes.len(),
            levels.len()
        ));
    }
    Ok(levels
        .into_iter()
        .map(|l| ("sphere".to_string(), l))
        .collect())
}

/// Builds the meshes one at a time (so the 5M-triangle sphere is not kept
/// while the others run).
fn generate(kind: &str, level: u32, s: &Settings) -> Result<BenchMesh, BenchError> {
    let (kind, mesh) = match kind {
        "sphere" => ("sphere", shapes::displaced_sphere(level, 0.1)),
        "soup" => {
            // Edge lengths up to 4/∛n: a soup about as dense as the sphere
            // of the same count is fine.
            let n = s.soup;
            ("soup", shapes::random_soup(n, 4.0 / (n as f32).cbrt(), 11))
        }
        "bunny" => {
            let path = s.bunny.as_ref().expect("bunny path");
            let text = std::fs::read_to_string(path)
                .map_err(|e| BenchError::Input(format!("{}: {e}", path.display())))?;
            let m = crate::scene::load::load_obj(&text, path)
                .map_err(|e| BenchError::Input(e.to_string()))?;
            ("bunny", m)
        }
        _ => unreachable!(),
    };
    Ok(BenchMesh {
        kind,
        mesh: Arc::new(vec![mesh]),
    })
}

/// Runs the benchmark, writes `bench.csv`, `report.txt` and the plots into
/// `s.out`, and returns the rows. Hit counts that differ between backends
/// beyond [`hit_tolerance`] make it fail after writing the results.
pub fn run(s: &Settings) -> Result<Outcome, BenchError> {
    validate(s)?;
    std::fs::create_dir_all(&s.out)
        .map_err(|e| BenchError::Input(format!("{}: {e}", s.out.display())))?;
    let mut notes = Vec::new();
    let mut plan = make_meshes(s, &mut notes)?;
    match &s.bunny {
        Some(_) => plan.push(("bunny".into(), 0)),
        None => notes.push("bunny skipped: scenes/meshes/bunny.obj not found".into()),
    }
    if s.soup > 0 {
        plan.push(("soup".into(), 0));
    }
    let mut threads = s.threads.clone();
    threads.sort_unstable();
    threads.dedup();
    let pools: Vec<(usize, rayon::ThreadPool)> = threads
        .iter()
        .map(|&t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map(|p| (t, p))
                .map_err(|e| BenchError::Runtime(format!("rayon pool of {t}: {e}")))
        })
        .collect::<Result<_, _>>()?;
    let build_pool = &pools.last().unwrap().1;

    let steps = plan.len() * s.backends.len() * (1 + threads.len() * QueryKind::ALL.len());
    let bar = if s.progress {
        let b = ProgressBar::with_draw_target(Some(steps as u64), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
                .unwrap()
                .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };

    let started = Instant::now();
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    let mut failures = Vec::new();
    for (kind, level) in &plan {
        bar.set_message(format!("generating {kind}"));
        let bm = generate(kind, *level, s)?;
        let tris = bm.triangles();
        let label = format!("{} {}", bm.kind, short_count(tris));
        bar.set_message(format!("{label}: rays"));
        let m = &bm.mesh[0];
        let (_, radius) = rays::bounding_sphere(m);
        let rmax = RMAX_FRACTION * 2.0 * radius;
        let sets: Vec<(QueryKind, Vec<rays::Query>)> = QueryKind::ALL
            .into_iter()
            .map(|q| {
                let v = match q {
                    QueryKind::Camera => rays::camera_rays(m, s.rays),
                    QueryKind::Incoherent => rays::incoherent(m, s.rays, 1),
                    QueryKind::Shadow => rays::shadow_segments(m, s.rays, 2),
                    QueryKind::Probe => rays::probe_segments(m, s.rays, 3, rmax),
                };
                (q, v)
            })
            .collect();
        let first_row = rows.len();
        for &backend in &s.backends {
            bar.set_message(format!("{label}: {} build", backend.name()));
            measure::trim_heap();
            let rss0 = measure::rss_bytes();
            let t0 = Instant::now();
            let accel = build_pool
                .install(|| accel::build(&bm.mesh, backend))
                .map_err(BenchError::Runtime)?;
            let build_seconds = t0.elapsed().as_secs_f64();
            let rss1 = measure::rss_bytes();
            let build_mib = rss0
                .zip(rss1)
                .map(|(a, b)| b.saturating_sub(a) as f64 / (1u64 << 20) as f64);
            bar.inc(1);
            for (t, pool) in &pools {
                for (q, set) in &sets {
                    bar.set_message(format!("{label}: {} {} {t}t", backend.name(), q.name()));
                    let tm = measure::time_queries(
                        accel.as_ref(),
                        *q,
                        set,
                        pool,
                        s.min_time,
                        s.min_passes,
                    );
                    rows.push(Row {
                        mesh: bm.kind.to_string(),
                        triangles: tris,
                        backend: backend.name().to_string(),
                        query: *q,
                        threads: *t,
                        rays: set.len(),
                        hits: tm.hits,
                        seconds: tm.best,
                        build_seconds,
                        build_mib,
                        cpu_per_wall: tm.cpu_per_wall,
                    });
                    bar.inc(1);
                }
            }
            drop(accel);
        }
        check_hits(&rows[first_row..], &label, &mut warnings, &mut failures);
    }
    bar.finish_and_clear();
    for w in &warnings {
        eprintln!("warning: {w}");
    }

    let csv = s.out.join("bench.csv");
    let mut text = String::from(CSV_HEADER);
    text.push('\n');
    for r in &rows {
        text.push_str(&csv_line(r));
        text.push('\n');
    }
    crate::film::atomic_write(&csv, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })
    .map_err(|e| BenchError::Runtime(format!("{}: {e}", csv.display())))?;

    let mut report = report(&rows, &threads, s, started.elapsed().as_secs_f64());
    for n in &notes {
        let _ = writeln!(report, "note: {n}");
    }
    for w in &warnings {
        let _ = writeln!(report, "warning: {w}");
    }
    std::fs::write(s.out.join("report.txt"), &report)
        .map_err(|e| BenchError::Runtime(format!("report.txt: {e}")))?;
    let plots = plot::write_plots(&s.out, &rows).map_err(BenchError::Runtime)?;
    if !failures.is_empty() {
        print!("{report}");
        return Err(BenchError::Runtime(format!(
            "the backends disagree on hit counts beyond edge cases: {}",
            failures.join("; ")
        )));
    }
    Ok(Outcome {
        rows,
        csv,
        plots,
        report,
    })
}

/// Compares hit counts between backends (and thread counts) for one mesh.
fn check_hits(rows: &[Row], label: &str, warnings: &mut Vec<String>, failures: &mut Vec<String>) {
    let mut by: BTreeMap<QueryKind, Vec<&Row>> = BTreeMap::new();
    for r in rows {
        by.entry(r.query).or_default().push(r);
    }
    for (q, rs) in by {
        let lo = rs.iter().min_by_key(|r| r.hits).unwrap();
        let hi = rs.iter().max_by_key(|r| r.hits).unwrap();
        if lo.hits == hi.hits {
            continue;
        }
        let msg = format!(
            "{label} {}: {} {}t found {} hits, {} {}t {} ({} rays)",
            q.name(),
            lo.backend,
            lo.threads,
            lo.hits,
            hi.backend,
            hi.threads,
            hi.hits,
            lo.rays
        );
        if hi.hits - lo.hits > hit_tolerance(lo.rays) {
            failures.push(msg.clone());
        }
        warnings.push(msg);
    }
}

/// 1280 → "1.3k", 5242880 → "5.2M".
pub fn short_count(n: usize) -> String {
    if n >= 1_000_000 {
        format!("{:.1}M", n as f64 / 1e6)
    } else if n >= 1000 {
        format!("{:.1}k", n as f64 / 1e3)
    } else {
        n.to_string()
    }
}

/// Least-squares fit y = a + b x; returns (a, b).
pub fn fit_line(pts: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return None;
    }
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| (my - sxy / sxx * mx, sxy / sxx))
}

fn find<'a>(
    rows: &'a [Row],
    mesh: &str,
    tris: usize,
    backend: &str,
    q: QueryKind,
    t: usize,
) -> Option<&'a Row> {
    rows.iter().find(|r| {
        r.mesh == mesh
            && r.triangles == tris
            && r.backend == backend
            && r.query == q
            && r.threads == t
    })
}

/// The text report: throughput table with Embree/BVH ratios, builds,
/// growth with triangle count, and thread scaling.
pub fn report(rows: &[Row], threads: &[usize], s: &Settings, seconds: f64) -> String {
    let mut o = String::new();
    let backends: Vec<String> = s.backends.iter().map(|b| b.name().to_string()).collect();
    let mut meshes: Vec<(String, usize)> = Vec::new();
    for r in rows {
        if !meshes.iter().any(|m| m.0 == r.mesh && m.1 == r.triangles) {
            meshes.push((r.mesh.clone(), r.triangles));
        }
    }
    let _ = writeln!(
        o,
        "lucent bench: {} rays per set, threads {:?}, {:.0} s",
        s.rays, threads, seconds
    );
    let _ = writeln!(o, "\nThroughput, Mrays/s (fastest pass)");
    let mut head = format!("{:<14} {:<11} {:>3}", "mesh", "query", "thr");
    for b in &backends {
        let _ = write!(head, " {:>9}", b);
    }
    if backends.len() == 2 {
        let _ = write!(head, " {:>8}", format!("{}/{}", backends[1], backends[0]));
    }
    let _ = write!(head, " {:>12}", "hits");
    let _ = writeln!(o, "{head}");
    for (mesh, tris) in &meshes {
        for q in QueryKind::ALL {
            for &t in threads {
                let rs: Vec<Option<&Row>> = backends
                    .iter()
                    .map(|b| find(rows, mesh, *tris, b, q, t))
                    .collect();
                let _ = write!(
                    o,
                    "{:<14} {:<11} {:>3}",
                    format!("{mesh} {}", short_count(*tris)),
                    q.name(),
                    t
                );
                for r in &rs {
                    let _ = write!(
                        o,
                        " {:>9}",
                        r.map_or("-".into(), |r| format!("{:.2}", r.mrays()))
                    );
                }
                if let [Some(a), Some(b)] = rs[..] {
                    let _ = write!(o, " {:>8.2}", b.mrays() / a.mrays());
                }
                let hits: Vec<u64> = rs.iter().flatten().map(|r| r.hits).collect();
                let same = hits.windows(2).all(|w| w[0] == w[1]);
                let _ = write!(
                    o,
                    " {:>12}",
                    match (hits.first(), same) {
                        (Some(h), true) => h.to_string(),
                        (Some(_), false) => hits
                            .iter()
                            .map(|h| h.to_string())
                            .collect::<Vec<_>>()
                            .join("/"),
                        _ => "-".into(),
                    }
                );
                let _ = writeln!(o);
            }
        }
    }

    let _ = writeln!(
        o,
        "\nBuilds (wall time in a {}-thread pool; memory = RSS growth over the build)",
        threads.last().unwrap()
    );
    let _ = writeln!(
        o,
        "{:<14} {:<7} {:>9} {:>9}",
        "mesh", "backend", "seconds", "MiB"
    );
    for (mesh, tris) in &meshes {
        for b in &backends {
            if let Some(r) = rows
                .iter()
                .find(|r| &r.mesh == mesh && r.triangles == *tris && &r.backend == b)
            {
                let _ = writeln!(
                    o,
                    "{:<14} {:<7} {:>9.3} {:>9}",
                    format!("{mesh} {}", short_count(*tris)),
                    b,
                    r.build_seconds,
                    r.build_mib.map_or("-".into(), |m| format!("{m:.1}"))
                );
            }
        }
    }

    let sphere_sizes: Vec<usize> = meshes
        .iter()
        .filter(|m| m.0 == "sphere")
        .map(|m| m.1)
        .collect();
    if sphere_sizes.len() >= 2 {
        let _ = writeln!(
            o,
            "\nGrowth with triangle count (displaced spheres {}–{}): fit of time per ray\n\
             t = a + b·log2(n): b in ns per doubling of n; and the log-log exponent k, t ∝ n^k",
            short_count(sphere_sizes[0]),
            short_count(*sphere_sizes.last().unwrap())
        );
        let _ = writeln!(
            o,
            "{:<7} {:<11} {:>3} {:>10} {:>10} {:>7}",
            "backend", "query", "thr", "ns@min", "ns/doubl", "k"
        );
        for b in &backends {
            for q in QueryKind::ALL {
                for &t in threads {
                    let pts: Vec<&Row> = sphere_sizes
                        .iter()
                        .filter_map(|&n| find(rows, "sphere", n, b, q, t))
                        .collect();
                    let lin: Vec<(f64, f64)> = pts
                        .iter()
                        .map(|r| ((r.triangles as f64).log2(), r.ns_per_ray()))
                        .collect();
                    let ll: Vec<(f64, f64)> = pts
                        .iter()
                        .map(|r| ((r.triangles as f64).ln(), r.ns_per_ray().ln()))
                        .collect();
                    if let (Some((_, slope)), Some((_, k)), Some(first)) =
                        (fit_line(&lin), fit_line(&ll), pts.first())
                    {
                        let _ = writeln!(
                            o,
                            "{:<7} {:<11} {:>3} {:>10.1} {:>10.2} {:>7.3}",
                            b,
                            q.name(),
                            t,
                            first.ns_per_ray(),
                            slope,
                            k
                        );
                    }
                }
            }
        }
    }

    if threads.len() >= 2 {
        let (t1, tn) = (threads[0], *threads.last().unwrap());
        let _ = writeln!(
            o,
            "\nThread scaling: efficiency = throughput({tn}t) / ({tn}/{t1} · throughput({t1}t)); \
             in brackets the CPU the process got at {tn}t (CPU time / wall time: {tn} = \
             {tn} whole cores, less on a machine busy with other work)"
        );
        let mut head = format!("{:<14} {:<7}", "mesh", "backend");
        for q in QueryKind::ALL {
            let _ = write!(head, " {:>16}", q.name());
        }
        let _ = writeln!(o, "{head}");
        for (mesh, tris) in &meshes {
            for b in &backends {
                let _ = write!(
                    o,
                    "{:<14} {:<7}",
                    format!("{mesh} {}", short_count(*tris)),
                    b
                );
                for q in QueryKind::ALL {
                    let cell = find(rows, mesh, *tris, b, q, t1)
                        .zip(find(rows, mesh, *tris, b, q, tn))
                        .map(|(a, c)| {
                            let e = c.mrays() / a.mrays() * t1 as f64 / tn as f64;
                            match c.cpu_per_wall {
                                Some(cpu) => format!("{:.0} % ({cpu:.1})", e * 100.0),
                                None => format!("{:.0} %", e * 100.0),
                            }
                        });
                    let _ = write!(o, " {:>16}", cell.unwrap_or_else(|| "-".into()));
                }
                let _ = writeln!(o);
            }
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_suffixes_and_reject_nonsense() {
        assert_eq!(parse_size("1000"), Ok(1000));
        assert_eq!(parse_size("16k"), Ok(16_000));
        assert_eq!(parse_size("1.3M"), Ok(1_300_000));
        assert!(parse_size("10").is_err());
        assert!(parse_size("abc").is_err());
        assert!(parse_size("30M").is_err());
        assert!(parse_size("-5k").is_err());
        assert_eq!(parse_threads("2"), Ok(2));
        assert!(parse_threads("0").is_err() && parse_threads("x").is_err());
        assert_eq!(parse_rays("500k"), Ok(500_000));
        assert!(parse_rays("0").is_err() && parse_rays("nan").is_err());
    }

    #[test]
    fn sphere_levels_are_nearest_in_ratio() {
        assert_eq!(sphere_level(1000), 3); // 1280
        assert_eq!(sphere_level(16_000), 5); // 20480
        assert_eq!(sphere_level(4_000_000), 9); // 5.2M
        assert_eq!(shapes::sphere(3).triangle_count(), 20 * 4usize.pow(3));
    }

    #[test]
    fn line_fit_recovers_slope() {
        let pts: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 3.0 + 2.0 * i as f64)).collect();
        let (a, b) = fit_line(&pts).unwrap();
        assert!((a - 3.0).abs() < 1e-9 && (b - 2.0).abs() < 1e-9);
        assert!(fit_line(&pts[..1]).is_none());
    }

    #[test]
    fn hit_check_flags_only_real_disagreements() {
        let row = |b: &str, hits| Row {
            mesh: "sphere".into(),
            triangles: 1280,
            backend: b.into(),
            query: QueryKind::Camera,
            threads: 1,
            rays: 10_000,
            hits,
            seconds: 0.01,
            build_seconds: 0.0,
            build_mib: None,
            cpu_per_wall: None,
        };
        let (mut w, mut f) = (Vec::new(), Vec::new());
        check_hits(
            &[row("bvh", 5000), row("embree", 5000)],
            "x",
            &mut w,
            &mut f,
        );
        assert!(w.is_empty() && f.is_empty());
        check_hits(
            &[row("bvh", 5000), row("embree", 5001)],
            "x",
            &mut w,
            &mut f,
        );
        assert_eq!((w.len(), f.len()), (1, 0));
        check_hits(
            &[row("bvh", 5000), row("embree", 5100)],
            "x",
            &mut w,
            &mut f,
        );
        assert_eq!((w.len(), f.len()), (2, 1));
    }
}
