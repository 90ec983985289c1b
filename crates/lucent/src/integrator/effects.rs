//! Where a render's ray queries and time go, per effect, for the
//! end-of-render summary of `lucent render --stats` (`docs/performance.md`,
//! "Per-effect statistics").
//!
//! **Ray queries** are counted always: every query site adds one to the
//! total ([`super::Counters::rays`]) and one to its effect's count
//! ([`Counters::ray`](super::Counters::ray)), a per-thread add with no
//! sharing. So the per-effect counts sum to the total by construction, and
//! a test checks it over real renders.
//!
//! **Time** is measured only when asked for, without slowing the renders
//! that do not ask: the tile loop and the integrators are generic over a
//! [`Clock`], and a render picks the instance once ([`Stopwatch`] with
//! `--stats`, [`NoClock`] without), as the passes pick their recorder
//! (`super::aov`). Under [`NoClock`] every reading is the constant 0 and
//! every `if C::ON` is removed at compile time, so the instance without
//! statistics runs no clock code at all. Under
//! [`Stopwatch`] the clock is read around each effect's section: the
//! nearest-hit query of a camera ray or of a continued path, the light
//! sample with its shadow ray, and a subsurface hit (the coat and the
//! probe rays, or the random walk), and around each whole sample. The
//! shares are ratios of these readings; what no section covers (shading,
//! sampling, emission, the film) is "shading and other".
//!
//! The clock is the time-stamp counter on x86_64 (`rdtsc`: constant-rate
//! on every x86_64 CPU of the last fifteen years, about 20 cycles a read,
//! not serializing, so a section's reading may be off by a few tens of
//! cycles, far below a ray query's thousands) and the monotonic clock
//! elsewhere (`Instant`, nanoseconds). Shares are ratios of one clock's
//! ticks, so its rate never needs to be known.

pub use crate::stats::{Effect, EFFECTS};

use crate::stats::Counters;

/// A clock the tile loop and the integrators read around effect sections
/// (module docs).
pub trait Clock {
    /// Whether readings are taken; false compiles every reading out.
    const ON: bool;
    /// Now, in this clock's ticks.
    fn now() -> u64;

    /// Adds the ticks since `t0` to `effect`'s time.
    #[inline(always)]
    fn lap(counters: &mut Counters, effect: Effect, t0: u64) {
        if Self::ON {
            counters.effect_ticks[effect as usize] += Self::now().wrapping_sub(t0);
        }
    }

    /// Adds the ticks since `t0` to the time of whole samples.
    #[inline(always)]
    fn lap_sample(counters: &mut Counters, t0: u64) {
        if Self::ON {
            counters.sample_ticks += Self::now().wrapping_sub(t0);
        }
    }
}

/// No time measured: every reading is 0 and compiled out.
pub struct NoClock;

impl Clock for NoClock {
    const ON: bool = false;
    #[inline(always)]
    fn now() -> u64 {
        0
    }
}

/// Time measured (`--stats`): the time-stamp counter, or `Instant`.
pub struct Stopwatch;

impl Clock for Stopwatch {
    const ON: bool = true;
    #[inline(always)]
    fn now() -> u64 {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: rdtsc has no preconditions on x86_64.
            #[allow(unused_unsafe)]
            unsafe {
                core::arch::x86_64::_rdtsc()
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            use std::sync::OnceLock;
            use std::time::Instant;
            static BASE: OnceLock<Instant> = OnceLock::new();
            BASE.get_or_init(Instant::now).elapsed().as_nanos() as u64
        }
    }
}

/// The per-effect lines of the end-of-render summary: each effect that
/// made a query or took time, its ray queries and share of them, and (when
/// time was measured) its share of the sample time; then the rest.
pub fn summary(c: &Counters) -> String {
    let timed = c.sample_ticks > 0;
    let mut out = String::from("per effect:\n");
    let pct = |a: u64, b: u64| {
        if b == 0 {
            0.0
        } else {
            100.0 * a as f64 / b as f64
        }
    };
    let width = Effect::ALL
        .iter()
        .map(|e| e.name().len())
        .max()
        .unwrap_or(0);
    for e in Effect::ALL {
        let (n, t) = (c.effect_rays[e as usize], c.effect_ticks[e as usize]);
        if n == 0 && t == 0 {
            continue;
        }
        out.push_str(&format!(
            "  {:<width$}  {n:>12} rays ({:5.1} %)",
            e.name(),
            pct(n, c.rays)
        ));
        if timed {
            out.push_str(&format!(", {:5.1} % of time", pct(t, c.sample_ticks)));
        }
        out.push('\n');
    }
    if c.culled > 0 {
        out.push_str(&format!(
            "  {:<width$}  {:>12} rays ({:5.1} %) of those, proven to meet nothing, no query made\n",
            "answered by bounds",
            c.culled,
            pct(c.culled, c.rays)
        ));
    }
    if timed {
        let sections: u64 = c.effect_ticks.iter().sum();
        out.push_str(&format!(
            "  {:<width$}  {:>12}              {:5.1} % of time\n",
            "shading and other",
            "",
            pct(c.sample_ticks.saturating_sub(sections), c.sample_ticks)
        ));
    }
    out
}
