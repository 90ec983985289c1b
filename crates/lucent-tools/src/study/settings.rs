//! What `lucent study` is told: [`Settings`], their defaults (full and
//! `--quick`), and the checks that make bad settings an input error (exit
//! code 2) before anything runs.

use std::path::PathBuf;

use super::config::Axis;
use lucent::integrator::IntegratorKind;
use lucent::Error;

/// Everything `lucent study` can be told.
#[derive(Clone, Debug)]
pub struct Settings {
    pub scene: PathBuf,
    pub out_dir: PathBuf,
    /// A small matrix (see [`config::matrix`](super::config::matrix)) and the small sizes below.
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

/// Checks the settings, that the scene file exists and that the output,
/// if it exists, is a directory.
pub(super) fn validate(s: &Settings) -> Result<(), Error> {
    let bad = |m: String| Err(Error::Input(m));
    if let Some(n) = s
        .threads
        .filter(|n| !(1..=lucent::render::MAX_THREADS).contains(n))
    {
        return bad(format!(
            "--threads: {n} is not a thread count (1 to {})",
            lucent::render::MAX_THREADS
        ));
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
