//! `lucent bench`: the ray-query backends side by side, on the same meshes
//! and the same rays in one run (`docs/performance.md`, "What is measured").
//!
//! For every mesh (a displaced sphere per requested size, the Stanford bunny
//! and a random triangle soup) and every available backend it measures the
//! build (wall time, and memory as the growth of the resident set) and the
//! throughput of four queries ([`rays`]: camera, incoherent, shadow, probe)
//! at each requested thread count, as the fastest of several passes
//! ([`measure`]). Both backends must find the same number of hits. With a
//! scene ([`replay`], `lucent bench --scene`) it measures instead the
//! renderer's end-to-end ray rate against the backend's raw rate on the
//! very queries that render issued. The files: `settings`, `meshes`,
//! [`rays`], [`measure`], `run`, `hits`, `csv`, `report` and [`plot`].

pub mod cli;
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
