//! A frame merged from its parts (`lucent merge`, docs/farm.md) and
//! written as one EXR with its preview, denoised when asked.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::denoise::stage_denoised;
use super::output::{check_exr_output, check_not_an_input};
use crate::denoise::DenoiseOptions;
use crate::error::Error;
use crate::farm::merge::merge;
use crate::film::commit_all;
use crate::film::exr_attributes::FrameHeader;
use crate::film::exr_layers::{self, OutputOptions, Preview, Window};

/// What a merge made: the frame's size and samples, and how long it took.
#[derive(Clone, Debug)]
pub struct MergedFrame {
    pub parts: usize,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seconds: f64,
    /// Non-finite samples the parts discarded.
    pub nonfinite: u64,
}

/// Merges `parts` into the frame `output` (EXR, with the preview
/// `preview`); `mixed_backends` lets parts rendered on different
/// ray-query backends merge (the frame names each); `denoise` adds the
/// denoised beauty, run so.
pub fn merge_parts(
    parts: &[PathBuf],
    output: &Path,
    preview: Preview,
    mixed_backends: bool,
    denoise: Option<&DenoiseOptions>,
) -> Result<MergedFrame, Error> {
    check_exr_output(output)?;
    if denoise.is_some() {
        crate::denoise::load::api()?;
    }
    let preview_path = crate::film::preview_path(output);
    check_not_an_input(&[output, &preview_path], parts)?;
    let start = Instant::now();
    let m = merge(parts, mixed_backends)?;
    // what the parts say of the render, as a single render's frame says it
    let header = FrameHeader {
        spp: Some(m.identity.spp),
        seed: Some(m.identity.seed),
        date: Some(super::provenance::date_now()),
        ..m.frame.clone()
    };
    let out = OutputOptions {
        preview: Some(preview),
        ..m.output
    };
    crate::memory::enter(crate::memory::Phase::Writing);
    match denoise {
        None => exr_layers::write_frame(output, &m.film, &m.layers, &m.coverage, &header, &out)?,
        Some(d) => {
            let window = Window::full(m.film.width, m.film.height);
            let (f, l, c) = (&m.film, &m.layers, &m.coverage);
            commit_all(stage_denoised(output, window, f, l, c, &header, &out, d)?)?
        }
    }
    Ok(MergedFrame {
        parts: parts.len(),
        width: m.film.width,
        height: m.film.height,
        spp: m.identity.spp,
        seconds: start.elapsed().as_secs_f64(),
        nonfinite: m.counters.nonfinite,
    })
}

impl MergedFrame {
    /// One line: where the frame went, from how many parts, its size,
    /// samples and time.
    pub fn summary(&self, output: &Path) -> String {
        format!(
            "{}: {} parts merged, {}×{} at {} spp, {:.2} s{}",
            output.display(),
            self.parts,
            self.width,
            self.height,
            self.spp,
            self.seconds,
            if self.nonfinite > 0 {
                format!(", {} non-finite samples discarded", self.nonfinite)
            } else {
                String::new()
            }
        )
    }
}
