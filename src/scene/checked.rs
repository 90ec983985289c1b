//! The scene file being loaded ([`Cx`]) and the checked reading of its
//! values: each check takes a [`Spanned`] value and its field (a dotted key
//! path) and fails with an [`InputError`] naming the file, the value's line
//! and the field.
//!
//! Numbers are checked in f32, the precision the renderer uses: a value
//! that is finite in f64 but overflows f32 (1e300) is rejected here rather
//! than becoming an infinity later.

use std::ops::Range;
use std::path::Path;

use super::format::{Spanned, Triple3};
use super::key_path::{key_path_at, line_of};
use crate::error::InputError;
use crate::geometry::Vec3;

pub(super) type Res<T> = Result<T, InputError>;

/// The scene file being loaded: its path (for errors and relative OBJ
/// paths) and text (for lines and key paths).
pub(super) struct Cx<'a> {
    pub file: &'a Path,
    pub text: &'a str,
}

impl Cx<'_> {
    /// An error at `span` in the scene file, in `field`.
    pub fn err(&self, span: Range<usize>, field: &str, msg: impl Into<String>) -> InputError {
        InputError::new(self.file, msg)
            .at_line(line_of(self.text, span.start))
            .in_field(field)
    }

    /// Converts a `toml` syntax or type error. Its message has no key path
    /// when the error carries a span, so the path is recovered from the
    /// span's position in the text (see [`super::key_path`]).
    pub fn toml_error(&self, e: &toml::de::Error) -> InputError {
        // Syntax errors carry a multi-line message; keep it on one line.
        let msg = e.message().trim_end().replace('\n', "; ");
        let mut err = InputError::new(self.file, msg);
        if let Some(span) = e.span() {
            err = err.at_line(line_of(self.text, span.start));
            if let Some(path) = key_path_at(self.text, span.start) {
                err = err.in_field(path);
            }
        }
        err
    }

    /// The value of a key the format requires, or a "missing field" error
    /// in `field` at the line where its table starts (`table`; None for a
    /// top-level key, which has no line to point at).
    pub fn required<'v, T>(
        &self,
        v: &'v Option<T>,
        table: Option<Range<usize>>,
        field: &str,
    ) -> Res<&'v T> {
        v.as_ref().ok_or_else(|| {
            let key = field.rsplit('.').next().unwrap_or(field);
            let msg = format!("missing field `{key}`");
            match table {
                Some(span) => self.err(span, field, msg),
                None => InputError::new(self.file, msg).in_field(field),
            }
        })
    }

    /// A finite `Vec3` (finite also after narrowing to f32).
    pub fn vec3(&self, v: &Spanned<Triple3>, field: &str) -> Res<Vec3> {
        let a = v.get_ref();
        let out = Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
        if !out.is_finite() {
            return Err(self.err(
                v.span(),
                field,
                format!(
                    "expected finite numbers, found [{}, {}, {}]",
                    a[0], a[1], a[2]
                ),
            ));
        }
        Ok(out)
    }

    pub fn scalar(&self, v: &Spanned<f64>, field: &str) -> Res<f32> {
        let x = *v.get_ref() as f32;
        if !x.is_finite() {
            return Err(self.err(
                v.span(),
                field,
                format!("expected a finite number, found {}", v.get_ref()),
            ));
        }
        Ok(x)
    }

    pub fn positive(&self, v: &Spanned<f64>, field: &str) -> Res<f32> {
        let x = self.scalar(v, field)?;
        if x <= 0.0 {
            return Err(self.err(v.span(), field, format!("expected a number > 0, found {x}")));
        }
        Ok(x)
    }

    /// RGB with every component ≥ 0 (and ≤ 1 if `unit`).
    pub fn rgb(&self, v: &Spanned<Triple3>, field: &str, unit: bool) -> Res<Vec3> {
        let c = self.vec3(v, field)?;
        let ok = c.min_element() >= 0.0 && (!unit || c.max_element() <= 1.0);
        if !ok {
            let range = if unit { "in [0, 1]" } else { ">= 0" };
            return Err(self.err(
                v.span(),
                field,
                format!(
                    "expected RGB components {range}, found [{}, {}, {}]",
                    c.x, c.y, c.z
                ),
            ));
        }
        Ok(c)
    }

    /// Rejects keys (of the table `field`, present with their spans) that
    /// belong to other types than `kind`.
    pub fn only_keys(
        &self,
        field: &str,
        kind: &str,
        present: Vec<(&'static str, Range<usize>)>,
        allowed: &[&str],
    ) -> Res<()> {
        for (key, span) in present {
            if !allowed.contains(&key) {
                let allowed = if allowed.is_empty() {
                    "none".to_string()
                } else {
                    allowed.join(", ")
                };
                return Err(self.err(
                    span,
                    &format!("{field}.{key}"),
                    format!("`{key}` does not apply to type \"{kind}\" (its keys: {allowed})"),
                ));
            }
        }
        Ok(())
    }
}
