//! The storage keys of the scene's `[output]` table: how the frame is stored (docs/output.md,
//! docs/scene-format.md). Every key is optional and the CLI's options
//! override it; what a key leaves unset is the writer's default
//! ([`crate::film::exr_layers::OutputOptions`]).

use super::checked::{Cx, Res};
use super::format::OutputDef;
use crate::film::cryptomatte::MAX_RANKS;
use crate::film::exr_layers::{ExrCompression, OutputOptions, Precision};

/// `[output]`, checked; `None`: not set in the scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OutputSettings {
    pub precision: Option<Precision>,
    pub compression: Option<ExrCompression>,
    pub split: Option<bool>,
    pub cryptomatte_ranks: Option<usize>,
    /// A transparent film (docs/output.md, "Transparent film").
    pub transparent: Option<bool>,
}

impl OutputSettings {
    /// The writer's options: these settings over `base`.
    pub fn over(&self, base: OutputOptions) -> OutputOptions {
        OutputOptions {
            precision: self.precision.unwrap_or(base.precision),
            compression: self.compression.unwrap_or(base.compression),
            split: self.split.unwrap_or(base.split),
            cryptomatte_ranks: self.cryptomatte_ranks.unwrap_or(base.cryptomatte_ranks),
            preview: base.preview,
            transparent: self.transparent.unwrap_or(base.transparent),
        }
    }
}

/// Checks `[output]`: names the scene format knows, ranks in range.
pub(super) fn output_file(cx: &Cx, d: &OutputDef) -> Res<OutputSettings> {
    let precision = match &d.aov_precision {
        Some(p) => Some(Precision::parse(p.get_ref()).ok_or_else(|| {
            cx.err(
                p.span(),
                "output.aov_precision",
                format!("expected \"half\" or \"float\", found \"{}\"", p.get_ref()),
            )
        })?),
        None => None,
    };
    let compression = match &d.exr_compression {
        Some(c) => Some(ExrCompression::parse(c.get_ref()).ok_or_else(|| {
            cx.err(
                c.span(),
                "output.exr_compression",
                format!(
                    "expected {} (lossless only), found \"{}\"",
                    ExrCompression::NAMES,
                    c.get_ref()
                ),
            )
        })?),
        None => None,
    };
    let cryptomatte_ranks = match &d.cryptomatte_ranks {
        Some(r) => {
            let n = *r.get_ref() as usize;
            if !(1..=MAX_RANKS).contains(&n) {
                return Err(cx.err(
                    r.span(),
                    "output.cryptomatte_ranks",
                    format!("expected 1 to {MAX_RANKS} ranks, found {n}"),
                ));
            }
            Some(n)
        }
        None => None,
    };
    Ok(OutputSettings {
        precision,
        compression,
        split: d.aov_split,
        cryptomatte_ranks,
        transparent: d.transparent,
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    fn load(output: &str) -> Result<OutputSettings, crate::error::InputError> {
        let text = format!(
            "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\n\n\
             [output]\n{output}\n"
        );
        crate::scene::load_str(&text, Path::new("s.toml")).map(|s| s.output.file)
    }

    #[test]
    fn keys_are_read_and_bad_values_named_by_line_and_field() {
        let s = load(
            "aov_precision = \"half\"\nexr_compression = \"piz\"\naov_split = true\n\
             cryptomatte_ranks = 4\ntransparent = true",
        )
        .unwrap();
        assert_eq!(
            s,
            OutputSettings {
                precision: Some(Precision::Half),
                compression: Some(ExrCompression::Piz),
                split: Some(true),
                cryptomatte_ranks: Some(4),
                transparent: Some(true),
            }
        );
        let o = s.over(OutputOptions::default());
        assert_eq!(
            (o.precision, o.split, o.cryptomatte_ranks, o.transparent),
            (Precision::Half, true, 4, true)
        );
        assert_eq!(load("").unwrap(), OutputSettings::default());
        for (text, field, line) in [
            ("aov_precision = \"double\"", "output.aov_precision", 7),
            ("\nexr_compression = \"b44\"", "output.exr_compression", 8),
            ("cryptomatte_ranks = 0", "output.cryptomatte_ranks", 7),
            ("cryptomatte_ranks = 65", "output.cryptomatte_ranks", 7),
        ] {
            let e = load(text).unwrap_err();
            assert_eq!(e.field.as_deref(), Some(field), "{e}");
            assert_eq!(e.line, Some(line), "{e}");
        }
        assert!(load("aov_split = 1").is_err());
        assert!(load("bogus = 1").is_err());
    }
}
