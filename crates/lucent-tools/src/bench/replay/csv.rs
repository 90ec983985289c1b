//! `render-mix.csv`: one row per (backend, threads) with the scene, the
//! end-to-end and raw figures and, per query kind, its count, hits, replay
//! time and rate. Empty cells where a CPU clock was missing.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::record::Kind;
use super::rows::MixRow;
use lucent::scene::Scene;
use lucent::Error;

/// The CSV's header: one row per (backend, threads).
pub fn csv_header() -> String {
    let mut h = String::from(
        "scene,width,height,spp,triangles,backend,threads,render_rays,records,\
         render_s,render_mrays_per_s,render_cpu_per_wall,record_s,replay_s,raw_mrays_per_s,\
         replay_cpu_per_wall,replay_imbalance,ratio,query_share,render_cpu_s,replay_cpu_s,\
         ratio_cpu",
    );
    for k in Kind::ALL {
        let n = k.name();
        let _ = write!(
            h,
            ",{n}_queries,{n}_hits,{n}_s,{n}_mrays_per_s,{n}_share_of_render,{n}_cpu_s"
        );
    }
    h
}

/// A CPU figure with 2 decimals, or nothing.
pub(super) fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |c| format!("{c:.2}"))
}

fn opt6(v: Option<f64>) -> String {
    v.map_or(String::new(), |c| format!("{c:.6}"))
}

fn csv_line(r: &MixRow, scene_name: &str, scene: &Scene, spp: u32) -> String {
    let mut l = format!(
        "{scene_name},{},{},{spp},{},{},{},{},{},{:.6},{:.4},{},{:.6},{:.6},{:.4},{},{:.3},{:.4},{:.4}",
        scene.camera.width,
        scene.camera.height,
        scene.triangle_count(),
        r.backend,
        r.threads,
        r.render_rays,
        r.records,
        r.render_seconds,
        r.render_mrays(),
        opt(r.render_cpu_per_wall),
        r.record_seconds,
        r.replay_seconds,
        r.raw_mrays(),
        opt(r.replay_cpu_per_wall),
        r.replay_imbalance,
        r.ratio(),
        r.query_share()
    );
    let _ = write!(
        l,
        ",{},{},{}",
        opt6(r.render_cpu_seconds),
        opt6(r.replay_cpu_seconds),
        r.ratio_cpu().map_or(String::new(), |x| format!("{x:.4}"))
    );
    for k in &r.kinds {
        let _ = write!(
            l,
            ",{},{},{:.6},{:.4},{:.4},{}",
            k.queries,
            k.hits,
            k.seconds,
            k.mrays(),
            k.seconds / r.render_seconds,
            opt6(k.cpu_seconds)
        );
    }
    l
}

/// The scene's name as a CSV field: its file stem, without the characters
/// that would break the row.
fn scene_name(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().replace([',', '"', '\n'], "_"))
        .unwrap_or_default()
}

/// Writes `render-mix.csv` into `out` (atomically: a failed write leaves
/// no partial file) and returns its path.
pub(super) fn write_csv(
    out: &Path,
    rows: &[MixRow],
    scene_path: &Path,
    scene: &Scene,
    spp: u32,
) -> Result<PathBuf, Error> {
    let csv = out.join("render-mix.csv");
    let name = scene_name(scene_path);
    let mut text = csv_header();
    text.push('\n');
    for r in rows {
        text.push_str(&csv_line(r, &name, scene, spp));
        text.push('\n');
    }
    lucent::film::atomic_write(&csv, |tmp| {
        std::io::Write::write_all(tmp, text.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(|e| Error::Runtime(e.to_string()))?;
    Ok(csv)
}
