//! `lucent study SCENE`: what accuracy costs in time.
//!
//! Renders a matrix of sampling configurations of the subsurface estimator
//! ([`config`]: a baseline and one-axis-at-a-time variations) at a ladder
//! of sample counts 1, 2, 4, …, times each render and measures its error
//! against a long reference render ([`metrics`]). Writes `results.csv`
//! ([`results`], resumable), plots ([`plots`]) and `report.md` ([`report`])
//! into the output directory.
//!
//! The ladder is progressive: rung j adds a chunk of samples with seed
//! `seed + j` to the running mean, so the image at 2^j spp costs 2^j spp of
//! render time in total (not 2^(j+1) − 1) and its time is the sum of the
//! chunks' wall times. Rungs are rendered round-robin (every
//! configuration's rung j before any rung j + 1), so load drift on a shared
//! machine spreads over all configurations. Every configuration uses the
//! same seeds, and the reference uses seeds no configuration uses
//! ([`REFERENCE_SEED_OFFSET`]), so reference noise is independent of the
//! images it judges. The running
//! mean after each rung is kept in `DIR/state/`, so an interrupted study
//! resumes where it stopped without re-rendering anything, and a rerun with
//! a larger `max_spp` extends the ladder. The final image of each
//! configuration is written to `DIR/images/<config>.exr` (and `.png`).
//!
//! The reference is cached as `DIR/reference-<hash>.exr`, where the hash is
//! 64-bit FNV-1a ([`Fnv1a`], written here so it is stable across Rust
//! versions, unlike `DefaultHasher`) over the scene file's bytes, every
//! mesh's transformed vertex positions (so edits of an OBJ invalidate it
//! too), and the reference settings (integrator, spp, seed, resolution,
//! path depth, probe options).

pub mod config;
pub mod metrics;
pub mod plots;
pub mod report;
pub mod results;

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::accel::{self, Accel, Backend};
use crate::film::{self, Film, ToneMap};
use crate::geometry::Vec3;
use crate::integrator::IntegratorKind;
use crate::render::{self, RenderOptions};
use crate::scene::{self, Camera, Scene};
pub use config::{Axis, Config, Overrides};
use results::{Results, Row};

/// The reference's seed is the study's seed plus this: far from the ladder's
/// seeds (seed + 0 … seed + 30).
pub const REFERENCE_SEED_OFFSET: u64 = 1_000_003;

/// Everything `lucent study` can be told.
#[derive(Clone, Debug)]
pub struct Settings {
    pub scene: PathBuf,
    pub out_dir: PathBuf,
    /// A small matrix (see [`config::matrix`]) and the small sizes below.
    pub quick: bool,
    pub threads: Option<usize>,
    /// The integrator of the reference render.
    pub reference: IntegratorKind,
    pub reference_spp: u32,
    /// The ladder is 1, 2, 4, … up to this (a power of two ≤ it).
    pub max_spp: u32,
    /// Image width; the scene's aspect ratio is kept. Never above the scene's.
    pub width: u32,
    /// Base seed (default: the scene's).
    pub seed: Option<u64>,
    /// Firefly threshold: pixels above k × the reference.
    pub firefly_k: f64,
    /// Only these axes (the baseline always runs); empty: all.
    pub only: Vec<Axis>,
    pub progress: bool,
}

impl Settings {
    /// Defaults: full matrix at 128 px wide, ladder to 128 spp, a 4096-spp
    /// diffusion reference; `quick`: 48 px, ladder to 16 spp, 512-spp
    /// reference, a reduced matrix — under two minutes on two busy cores.
    pub fn new(scene: impl Into<PathBuf>, out_dir: impl Into<PathBuf>, quick: bool) -> Settings {
        Settings {
            scene: scene.into(),
            out_dir: out_dir.into(),
            quick,
            threads: None,
            reference: IntegratorKind::Path,
            reference_spp: if quick { 512 } else { 4096 },
            max_spp: if quick { 16 } else { 128 },
            width: if quick { 48 } else { 128 },
            seed: None,
            firefly_k: 10.0,
            only: Vec::new(),
            progress: false,
        }
    }
}

/// A study failure: bad input (exit code 2) or a failure while running.
#[derive(Clone, Debug, PartialEq)]
pub enum StudyError {
    Input(String),
    Runtime(String),
}

impl std::fmt::Display for StudyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StudyError::Input(m) | StudyError::Runtime(m) => f.write_str(m),
        }
    }
}

/// What a finished study produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub configs: Vec<Config>,
    pub rows: Vec<Row>,
    /// Rows rendered by this run (the others were already in the CSV).
    pub rendered_rows: usize,
    pub reference: ReferenceInfo,
    pub report: PathBuf,
    pub plots: Vec<PathBuf>,
}

/// How the reference image was made.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceInfo {
    pub path: PathBuf,
    pub hash: u64,
    pub integrator: IntegratorKind,
    pub spp: u32,
    pub seed: u64,
    /// Wall time of the render that made it (when it was made, possibly by
    /// an earlier run).
    pub seconds: f64,
    pub cached: bool,
    pub overrides: Overrides,
}

/// 64-bit FNV-1a (Fowler–Noll–Vo): a fixed, documented hash for cache keys.
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(pub u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    /// A length-prefixed field, so ("ab", "c") and ("a", "bc") differ.
    pub fn field(&mut self, bytes: &[u8]) {
        self.write(&(bytes.len() as u64).to_le_bytes());
        self.write(bytes);
    }
}

/// The ladder of sample counts: 1, 2, 4, … ≤ `max_spp`.
pub fn ladder(max_spp: u32) -> Vec<u32> {
    std::iter::successors(Some(1u32), |&s| s.checked_mul(2))
        .take_while(|&s| s <= max_spp)
        .collect()
}

fn validate(s: &Settings) -> Result<(), StudyError> {
    let bad = |m: String| Err(StudyError::Input(m));
    if s.threads == Some(0) {
        return bad("--threads must be at least 1".into());
    }
    if s.reference_spp == 0 || s.max_spp == 0 {
        return bad("sample counts must be at least 1".into());
    }
    if s.width < 4 {
        return bad(format!("--width {} is too small (at least 4)", s.width));
    }
    if !(s.firefly_k.is_finite() && s.firefly_k > 1.0) {
        return bad(format!(
            "--firefly-k {} must be a number above 1",
            s.firefly_k
        ));
    }
    if !s.scene.is_file() {
        return bad(format!("scene {}: no such file", s.scene.display()));
    }
    if s.out_dir.exists() && !s.out_dir.is_dir() {
        return bad(format!(
            "output {} exists and is not a directory",
            s.out_dir.display()
        ));
    }
    Ok(())
}

/// The scene at the study's resolution (the scene's aspect, `width` wide).
fn resized(mut scene: Scene, width: u32) -> Scene {
    let c = &scene.camera;
    let w = width.min(c.width);
    let h = ((c.height as f64 * w as f64 / c.width as f64).round() as u32).max(1);
    scene.camera = Camera::new(c.look_from, c.look_at, c.up, c.fov_y, w, h);
    scene
}

/// A configuration name as a file name: "radius=table:16" → "radius_table_16".
pub fn slug(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn state_path(dir: &Path, config: &str, spp: u32) -> PathBuf {
    dir.join("state")
        .join(format!("{}-{spp}.exr", slug(config)))
}

/// The cache key of the reference render.
fn reference_hash(
    scene_text: &[u8],
    scene: &Scene,
    integrator: IntegratorKind,
    spp: u32,
    seed: u64,
) -> u64 {
    let mut h = Fnv1a::default();
    h.field(b"lucent study reference v1");
    h.field(scene_text);
    for m in scene.meshes.iter() {
        h.field(&(m.positions().len() as u64).to_le_bytes());
        for p in m.positions() {
            for v in p.to_array() {
                h.write(&v.to_le_bytes());
            }
        }
    }
    let settings = format!(
        "integrator={} spp={spp} seed={seed} res={}x{} depth={} probe={}",
        config::integrator_name(integrator),
        scene.camera.width,
        scene.camera.height,
        scene.settings.max_depth,
        config::describe(&config::reference_overrides()),
    );
    h.field(settings.as_bytes());
    h.0
}

fn render_opts(
    s: &Settings,
    spp: u32,
    seed: u64,
    integrator: IntegratorKind,
    progress: bool,
) -> RenderOptions {
    RenderOptions {
        spp: Some(spp),
        seed: Some(seed),
        threads: s.threads,
        progress,
        integrator,
    }
}

fn runtime<E: std::fmt::Display>(e: E) -> StudyError {
    StudyError::Runtime(e.to_string())
}

/// Loads or renders the reference.
fn reference(
    s: &Settings,
    scene: &Scene,
    scene_text: &[u8],
    accel: &dyn Accel,
    seed: u64,
) -> Result<(Film, ReferenceInfo), StudyError> {
    let ref_seed = seed.wrapping_add(REFERENCE_SEED_OFFSET);
    let hash = reference_hash(scene_text, scene, s.reference, s.reference_spp, ref_seed);
    let path = s.out_dir.join(format!("reference-{hash:016x}.exr"));
    let meta = path.with_extension("txt");
    let overrides = config::reference_overrides();
    let mut info = ReferenceInfo {
        path: path.clone(),
        hash,
        integrator: s.reference,
        spp: s.reference_spp,
        seed: ref_seed,
        seconds: f64::NAN,
        cached: false,
        overrides,
    };
    if path.is_file() {
        let film = Film::read_exr(&path).map_err(runtime)?;
        if (film.width, film.height) == (scene.camera.width, scene.camera.height) {
            info.cached = true;
            info.seconds = fs::read_to_string(&meta)
                .ok()
                .and_then(|t| {
                    t.lines().find_map(|l| {
                        l.strip_prefix("seconds=")
                            .and_then(|v| v.trim().parse().ok())
                    })
                })
                .unwrap_or(f64::NAN);
            return Ok((film, info));
        }
    }
    let ref_scene = config::apply(scene, &overrides).map_err(StudyError::Input)?;
    if s.progress {
        eprintln!(
            "reference: {} at {} spp, {}x{} → {}",
            config::integrator_name(s.reference),
            s.reference_spp,
            scene.camera.width,
            scene.camera.height,
            path.display()
        );
    }
    let (film, stats) = render::render(
        &ref_scene,
        accel,
        &render_opts(s, s.reference_spp, ref_seed, s.reference, s.progress),
    )
    .map_err(runtime)?;
    film.write_exr(&path).map_err(runtime)?;
    film.write_png(&film::preview_path(&path), ToneMap::Filmic, 0.0)
        .map_err(runtime)?;
    info.seconds = stats.seconds;
    let text = format!(
        "integrator={}\nspp={}\nseed={}\nseconds={}\nresolution={}x{}\nprobe={}\nthreads={}\n",
        config::integrator_name(s.reference),
        s.reference_spp,
        ref_seed,
        stats.seconds,
        film.width,
        film.height,
        config::describe(&overrides),
        stats.threads
    );
    film::atomic_write(&meta, |tmp| fs::write(tmp, text).map_err(|e| e.to_string()))
        .map_err(runtime)?;
    Ok((film, info))
}

/// Rows in `results.csv` are only comparable (and only resumable) under the
/// settings that made them: the same reference (which covers the scene,
/// resolution and reference settings), base seed and firefly factor. They
/// are recorded in `DIR/results.key` next to the CSV; a directory holding
/// rows made under other settings is refused rather than mixed. Thread
/// count, ladder length and the axis filter may change between runs.
fn check_results_key(
    s: &Settings,
    r: &ReferenceInfo,
    seed: u64,
    scene: &Scene,
) -> Result<(), StudyError> {
    let key = format!(
        "reference={:016x} seed={seed} firefly_k={} resolution={}x{}\n",
        r.hash, s.firefly_k, scene.camera.width, scene.camera.height
    );
    let key_path = s.out_dir.join("results.key");
    let csv = s.out_dir.join("results.csv");
    let has_rows = fs::read_to_string(&csv)
        .map(|t| t.lines().count() > 1)
        .unwrap_or(false);
    match fs::read_to_string(&key_path) {
        Ok(old) if old == key => return Ok(()),
        Ok(old) if has_rows => {
            return Err(StudyError::Input(format!(
                "{} holds results made with other settings ({}), not ({}); choose another output directory",
                csv.display(),
                old.trim(),
                key.trim()
            )))
        }
        Err(_) if has_rows => {
            return Err(StudyError::Input(format!(
                "{} has rows but no results.key: cannot tell which settings made them; choose another output directory",
                csv.display()
            )))
        }
        _ => {}
    }
    film::atomic_write(&key_path, |tmp| {
        fs::write(tmp, &key).map_err(|e| e.to_string())
    })
    .map_err(runtime)
}

/// Runs (or resumes) a study; see the module docs.
pub fn run(s: &Settings) -> Result<Outcome, StudyError> {
    validate(s)?;
    let scene_text =
        fs::read(&s.scene).map_err(|e| StudyError::Input(format!("{}: {e}", s.scene.display())))?;
    let scene = scene::load(&s.scene).map_err(|e| StudyError::Input(e.to_string()))?;
    let scene = resized(scene, s.width);
    let seed = s.seed.unwrap_or(scene.settings.seed);
    let mut backends = vec![Backend::default_available()];
    if backends[0] == Backend::Embree {
        backends.push(Backend::Bvh);
    }
    let configs: Vec<Config> = config::matrix(&scene, s.quick, &backends)
        .map_err(StudyError::Input)?
        .into_iter()
        .filter(|c| c.axis == Axis::Baseline || s.only.is_empty() || s.only.contains(&c.axis))
        .collect();
    fs::create_dir_all(s.out_dir.join("state"))
        .map_err(|e| StudyError::Runtime(format!("cannot create {}: {e}", s.out_dir.display())))?;

    // Every backend the matrix uses, built once and shared by its configs
    // (a configuration rebuilds materials, never meshes).
    let mut accels: HashMap<&'static str, Box<dyn Accel>> = HashMap::new();
    for b in backends
        .iter()
        .filter(|b| configs.iter().any(|c| c.backend == **b) || **b == backends[0])
    {
        accels.insert(
            b.name(),
            accel::build(&scene.meshes, *b).map_err(StudyError::Input)?,
        );
    }
    let (reference, ref_info) = reference(
        s,
        &scene,
        &scene_text,
        accels[backends[0].name()].as_ref(),
        seed,
    )?;

    check_results_key(s, &ref_info, seed, &scene)?;
    let mut results = Results::open(&s.out_dir.join("results.csv")).map_err(runtime)?;
    let spps = ladder(s.max_spp);
    let pending = configs
        .iter()
        .map(|c| {
            spps.iter()
                .filter(|&&n| results.get(&c.name, n).is_none())
                .count() as u64
        })
        .sum::<u64>();
    let bar = if s.progress && pending > 0 {
        let b = ProgressBar::with_draw_target(Some(pending), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {pos}/{len} renders, eta {eta} {msg}",
            )
            .unwrap()
            .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let mut rendered_rows = 0;
    let started = Instant::now();

    // Per configuration: where it resumes, and its running mean so far.
    struct Job<'c> {
        config: &'c Config,
        scene: Scene,
        start: usize,
        acc: Option<(Film, f64)>,
    }
    let mut jobs = Vec::new();
    for c in &configs {
        if spps.iter().all(|&n| results.get(&c.name, n).is_some()) {
            continue;
        }
        // Resume from the last rung whose row and running mean both exist
        // and below which every row exists.
        let (mut start, mut acc) = (0, None);
        for (j, &n) in spps.iter().enumerate() {
            let Some(row) = results.get(&c.name, n) else {
                break;
            };
            if let Ok(f) = Film::read_exr(&state_path(&s.out_dir, &c.name, n)) {
                if (f.width, f.height) == (scene.camera.width, scene.camera.height) {
                    start = j + 1;
                    acc = Some((f, row.seconds));
                }
            }
        }
        let scene = config::apply(&scene, &c.overrides).map_err(StudyError::Input)?;
        jobs.push(Job {
            config: c,
            scene,
            start,
            acc,
        });
    }
    // Rung by rung, every configuration in turn: on a shared machine the
    // load drifts, and interleaving spreads that drift over all
    // configurations instead of penalizing whichever ran in a busy minute.
    for (j, &n) in spps.iter().enumerate() {
        let prev_n = if j == 0 { 0 } else { spps[j - 1] };
        for job in jobs.iter_mut().filter(|job| job.start <= j) {
            let c = job.config;
            bar.set_message(format!("{} @ {n} spp", c.name));
            let (film, stats) = render::render(
                &job.scene,
                accels[c.backend.name()].as_ref(),
                &render_opts(
                    s,
                    n - prev_n,
                    seed.wrapping_add(j as u64),
                    c.integrator,
                    false,
                ),
            )
            .map_err(runtime)?;
            let (mean, seconds) = match job.acc.take() {
                None => (film, stats.seconds),
                Some((mut m, t)) => {
                    let (a, b) = (prev_n as f64 / n as f64, (n - prev_n) as f64 / n as f64);
                    for (p, q) in m.pixels.iter_mut().zip(&film.pixels) {
                        let mix = |x: f32, y: f32| (a * x as f64 + b * y as f64) as f32;
                        *p = Vec3::new(mix(p.x, q.x), mix(p.y, q.y), mix(p.z, q.z));
                    }
                    (m, t + stats.seconds)
                }
            };
            // The running mean of the last finished rung, kept also after the
            // last one so a rerun with a larger max_spp extends the ladder.
            mean.write_exr(&state_path(&s.out_dir, &c.name, n))
                .map_err(runtime)?;
            if j > 0 {
                let _ = fs::remove_file(state_path(&s.out_dir, &c.name, prev_n));
            }
            if results.get(&c.name, n).is_none() {
                let m = metrics::compare(&mean, &reference, s.firefly_k).map_err(runtime)?;
                results
                    .append(Row {
                        config: c.name.clone(),
                        axis: c.axis.name().into(),
                        value: c.value.clone(),
                        backend: c.backend.name().into(),
                        integrator: config::integrator_name(c.integrator).into(),
                        spp: n,
                        seconds,
                        rmse: m.rmse,
                        rel_mse: m.rel_mse,
                        bias: m.bias,
                        bias_stderr: m.bias_stderr,
                        fireflies: m.fireflies,
                    })
                    .map_err(runtime)?;
                rendered_rows += 1;
                bar.inc(1);
            }
            job.acc = Some((mean, seconds));
        }
    }
    for job in &jobs {
        if let Some((film, _)) = &job.acc {
            // The final image of each configuration, for looking at.
            let img = s
                .out_dir
                .join("images")
                .join(format!("{}.exr", slug(&job.config.name)));
            fs::create_dir_all(img.parent().unwrap()).map_err(runtime)?;
            film.write_exr(&img).map_err(runtime)?;
            film.write_png(&film::preview_path(&img), ToneMap::Filmic, 0.0)
                .map_err(runtime)?;
        }
    }
    bar.finish_and_clear();
    let rows: Vec<Row> = results
        .rows()
        .iter()
        .filter(|r| configs.iter().any(|c| c.name == r.config) && spps.contains(&r.spp))
        .cloned()
        .collect();
    let plots = plots::write_all(&s.out_dir, &rows, &configs).map_err(runtime)?;
    let report = report::write(
        s,
        &scene,
        &configs,
        &rows,
        &ref_info,
        &plots,
        started.elapsed().as_secs_f64(),
    )
    .map_err(runtime)?;
    Ok(Outcome {
        configs,
        rows,
        rendered_rows,
        reference: ref_info,
        report,
        plots,
    })
}
