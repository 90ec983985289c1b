//! Resuming a study: nothing already rendered is rendered again.
//!
//! The running mean after each rung of a configuration's ladder
//! ([`Running`]) is kept in `DIR/state/<config>-<spp>.exr`, with
//! `-albedo` and `-normal` guides when it denoises (only the last finished rung's, also
//! after the last rung, so a rerun with a larger `max_spp` extends the
//! ladder); a configuration resumes after the last rung whose CSV row and
//! running mean both exist and below which every row exists. Rows are
//! only resumed under the settings that made them ([`check_results_key`]).

use super::config::{self, Config};
use super::input_file::read_text;
use super::reference::ReferenceInfo;
use super::results::Results;
use super::running::Running;
use super::runtime;
use super::settings::Settings;
use lucent::film;
use lucent::scene::Scene;
use lucent::Error;

/// Rows in `results.csv` are only comparable (and only resumable) under the
/// settings that made them: the same reference (which covers the scene,
/// resolution and reference settings), base seed, firefly factor and
/// ladder ([`LADDER`]). They
/// are recorded in `DIR/results.key` next to the CSV; a directory holding
/// rows made under other settings is refused rather than mixed. Thread
/// count, ladder length and the axis filter may change between runs.
///
/// Only reads: [`write_results_key`] records the key once the reference
/// exists. A study checks this before it writes anything, so a directory
/// it refuses is left as it was.
pub(super) fn check_results_key(
    s: &Settings,
    reference_hash: u64,
    seed: u64,
    scene: &Scene,
) -> Result<(), Error> {
    let key = results_key(s, reference_hash, seed, scene);
    let key_path = s.out_dir.join("results.key");
    let csv = s.out_dir.join("results.csv");
    let has_rows = read_text(&csv)
        .map_err(|e| Error::Input(format!("{}: {e}", csv.display())))?
        .is_some_and(|t| t.lines().count() > 1);
    let old_key = read_text(&key_path)
        .map_err(|e| Error::Input(format!("{}: {e}", key_path.display())))?
        .ok_or(());
    match old_key {
        Ok(old) if old == key => return Ok(()),
        Ok(old) if has_rows => {
            return Err(Error::Input(format!(
                "{} holds results made with other settings ({}), not ({}); choose another output directory",
                csv.display(),
                old.trim(),
                key.trim()
            )))
        }
        Err(_) if has_rows => {
            return Err(Error::Input(format!(
                "{} has rows but no results.key: cannot tell which settings made them; choose another output directory",
                csv.display()
            )))
        }
        _ => {}
    }
    Ok(())
}

/// How the ladder's rungs are rendered: each extends the sample range of
/// one seed (rows of a ladder that reseeded every rung are not mixed in).
const LADDER: &str = "ranges";

/// The line `results.key` holds for these settings.
fn results_key(s: &Settings, reference_hash: u64, seed: u64, scene: &Scene) -> String {
    format!(
        "reference={reference_hash:016x} seed={seed} firefly_k={} resolution={}x{} ladder={LADDER}\n",
        s.firefly_k, scene.camera.width, scene.camera.height
    )
}

/// Records the settings of the rows in `results.csv` (see
/// [`check_results_key`]).
pub(super) fn write_results_key(
    s: &Settings,
    r: &ReferenceInfo,
    seed: u64,
    scene: &Scene,
) -> Result<(), Error> {
    let key = results_key(s, r.hash, seed, scene);
    let key_path = s.out_dir.join("results.key");
    if read_text(&key_path).is_ok_and(|old| old.is_some_and(|old| old == key)) {
        return Ok(());
    }
    film::atomic_write(&key_path, |tmp| {
        std::io::Write::write_all(tmp, key.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(runtime)
}

/// One configuration still to render: where it resumes, and its running
/// mean so far.
pub(super) struct Job<'c> {
    pub(super) config: &'c Config,
    /// The scene with the configuration's overrides applied.
    pub(super) scene: Scene,
    /// Index of the first rung to render.
    pub(super) start: usize,
    /// The running mean after rung `start - 1`.
    pub(super) acc: Option<Running>,
}

/// The configurations with rungs left to render, each with its resume
/// point.
pub(super) fn jobs<'c>(
    s: &Settings,
    scene: &Scene,
    configs: &'c [Config],
    spps: &[u32],
    results: &Results,
) -> Result<Vec<Job<'c>>, Error> {
    let mut jobs = Vec::new();
    for c in configs {
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
            let size = (scene.camera.width, scene.camera.height);
            let render_seconds = row.seconds - row.denoise_seconds;
            if let Some(r) = Running::load(&s.out_dir, &c.name, n, size, c.denoise, render_seconds)
            {
                start = j + 1;
                acc = Some(r);
            }
        }
        let scene = config::apply(scene, &c.overrides).map_err(|e| Error::Input(e.to_string()))?;
        jobs.push(Job {
            config: c,
            scene,
            start,
            acc,
        });
    }
    Ok(jobs)
}
