//! Running `lucent bench`: for every mesh of the plan and every backend,
//! the build (wall time in a rayon pool of the largest thread count, and
//! RSS growth) and the fastest pass of each query kind with each thread
//! count; then the CSV, the report and the plots.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::csv::{write_csv, Row};
use super::hits::check_hits;
use super::measure::{self, QueryKind};
use super::meshes::{generate, plan};
use super::report::{report, short_count};
use super::settings::{validate, Settings};
use super::{plot, rays};
use lucent::accel;
use lucent::Error;

/// Probe segments have half-length up to Rmax = this fraction of the
/// mesh's bounding-box diagonal.
pub const RMAX_FRACTION: f32 = 0.02;

/// What [`run`] produced.
pub struct Outcome {
    pub rows: Vec<Row>,
    pub csv: PathBuf,
    pub plots: Vec<PathBuf>,
    /// The text printed on stdout.
    pub report: String,
}

/// One rayon pool per thread count.
type Pools = Vec<(usize, rayon::ThreadPool)>;

/// Runs the benchmark, writes `bench.csv`, `report.txt` and the plots into
/// `s.out`, and returns the rows. Hit counts that differ between backends
/// beyond [`hit_tolerance`](super::hit_tolerance) make it fail after
/// writing the results.
pub fn run(s: &Settings) -> Result<Outcome, Error> {
    validate(s)?;
    // created only to write the results (see out_dir.rs)
    super::out_dir::check(&s.out)?;
    let mut notes = Vec::new();
    let plan = plan(s, &mut notes);
    let mut threads = s.threads.clone();
    threads.sort_unstable();
    threads.dedup();
    let pools: Pools = threads
        .iter()
        .map(|&t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map(|p| (t, p))
                .map_err(|e| Error::Runtime(format!("rayon pool of {t}: {e}")))
        })
        .collect::<Result<_, _>>()?;

    let steps = plan.len() * s.backends.len() * (1 + threads.len() * QueryKind::ALL.len());
    let bar = progress_bar(s.progress, steps);
    let started = Instant::now();
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    let mut failures = Vec::new();
    for (kind, level) in &plan {
        bar.set_message(format!("generating {kind}"));
        let first_row = rows.len();
        if let Some(sig) = lucent::interrupt::requested() {
            return Err(Error::Interrupted(sig));
        }
        let label = measure_mesh(s, kind, *level, &pools, &bar, &mut rows)?;
        check_hits(&rows[first_row..], &label, &mut warnings, &mut failures);
    }
    bar.finish_and_clear();
    for w in &warnings {
        let _ = writeln!(std::io::stderr(), "warning: {w}");
    }

    let mut report = report(&rows, &threads, s, started.elapsed().as_secs_f64());
    for n in &notes {
        let _ = writeln!(report, "note: {n}");
    }
    for w in &warnings {
        let _ = writeln!(report, "warning: {w}");
    }
    let out = super::out_dir::create(&s.out)?;
    let (csv, plots) = out.finish((|| {
        let csv = write_csv(&s.out, &rows)?;
        lucent::film::write_atomically(&s.out.join("report.txt"), |tmp| {
            std::io::Write::write_all(tmp, report.as_bytes()).map_err(|e| e.to_string())
        })?;
        let plots = plot::write_plots(&s.out, &rows).map_err(|e| Error::Runtime(e.to_string()))?;
        Ok((csv, plots))
    })())?;
    if !failures.is_empty() {
        let _ = write!(std::io::stdout(), "{report}");
        return Err(Error::Runtime(format!(
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

/// A bar on stderr counting builds and timed query sets, or a hidden one.
fn progress_bar(show: bool, steps: usize) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(Some(steps as u64), ProgressDrawTarget::stderr());
    b.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .unwrap()
            .progress_chars("=> "),
    );
    b
}

/// Generates one mesh of the plan and its ray sets, and measures every
/// backend on it: the build in the largest pool, then every query kind in
/// every pool, one row each appended to `rows`. Returns the mesh's label.
fn measure_mesh(
    s: &Settings,
    kind: &str,
    level: u32,
    pools: &Pools,
    bar: &ProgressBar,
    rows: &mut Vec<Row>,
) -> Result<String, Error> {
    let build_pool = &pools.last().unwrap().1;
    let bm = generate(kind, level, s)?;
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
    for &backend in &s.backends {
        bar.set_message(format!("{label}: {} build", backend.name()));
        measure::trim_heap();
        let rss0 = measure::rss_bytes();
        let t0 = Instant::now();
        let accel = build_pool
            .install(|| accel::build(&bm.mesh, backend))
            .map_err(|e| Error::Runtime(e.to_string()))?;
        let build_seconds = t0.elapsed().as_secs_f64();
        let rss1 = measure::rss_bytes();
        let build_mib = rss0
            .zip(rss1)
            .map(|(a, b)| b.saturating_sub(a) as f64 / (1u64 << 20) as f64);
        bar.inc(1);
        for (t, pool) in pools {
            for (q, set) in &sets {
                bar.set_message(format!("{label}: {} {} {t}t", backend.name(), q.name()));
                let tm =
                    measure::time_queries(accel.as_ref(), *q, set, pool, s.min_time, s.min_passes);
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
    Ok(label)
}
