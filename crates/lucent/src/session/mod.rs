//! A render as `lucent render` runs it: the scene loaded and the command
//! line's overrides applied, the settings resolved once
//! ([`crate::render::Settings`]), the frame or part rendered, checkpoints
//! kept and a stopped render resumed, and the output written, denoised
//! when asked (docs/farm.md, docs/output.md).

pub mod checkpoint;
mod checkpoint_owner;
mod denoise;
pub mod identity;
mod info;
mod merge;
pub mod output;
pub mod overrides;
pub mod paste;
pub mod provenance;
pub mod request;
pub mod resume;
mod run;

pub use denoise::{denoise_file, Denoised};
pub use info::build_info;
pub use merge::{merge_parts, MergedFrame};
pub use output::check_exr_output;
pub use overrides::Overrides;
pub use paste::{paste, Pasted};
pub use provenance::{build_id, embree4_warning};
pub use request::{Request, Split};
pub use run::{apply_film, run, stop_if_interrupted, Outcome};
