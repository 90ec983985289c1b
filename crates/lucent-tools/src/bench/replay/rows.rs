//! One measurement of `lucent bench --scene` per (backend, threads) and
//! the figures derived from it.
//!
//! With R render rays in render wall time T and Q recorded queries
//! replayed in wall time t (Q = R unless the renderer counted a probe it
//! did not trace), the end-to-end rate is R/T, the raw rate Q/t, and their
//! ratio (R/T)/(Q/t) = t/T when Q = R: the share of the render's wall time
//! spent inside ray queries. The rest, (T − t)/R per ray, is shading,
//! sampling and bookkeeping.

use super::record::Kind;

/// The target ratio of end-to-end over raw (docs/performance.md, "Where
/// the renderer's time goes").
pub const TARGET_RATIO: f64 = 0.7;

/// Per-kind replay of one (backend, threads).
#[derive(Clone, Debug, PartialEq)]
pub struct KindRow {
    pub kind: Kind,
    pub queries: u64,
    pub hits: u64,
    /// Fastest replay of this kind's records only (0 when there are none).
    pub seconds: f64,
    /// Smallest process CPU time of those replays.
    pub cpu_seconds: Option<f64>,
}

impl KindRow {
    pub fn mrays(&self) -> f64 {
        if self.seconds > 0.0 {
            self.queries as f64 / self.seconds / 1e6
        } else {
            0.0
        }
    }
}

/// One (backend, threads) measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct MixRow {
    pub backend: String,
    pub threads: usize,
    /// The render's own ray counter (`RenderStats::counters.rays`).
    pub render_rays: u64,
    /// Queries the recorder saw.
    pub records: u64,
    /// Fastest timed render, wall seconds of its tile loop.
    pub render_seconds: f64,
    /// Smallest process CPU time of a timed render.
    pub render_cpu_seconds: Option<f64>,
    /// CPU time over wall time of all timed renders.
    pub render_cpu_per_wall: Option<f64>,
    /// The recording render's wall time (slower: it logs every query).
    pub record_seconds: f64,
    /// Fastest replay of all the records.
    pub replay_seconds: f64,
    /// Smallest process CPU time of a replay of all the records.
    pub replay_cpu_seconds: Option<f64>,
    /// CPU time over wall time of all those replays.
    pub replay_cpu_per_wall: Option<f64>,
    /// Busiest worker's replay time over the mean worker's.
    pub replay_imbalance: f64,
    /// In [`Kind::ALL`] order.
    pub kinds: Vec<KindRow>,
}

impl MixRow {
    /// End-to-end rate: the render's rays over its wall time, Mrays/s.
    pub(crate) fn render_mrays(&self) -> f64 {
        self.render_rays as f64 / self.render_seconds / 1e6
    }
    /// Raw rate: the recorded queries over the replay's wall time.
    pub(crate) fn raw_mrays(&self) -> f64 {
        self.records as f64 / self.replay_seconds / 1e6
    }
    /// End-to-end over raw.
    pub fn ratio(&self) -> f64 {
        self.render_mrays() / self.raw_mrays()
    }
    /// Share of the render's wall time spent in queries: replay / render.
    pub fn query_share(&self) -> f64 {
        self.replay_seconds / self.render_seconds
    }
    /// The ratio from CPU times instead of wall times: what the ratio
    /// would be if the machine ran us undisturbed (time we spent waiting
    /// for a core does not count; cache pollution by others still does).
    /// At more than one thread it also counts idle workers' spinning.
    pub fn ratio_cpu(&self) -> Option<f64> {
        let (rc, qc) = (self.render_cpu_seconds?, self.replay_cpu_seconds?);
        Some(self.render_rays as f64 / rc / (self.records as f64 / qc))
    }
    /// Wall time per ray outside the queries, ns (render − replay, per ray).
    pub(crate) fn other_ns_per_ray(&self) -> f64 {
        (self.render_seconds - self.replay_seconds) / self.render_rays as f64 * 1e9
    }
    /// Query wall time per ray, ns.
    pub(crate) fn query_ns_per_ray(&self) -> f64 {
        self.replay_seconds / self.records as f64 * 1e9
    }
    /// The time per ray outside queries at which the ratio would be 0.7 at
    /// today's query cost: q · 0.3 / 0.7.
    pub(crate) fn other_ns_for_target(&self, target: f64) -> f64 {
        self.query_ns_per_ray() * (1.0 - target) / target
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_figures_are_consistent() {
        let r = MixRow {
            backend: "bvh".into(),
            threads: 1,
            render_rays: 1_000_000,
            records: 1_000_000,
            render_seconds: 2.0,
            render_cpu_seconds: Some(2.0),
            render_cpu_per_wall: None,
            record_seconds: 3.0,
            replay_seconds: 1.0,
            replay_cpu_seconds: Some(0.5),
            replay_cpu_per_wall: None,
            replay_imbalance: 1.0,
            kinds: vec![],
        };
        assert!((r.render_mrays() - 0.5).abs() < 1e-12);
        assert!((r.raw_mrays() - 1.0).abs() < 1e-12);
        assert!((r.ratio() - 0.5).abs() < 1e-12);
        assert!((r.query_share() - 0.5).abs() < 1e-12);
        assert!((r.ratio_cpu().unwrap() - 0.25).abs() < 1e-12);
        assert!((r.other_ns_per_ray() - 1000.0).abs() < 1e-6);
        // Ratio 0.7 at 1000 ns of queries per ray: 428.6 ns of the rest.
        assert!((r.other_ns_for_target(0.7) - 1000.0 * 0.3 / 0.7).abs() < 1e-6);
    }
}
