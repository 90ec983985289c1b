//! `lucent bench --scene`: how fast the renderer runs against how fast its
//! backend answers the very queries the render issued (`docs/performance.md`,
//! "Where the renderer's time goes").
//!
//! The scene is rendered normally (timed: the end-to-end rate), then once
//! more through a [`Recorder`], an [`Accel`](lucent::accel::Accel) that
//! forwards every query to the real backend and logs it per rayon worker
//! with a digest of every answer; each worker's log is then replayed on its
//! own thread through the bare backend as `&dyn Accel` (the raw rate), and
//! an answer that differs from the render's is an error. A record is
//! [`RECORD_BYTES`] bytes; a run stops beyond [`Settings::max_records`]
//! queries. The files: `record`, `recorder`, `digest`, `playback`,
//! `timing`, `measure`, `rows`, `csv`, `report`, `settings`; `tests`
//! records and replays the marble-ball fixture.

mod csv;
mod digest;
mod measure;
mod playback;
mod record;
mod recorder;
mod report;
mod rows;
mod settings;
mod timing;

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

pub use csv::csv_header;
pub use digest::{Digest, Digests};
use lucent::accel;
use lucent::Error;
pub use playback::{replay_digest, replay_hits};
pub use record::{Kind, Record, RECORD_BYTES};
pub use recorder::Recorder;
pub use report::report;
pub use rows::{KindRow, MixRow, TARGET_RATIO};
pub use settings::{Settings, DEFAULT_MAX_RECORDS, DEFAULT_SPP};

/// What [`run`] produced.
pub struct Outcome {
    pub rows: Vec<MixRow>,
    pub csv: PathBuf,
    /// The text printed on stdout (also `render-mix.txt`).
    pub report: String,
    /// Differences between the render's ray counter and the record count,
    /// explained (also in the report).
    pub notes: Vec<String>,
}

fn input(m: impl Into<String>) -> Error {
    Error::Input(m.into())
}

fn runtime(m: impl Into<String>) -> Error {
    Error::Runtime(m.into())
}

fn status(s: &Settings, m: String) {
    if s.progress {
        eprintln!("{m}");
    }
}

/// Runs the measurement for every backend and thread count and writes
/// `render-mix.csv` and `render-mix.txt` into `s.out`.
pub fn run(s: &Settings) -> Result<Outcome, Error> {
    settings::validate(s)?;
    let scene = lucent::scene::load(&s.scene).map_err(|e| input(e.to_string()))?;
    // created only to write the results (see out_dir.rs)
    super::out_dir::check(&s.out)?;
    let mut threads = s.threads.clone();
    threads.sort_unstable();
    threads.dedup();
    let started = Instant::now();
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for &backend in &s.backends {
        let accel = accel::build(&scene.meshes, backend).map_err(input)?;
        for &t in &threads {
            if let Some(sig) = lucent::interrupt::requested() {
                return Err(Error::Interrupted(sig));
            }
            let row = measure::measure(s, &scene, accel.as_ref(), t, &mut notes)?;
            rows.push(row);
        }
    }
    let mut rep = report(&rows, s, &scene, started.elapsed());
    for n in &notes {
        let _ = writeln!(rep, "note: {n}");
    }
    let out = super::out_dir::create(&s.out)?;
    let csv = out.finish((|| {
        let csv = csv::write_csv(&s.out, &rows, &s.scene, &scene, s.spp)?;
        lucent::film::write_atomically(&s.out.join("render-mix.txt"), |tmp| {
            std::io::Write::write_all(tmp, rep.as_bytes()).map_err(|e| e.to_string())
        })?;
        Ok(csv)
    })())?;
    Ok(Outcome {
        rows,
        csv,
        report: rep,
        notes,
    })
}

// Their scene (tests/fixtures/marble-ball.toml) has a subsurface material.
#[cfg(all(test, feature = "subsurface"))]
mod tests;
