//! `lucent bench`: the ray-query backends side by side, on the same meshes
//! and the same rays in one run.
//!
//! For every mesh (a displaced sphere per requested size, the Stanford bunny
//! and a random triangle soup) and every available backend it measures
//!
//! - the build: wall time (inside a rayon pool of the largest thread count;
//!   Embree builds on its own threads, sized from that pool) and memory, as
//!   the growth of the resident set (`/proc/self/statm`) from just before
//!   to just after the build, with freed heap returned to the kernel first
//!   (neither backend reports its structure size, so this is an estimate
//!   that includes allocator slack and, for our BVH, the whole of any huge
//!   page it touches);
//! - the throughput of four queries ([`rays`]): camera rays (coherent),
//!   incoherent rays, shadow segments and BSSRDF probe segments, with each
//!   requested thread count (one rayon pool per count, the ray set split
//!   into chunks of [`measure::CHUNK`]), as the fastest of several passes.
//!
//! Both backends must find the same number of hits on the same rays; a
//! difference beyond rays that graze an edge is an error. Results go to
//! `DIR/bench.csv`, a table on stdout (also `DIR/report.txt`) and log-log
//! plots `DIR/bench-<query>.png` of time per ray against triangle count.
//!
//! With a scene ([`replay`], `lucent bench --scene`) it measures instead the
//! renderer's end-to-end ray rate against the backend's raw rate on the
//! very queries that render issued (recorded, then replayed).

//!
//! The files: `settings` (what it is told), `meshes` (what it measures),
//! [`rays`] (the ray sets), [`measure`] (timing and memory), `run` (the
//! loop over meshes, backends and thread counts), `hits` (do the backends
//! agree), `csv`, `report` and [`plot`] (the output).

mod csv;
mod hits;
pub mod measure;
mod meshes;
mod out_dir;
pub mod plot;
pub mod rays;
pub mod replay;
mod report;
mod run;
mod settings;

pub use csv::{Row, CSV_HEADER};
pub use hits::hit_tolerance;
pub use measure::QueryKind;
pub use meshes::{sphere_level, BenchMesh};
pub use report::{fit_line, report, short_count};
pub use run::{run, Outcome, RMAX_FRACTION};
pub use settings::{
    available_backends, default_bunny, default_threads, parse_rays, parse_size, parse_threads,
    Settings, FULL_SIZES, QUICK_SIZES,
};
