//! What `lucent bench` is told: [`Settings`], their defaults (full run and
//! `--quick`), the parsers of its command-line values, and the checks that
//! make bad settings an input error (exit code 2) before anything runs.

use std::path::{Path, PathBuf};
use std::time::Duration;

use lucent::accel::Backend;
use lucent::render::MAX_THREADS;
use lucent::Error;

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
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(rel),
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

/// Our BVH, and each Embree this process can use (Embree 3, Embree 4).
pub fn available_backends() -> Vec<Backend> {
    Backend::all_available()
}

/// A count on the command line that cannot be used; each names the text
/// given. clap's `value_parser`s return it as is.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CountError {
    /// Not a number (with an optional `k`/`M` suffix).
    #[error("\"{0}\" is not a triangle count (examples: 1000, 16k, 1.3M)")]
    Size(String),
    /// A triangle count outside 20 to 25M.
    #[error("size \"{0}\" out of range: between 20 and 25M triangles")]
    SizeRange(String),
    /// Not a thread count from 1 to [`MAX_THREADS`].
    #[error("\"{0}\" is not a thread count (1 to {max})", max = MAX_THREADS)]
    Threads(String),
    /// Not a ray count from 1 to `MAX_RAYS`.
    #[error("\"{0}\" is not a ray count from 1 to 20M (examples: 100000, 500k, 2M)")]
    Rays(String),
}

/// Parses a triangle count: `1000`, `16k`, `1.3M`.
pub fn parse_size(s: &str) -> Result<usize, CountError> {
    let t = s.trim();
    let (num, mul) = match t.chars().last() {
        Some('k' | 'K') => (&t[..t.len() - 1], 1e3),
        Some('m' | 'M') => (&t[..t.len() - 1], 1e6),
        _ => (t, 1.0),
    };
    let v: f64 = num.parse().map_err(|_| CountError::Size(s.to_string()))?;
    let n = (v * mul).round();
    if !(20.0..=25e6).contains(&n) {
        return Err(CountError::SizeRange(s.to_string()));
    }
    Ok(n as usize)
}

/// Parses a thread count: 1 to [`MAX_THREADS`] (1024); `render` and
/// `study` parse `--threads` with it too.
pub fn parse_threads(s: &str) -> Result<usize, CountError> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
        _ => Err(CountError::Threads(s.to_string())),
    }
}

/// The most rays a query set may have: each set is held in memory with its
/// results (about 40 bytes a ray), 800 MB at this bound.
pub(crate) const MAX_RAYS: usize = 20_000_000;

/// Parses a ray count: a positive integer up to `MAX_RAYS`, `k`/`M`
/// suffixes allowed.
pub fn parse_rays(s: &str) -> Result<usize, CountError> {
    let t = s.trim();
    let (num, mul) = match t.chars().last() {
        Some('k' | 'K') => (&t[..t.len() - 1], 1e3),
        Some('m' | 'M') => (&t[..t.len() - 1], 1e6),
        _ => (t, 1.0),
    };
    match num.parse::<f64>() {
        Ok(v) if (v * mul).round() >= 1.0 && v * mul <= MAX_RAYS as f64 => {
            Ok((v * mul).round() as usize)
        }
        _ => Err(CountError::Rays(s.to_string())),
    }
}

/// Checks the settings: at least one size, thread count, ray and backend.
pub(super) fn validate(s: &Settings) -> Result<(), Error> {
    let bad = |m: &str| Err(Error::Input(m.to_string()));
    if s.sizes.is_empty() {
        return bad("--sizes: give at least one size");
    }
    if s.threads.is_empty() || s.threads.iter().any(|n| !(1..=MAX_THREADS).contains(n)) {
        return bad("--threads: thread counts must be 1 to 1024");
    }
    if s.rays == 0 {
        return bad("--rays must be at least 1");
    }
    if s.backends.is_empty() {
        return bad("no backend to measure");
    }
    Ok(())
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
        assert_eq!(parse_rays("20M"), Ok(MAX_RAYS));
        assert!(parse_rays("20000001").is_err() && parse_rays("1e9").is_err());
        // the messages clap shows after the argument's name
        assert_eq!(
            parse_size("10").unwrap_err().to_string(),
            "size \"10\" out of range: between 20 and 25M triangles"
        );
        assert_eq!(
            parse_threads("0").unwrap_err().to_string(),
            "\"0\" is not a thread count (1 to 1024)"
        );
    }
}
