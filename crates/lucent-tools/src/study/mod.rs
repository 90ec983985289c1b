//! `lucent study SCENE`: what accuracy costs in time (`docs/accuracy.md`,
//! "How a study works").
//!
//! Renders a matrix of sampling configurations of the subsurface estimator
//! ([`config`]: a baseline and one-axis-at-a-time variations) at a
//! progressive ladder of sample counts 1, 2, 4, …, times each render and
//! measures its error (of the image denoised, for the configuration that
//! denoises) against a long, cached reference render
//! ([`metrics`]; the reference's seeds are offset by
//! [`REFERENCE_SEED_OFFSET`], its cache key is [`Fnv1a`]). Writes
//! `results.csv` ([`results`], resumable), plots ([`plots`]) and
//! `report.md` ([`report`]) into the output directory. The files:
//! `settings` (what it is told), [`config`] (the matrix), `reference`,
//! `resume` (what is already done), `ladder` (the renders), [`metrics`],
//! [`results`], [`plots`] and [`report`].

pub mod cli;
mod compare;
pub mod config;
mod convergence;
mod denoised;
mod input_file;
mod ladder;
pub mod metrics;
pub mod plots;
mod reference;
pub mod report;
pub mod results;
mod resume;
mod running;
mod settings;

use std::collections::HashMap;
use std::fs;
use std::path::PathBuf;
use std::time::Instant;

pub use config::{Axis, Config, Overrides};
pub use ladder::ladder;
use ladder::Ladder;
use lucent::accel::{self, Accel, Backend, Traversal};
use lucent::integrator::IntegratorKind;
use lucent::render::RenderOptions;
use lucent::sampling::SamplerKind;
use lucent::scene::{self, Camera, Scene};
pub use reference::{Fnv1a, ReferenceInfo, REFERENCE_SEED_OFFSET};
use results::{Results, Row};
pub use running::slug;
pub use settings::Settings;

use lucent::Error;

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
    /// Why the denoised configuration was left out (Open Image Denoise
    /// could not be loaded), if it was.
    pub no_denoise: Option<String>,
}

/// The scene at the study's resolution (the scene's aspect, `width` wide).
fn resized(mut scene: Scene, width: u32) -> Scene {
    let c = &scene.camera;
    let w = width.min(c.width);
    let h = ((c.height as f64 * w as f64 / c.width as f64).round() as u32).max(1);
    scene.camera = Camera::new(c.look_from, c.look_at, c.up, c.fov_y, w, h);
    scene
}

fn render_opts(
    s: &Settings,
    spp: u32,
    seed: u64,
    integrator: IntegratorKind,
    sampler: Option<SamplerKind>,
    progress: bool,
) -> RenderOptions {
    RenderOptions {
        spp: Some(spp),
        seed: Some(seed),
        sampler,
        threads: s.threads,
        progress: progress.then(crate::progress::Bar::sink),
        integrator,
        stats: false,
    }
}

fn runtime<E: std::fmt::Display>(e: E) -> Error {
    Error::Runtime(e.to_string())
}

/// The accels the matrix uses, by backend name and traversal, built once
/// and shared by its configurations (a configuration rebuilds materials,
/// never meshes): each configuration's backend with the traversal `lucent
/// render` would use for it (`IntegratorKind::traversal`), so its time is a
/// render's, and the first backend watertight, which renders the
/// reference.
pub(super) type Accels = HashMap<(&'static str, Traversal), Box<dyn Accel>>;

fn build_accels(scene: &Scene, backends: &[Backend], configs: &[Config]) -> Result<Accels, Error> {
    let mut accels = Accels::new();
    let wanted = configs
        .iter()
        .map(|c| (c.backend, c.integrator.traversal(scene.settings.traversal)))
        .chain([(backends[0], Traversal::Watertight)]);
    for (b, t) in wanted {
        if let std::collections::hash_map::Entry::Vacant(e) = accels.entry((b.name(), t)) {
            e.insert(accel::build_with(&scene.meshes, b, t)?);
        }
    }
    Ok(accels)
}

/// Runs (or resumes) a study; see the module docs.
pub fn run(s: &Settings) -> Result<Outcome, Error> {
    settings::validate(s)?;
    let scene = scene::load(&s.scene).map_err(|e| Error::Input(e.to_string()))?;
    let scene_text = scene::load::read_regular_file(&s.scene, scene::load::MAX_SCENE_BYTES)
        .map_err(|e| Error::Input(format!("{}: {e}", s.scene.display())))?
        .into_bytes();
    let scene = resized(scene, s.width);
    let seed = s.seed.unwrap_or(scene.settings.seed);
    let mut backends = vec![Backend::default_available()];
    if backends[0] == Backend::Embree {
        backends.push(Backend::Bvh);
    }
    let mut configs: Vec<Config> = config::matrix(&scene, s.quick, &backends)
        .map_err(|e| Error::Input(e.to_string()))?
        .into_iter()
        .filter(|c| c.axis == Axis::Baseline || s.only.is_empty() || s.only.contains(&c.axis))
        .collect();
    // Without the denoiser there is no denoised curve, never a stand-in.
    let no_denoise = configs
        .iter()
        .any(|c| c.denoise)
        .then(denoised::unavailable)
        .flatten();
    if no_denoise.is_some() {
        configs.retain(|c| !c.denoise);
    }
    // A directory whose results cannot be resumed is refused before
    // anything is written in it (no state/, no cached reference).
    let csv = s.out_dir.join("results.csv");
    Results::read(&csv).map_err(|e| Error::Input(e.to_string()))?;
    let hash = reference::hash_for(s, &scene, &scene_text, seed);
    resume::check_results_key(s, hash, seed, &scene)?;
    fs::create_dir_all(s.out_dir.join("state"))
        .map_err(|e| Error::Runtime(format!("cannot create {}: {e}", s.out_dir.display())))?;
    let accels = build_accels(&scene, &backends, &configs)?;
    let (reference, ref_info) = reference::reference(
        s,
        &scene,
        &scene_text,
        accels[&(backends[0].name(), Traversal::Watertight)].as_ref(),
        seed,
    )?;

    resume::write_results_key(s, &ref_info, seed, &scene)?;
    let mut results = Results::open(&csv).map_err(runtime)?;
    let spps = ladder(s.max_spp);
    let bar = ladder::progress_bar(s, &configs, &spps, &results);
    let started = Instant::now();
    let mut jobs = resume::jobs(s, &scene, &configs, &spps, &results)?;
    let rungs = Ladder {
        settings: s,
        spps: &spps,
        accels: &accels,
        reference: &reference,
        seed,
    };
    let rendered_rows = rungs.render(&mut jobs, &mut results, &bar)?;
    ladder::write_final_images(s, &jobs)?;
    bar.finish_and_clear();
    let rows: Vec<Row> = results
        .rows()
        .iter()
        .filter(|r| configs.iter().any(|c| c.name == r.config) && spps.contains(&r.spp))
        .cloned()
        .collect();
    let plots = plots::write_all(&s.out_dir, &rows, &configs).map_err(runtime)?;
    let made = report::Made {
        reference: &ref_info,
        plots: &plots,
        no_denoise: no_denoise.as_deref(),
        seconds: started.elapsed().as_secs_f64(),
    };
    let report = report::write(s, &scene, &configs, &rows, &made).map_err(runtime)?;
    Ok(Outcome {
        configs,
        rows,
        rendered_rows,
        reference: ref_info,
        report,
        plots,
        no_denoise,
    })
}
