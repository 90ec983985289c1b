//! `bench.csv`: one [`Row`] per (mesh, backend, query, threads), with the
//! fastest pass, the rate derived from it, and the mesh's build. Empty
//! cells where `/proc` or a CPU clock was missing.

use std::path::{Path, PathBuf};

use super::measure::QueryKind;
use lucent::Error;

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
    /// ([`Timing::cpu_per_wall`](super::measure::Timing::cpu_per_wall)).
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

/// Writes `bench.csv` into `out` (atomically: a failed write leaves no
/// partial file) and returns its path.
pub(super) fn write_csv(out: &Path, rows: &[Row]) -> Result<PathBuf, Error> {
    let csv = out.join("bench.csv");
    let mut text = String::from(CSV_HEADER);
    text.push('\n');
    for r in rows {
        text.push_str(&csv_line(r));
        text.push('\n');
    }
    lucent::film::atomic_write(&csv, |tmp| {
        std::io::Write::write_all(tmp, text.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(|e| Error::Runtime(format!("{}: {e}", csv.display())))?;
    Ok(csv)
}
