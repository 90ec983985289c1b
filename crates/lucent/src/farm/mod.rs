//! One frame on many machines: parts that split it by pixels and sample
//! indices, a merge that puts them back bitwise, and what an interrupted
//! render leaves to resume from (docs/farm.md).
//!
//! The exactness comes from the renderer itself: every render sums its
//! samples in [`crate::film::accumulate`]'s fixed point, whose integer sums
//! do not depend on order or grouping, so a region's sums over a range of
//! sample indices ([`crate::render::render_job`]) are a part of the frame's
//! sums, and adding parts ([`merge`]) gives exactly the sums of one run.
//!
//! - [`part`]: the part file (an EXR of the integer sums), with its
//!   [`header`] saying which frame, region and samples it holds;
//! - `part_file` and `part_values`: a part read as untrusted input,
//!   its structure and its values checked;
//! - [`cover`]: whether parts cover the frame exactly once;
//! - [`merge`]: the checks and the sum;
//! - [`mod@scene_hash`]: which scene a part is of.

pub mod cover;
pub mod header;
pub mod merge;
pub mod part;
mod part_file;
mod part_values;
mod part_words;
pub mod scene_hash;

pub use scene_hash::scene_hash;
