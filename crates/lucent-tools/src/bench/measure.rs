//! Timing one query kind on one backend, and the memory a build keeps.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::rays::Query;
use lucent::accel::{Accel, ProbeHits};

/// Queries per rayon task: one 32×32 camera tile.
pub const CHUNK: usize = 1024;

/// The four measured queries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum QueryKind {
    /// Pinhole primary rays, nearest hit.
    Camera,
    /// Random rays through the bounds, nearest hit.
    Incoherent,
    /// Segments between surface points, any hit.
    Shadow,
    /// BSSRDF probe segments, every hit on the mesh.
    Probe,
}

impl QueryKind {
    pub const ALL: [QueryKind; 4] = [
        QueryKind::Camera,
        QueryKind::Incoherent,
        QueryKind::Shadow,
        QueryKind::Probe,
    ];
    pub fn name(self) -> &'static str {
        match self {
            QueryKind::Camera => "camera",
            QueryKind::Incoherent => "incoherent",
            QueryKind::Shadow => "shadow",
            QueryKind::Probe => "probe",
        }
    }
    pub fn parse(s: &str) -> Option<QueryKind> {
        QueryKind::ALL.into_iter().find(|q| q.name() == s)
    }
}

/// Runs every query once on the current rayon pool, in chunks of
/// [`CHUNK`]; returns the hit count: rays with a hit (camera, incoherent),
/// occluded segments (shadow) or the sum of distinct hits per segment
/// (probe, [`ProbeHits::total`]).
pub fn run_once(accel: &dyn Accel, kind: QueryKind, queries: &[Query]) -> u64 {
    queries
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(k, c)| match kind {
            QueryKind::Camera | QueryKind::Incoherent => c
                .iter()
                .filter(|q| accel.intersect(&q.ray, q.tmin, q.tmax).is_some())
                .count() as u64,
            QueryKind::Shadow => c
                .iter()
                .filter(|q| accel.occluded(&q.ray, q.tmin, q.tmax))
                .count() as u64,
            QueryKind::Probe => {
                let mut out = ProbeHits::new();
                c.iter()
                    .enumerate()
                    .map(|(i, q)| {
                        accel.hits_on_segment(&q.ray, q.tmax, 0, (k * CHUNK + i) as u32, &mut out);
                        out.total() as u64
                    })
                    .sum()
            }
        })
        .sum()
}

/// The result of [`time_queries`].
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    /// Hit count of the first (warm-up) pass.
    pub hits: u64,
    /// The fastest pass, in seconds.
    pub best: f64,
    /// Timed passes (after the warm-up).
    pub passes: u32,
    /// CPU time of the whole process over the timed passes divided by
    /// their wall time: about the thread count when the machine gives us
    /// the cores, less when others' work takes them (None without a
    /// process CPU clock).
    pub cpu_per_wall: Option<f64>,
}

/// Times [`run_once`] on `pool`: one warm-up pass (which also gives the hit
/// count), then passes until `min_time` has been spent and at least
/// `min_passes` ran (at most 50). Reports the fastest pass: on a machine
/// shared with other work, the fastest is the one least disturbed.
pub fn time_queries(
    accel: &dyn Accel,
    kind: QueryKind,
    queries: &[Query],
    pool: &rayon::ThreadPool,
    min_time: Duration,
    min_passes: u32,
) -> Timing {
    pool.install(|| {
        let hits = run_once(accel, kind, queries);
        let mut best = f64::INFINITY;
        let mut spent = Duration::ZERO;
        let mut passes = 0;
        let cpu0 = process_cpu_seconds();
        while passes < 50 && (passes < min_passes.max(1) || spent < min_time) {
            let t0 = Instant::now();
            let h = run_once(accel, kind, queries);
            let dt = t0.elapsed();
            assert_eq!(h, hits, "{} is not deterministic", accel.name());
            best = best.min(dt.as_secs_f64());
            spent += dt;
            passes += 1;
        }
        let cpu_per_wall = cpu0
            .zip(process_cpu_seconds())
            .map(|(a, b)| (b - a) / spent.as_secs_f64().max(1e-9));
        Timing {
            hits,
            best: best.max(1e-9),
            passes,
            cpu_per_wall,
        }
    })
}

/// CPU time used by all threads of this process so far, in seconds
/// (`CLOCK_PROCESS_CPUTIME_ID`; Linux only).
pub(crate) fn process_cpu_seconds() -> Option<f64> {
    #[cfg(all(target_os = "linux", target_pointer_width = "64"))]
    {
        #[repr(C)]
        struct Timespec {
            sec: i64,
            nsec: i64,
        }
        extern "C" {
            fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
        }
        const CLOCK_PROCESS_CPUTIME_ID: i32 = 2;
        let mut ts = Timespec { sec: 0, nsec: 0 };
        // SAFETY: ts is a valid, writable timespec (two 64-bit fields on
        // 64-bit Linux).
        let r = unsafe { clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
        if r == 0 {
            return Some(ts.sec as f64 + ts.nsec as f64 * 1e-9);
        }
    }
    None
}

/// Resident set size of this process in bytes, from `/proc/self/statm`
/// (None where that file does not exist).
pub fn rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = s.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * page_size())
}

fn page_size() -> u64 {
    #[cfg(target_os = "linux")]
    {
        extern "C" {
            fn sysconf(name: i32) -> i64;
        }
        // _SC_PAGESIZE is 30 on Linux.
        // SAFETY: sysconf has no preconditions.
        let p = unsafe { sysconf(30) };
        if p > 0 {
            return p as u64;
        }
    }
    4096
}

/// Returns freed heap memory to the kernel (glibc's `malloc_trim`), so that
/// an RSS delta around a build measures the build rather than reuse of
/// memory freed by the previous one. A no-op elsewhere.
pub(crate) fn trim_heap() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        extern "C" {
            fn malloc_trim(pad: usize) -> i32;
        }
        // SAFETY: malloc_trim only releases free memory.
        unsafe {
            malloc_trim(0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn query_names_round_trip() {
        for q in QueryKind::ALL {
            assert_eq!(QueryKind::parse(q.name()), Some(q));
        }
        assert_eq!(QueryKind::parse("nearest"), None);
    }

    #[test]
    fn cpu_clock_counts_busy_time() {
        let a = process_cpu_seconds().unwrap();
        let t0 = std::time::Instant::now();
        let mut x = 0u64;
        while t0.elapsed() < Duration::from_millis(100) {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
        let b = process_cpu_seconds().unwrap();
        // At least part of the 100 ms busy loop ran on a CPU.
        assert!(b - a > 0.02 && b - a < 100.0, "{a} -> {b}");
    }

    #[test]
    fn rss_grows_when_memory_is_touched() {
        // Other tests of the process may free memory meanwhile: a few tries.
        let grew = (0..3).any(|_| {
            let before = rss_bytes().unwrap();
            let v = vec![1u8; 64 << 20];
            let w: Vec<u8> = v.iter().map(|x| x.wrapping_add(1)).collect();
            let after = rss_bytes().unwrap();
            assert_eq!(w[12345], 2);
            after >= before + (32 << 20)
        });
        assert!(grew);
    }
}
