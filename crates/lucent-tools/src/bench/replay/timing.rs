//! Repeated timings of one thing, reduced to what the report uses.
//!
//! On a machine shared with other work, the fastest of several runs is the
//! one least disturbed, so wall time and CPU time are each the minimum
//! over runs; CPU time over wall time is summed over all runs instead (it
//! describes the load the runs saw, not a best case).

/// Repeated timings of one thing: the fastest wall time (the run least
/// disturbed by other work), the smallest CPU time, and CPU time over wall
/// time summed over all runs.
#[derive(Clone, Copy, Debug)]
pub(super) struct Best {
    pub(super) wall: f64,
    cpu: f64,
    total_wall: f64,
    total_cpu: f64,
    /// False once a run had no CPU clock.
    has_cpu: bool,
    /// [`Pass::imbalance`](super::playback::Pass::imbalance) of the fastest run.
    pub(super) imbalance: f64,
}

impl Best {
    pub(super) fn new() -> Best {
        Best {
            wall: f64::INFINITY,
            cpu: f64::INFINITY,
            total_wall: 0.0,
            total_cpu: 0.0,
            has_cpu: true,
            imbalance: 1.0,
        }
    }
    /// Adds one run: its wall time, its CPU time (None: no CPU clock)
    /// and its workers' imbalance.
    pub(super) fn add(&mut self, wall: f64, cpu: Option<f64>, imbalance: f64) {
        if wall < self.wall {
            self.wall = wall;
            self.imbalance = imbalance;
        }
        self.total_wall += wall;
        match cpu {
            Some(c) => {
                self.cpu = self.cpu.min(c.max(1e-9));
                self.total_cpu += c;
            }
            None => self.has_cpu = false,
        }
    }
    /// The smallest CPU time, if every run had a CPU clock.
    pub(super) fn cpu(&self) -> Option<f64> {
        (self.has_cpu && self.cpu.is_finite()).then_some(self.cpu)
    }
    /// CPU time over wall time, summed over all runs.
    pub(super) fn cpu_per_wall(&self) -> Option<f64> {
        self.has_cpu
            .then(|| self.total_cpu / self.total_wall.max(1e-9))
    }
}
