//! What `lucent bench --scene` is told: [`Settings`], their defaults, and
//! the checks that make bad settings an input error (exit code 2) before
//! anything runs.

use std::path::PathBuf;

use crate::bench::{available_backends, default_threads};
use lucent::accel::{self, Backend};
use lucent::Error;

/// What `lucent bench --scene` does.
#[derive(Clone, Debug)]
pub struct Settings {
    pub scene: PathBuf,
    pub out: PathBuf,
    /// Samples per pixel of every render.
    pub spp: u32,
    /// Thread counts; each gets its own renders, recording and replays.
    pub threads: Vec<usize>,
    pub backends: Vec<Backend>,
    /// Timed renders per (backend, threads); the fastest counts.
    pub renders: u32,
    /// Timed replay passes (all kinds, alternating with the renders, then
    /// each kind); the fastest counts.
    pub passes: u32,
    /// Most queries one recording may hold (× [`RECORD_BYTES`](super::RECORD_BYTES) of memory).
    pub max_records: usize,
    /// Status lines on stderr.
    pub progress: bool,
}

/// Default samples per pixel: the marble bunny at 640×480 and 2 spp is
/// 1.7M queries (73 MB of log), about 1 s per render on one core.
pub const DEFAULT_SPP: u32 = 2;
/// Default cap on one recording: 32M queries, 1.4 GB.
pub const DEFAULT_MAX_RECORDS: usize = 32_000_000;

impl Settings {
    /// The defaults: [`DEFAULT_SPP`], one thread and all, every backend of
    /// this build, 3 renders and 5 replay passes, [`DEFAULT_MAX_RECORDS`].
    pub fn new(scene: impl Into<PathBuf>, out: impl Into<PathBuf>) -> Settings {
        let threads = default_threads();
        Settings {
            scene: scene.into(),
            out: out.into(),
            spp: DEFAULT_SPP,
            threads,
            backends: available_backends(),
            renders: 3,
            passes: 5,
            max_records: DEFAULT_MAX_RECORDS,
            progress: true,
        }
    }
}

/// Checks the settings and that the scene's backends are in this build.
pub(super) fn validate(s: &Settings) -> Result<(), Error> {
    let input = |m: String| Err(Error::Input(m));
    if s.spp == 0 {
        return input("--spp must be at least 1".into());
    }
    let max = lucent::render::MAX_THREADS;
    if s.threads.is_empty() || s.threads.iter().any(|n| !(1..=max).contains(n)) {
        return input(format!("--threads: thread counts must be 1 to {max}"));
    }
    if s.backends.is_empty() {
        return input("no backend to measure".into());
    }
    let available = available_backends();
    if let Some(b) = s.backends.iter().find(|b| !available.contains(b)) {
        // The same message `lucent render --accel` gives.
        let e = accel::build(&std::sync::Arc::new(Vec::new()), *b).err();
        return Err(
            e.unwrap_or_else(|| Error::Input(format!("backend {} is not available", b.name())))
        );
    }
    Ok(())
}
