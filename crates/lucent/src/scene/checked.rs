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
    /// Some syntax errors come with an empty message (a key without a
    /// value); those are described here from the text at the span.
    pub(crate) fn toml_error(&self, e: &toml::de::Error) -> InputError {
        // Syntax errors carry a multi-line message; keep it on one line.
        let mut msg = shortened(&e.message().trim_end().replace('\n', "; "));
        let mut key = None;
        if msg.is_empty() {
            (msg, key) = match e.span() {
                Some(span) => syntax_cause(self.text, span.start),
                None => ("invalid TOML".into(), None),
            };
        }
        let mut err = InputError::new(self.file, msg);
        if let Some(span) = e.span() {
            err = err.at_line(line_of(self.text, span.start));
            // a key without its value is not a statement to the scanner:
            // its table's path, and the key
            let path = match (key_path_at(self.text, span.start), key) {
                (Some(p), Some(k)) if !p.ends_with(k.as_str()) => Some(format!("{p}.{k}")),
                (None, Some(k)) => Some(k),
                (p, _) => p,
            };
            if let Some(path) = path {
                err = err.in_field(path);
            }
        }
        err
    }

    /// Fails at the first control character TOML does not allow anywhere,
    /// comments included (all of U+0000–U+001F but tab and line ends, and
    /// U+007F): the `toml` crate reports one with no message, or as an
    /// "expected newline" that does not say what is wrong.
    pub(crate) fn no_control_characters(&self) -> Res<()> {
        let b = self.text.as_bytes();
        let bad = b.iter().enumerate().find(|&(i, &c)| {
            (c < 0x20 && c != b'\t' && c != b'\n' && !(c == b'\r' && b.get(i + 1) == Some(&b'\n')))
                || c == 0x7f
        });
        let Some((at, &c)) = bad else {
            return Ok(());
        };
        let mut err = InputError::new(
            self.file,
            format!(
                "control character U+{c:04X} ({}) is not allowed in TOML, not even in a comment \
                 (only tab; in a string, write an escape such as \\u{c:04X})",
                control_name(c)
            ),
        )
        .at_line(line_of(self.text, at));
        if let Some(path) = key_path_at(self.text, at) {
            err = err.in_field(path);
        }
        Err(err)
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
    pub(crate) fn vec3(&self, v: &Spanned<Triple3>, field: &str) -> Res<Vec3> {
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
    pub(crate) fn rgb(&self, v: &Spanned<Triple3>, field: &str, unit: bool) -> Res<Vec3> {
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
    pub(crate) fn only_keys(
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

/// The name of an ASCII control character, for messages.
fn control_name(c: u8) -> &'static str {
    match c {
        0x00 => "NUL",
        0x08 => "backspace",
        0x0b => "vertical tab",
        0x0c => "form feed",
        0x0d => "carriage return without a line feed",
        0x1b => "escape",
        0x7f => "delete",
        _ => "a control character",
    }
}

/// What is wrong at byte `at` of a TOML text whose parse error came without
/// a message: a key with no value (at the end of the file or of its line),
/// or something else, quoted; and the key without a value.
fn syntax_cause(text: &str, at: usize) -> (String, Option<String>) {
    let at = at.min(text.len());
    let at = (0..=at)
        .rev()
        .find(|&i| text.is_char_boundary(i))
        .unwrap_or(0);
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let before = text[line_start..at].trim_end();
    let rest = &text[at..];
    let line_rest = rest.split('\n').next().unwrap_or("").trim();
    let at_eof = rest.trim().is_empty();
    if before.ends_with('=') && (line_rest.is_empty() || line_rest.starts_with('#')) {
        let key = before.trim_end_matches('=').trim();
        let msg = if at_eof {
            format!("the file ends in the middle of an assignment: `{key} =` has no value")
        } else {
            format!("`{key} =` has no value on its line")
        };
        (msg, Some(key.to_string()))
    } else if at_eof {
        ("the file ends in the middle of a statement".into(), None)
    } else {
        let found: String = line_rest.chars().take(20).collect();
        (
            format!("invalid TOML at `{}`", found.escape_default()),
            None,
        )
    }
}

/// The longest message a TOML error keeps (in characters): a value it
/// quotes (a 10 MB string of the wrong type) is cut, the message says so.
const MAX_MESSAGE_CHARS: usize = 300;

/// `msg`, cut to [`MAX_MESSAGE_CHARS`] with the length of what was cut.
fn shortened(msg: &str) -> String {
    match msg.char_indices().nth(MAX_MESSAGE_CHARS) {
        None => msg.to_string(),
        Some((at, _)) => format!(
            "{}… ({} more characters not shown)",
            &msg[..at],
            msg[at..].chars().count()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> InputError {
        let cx = Cx {
            file: Path::new("s.toml"),
            text,
        };
        match cx.no_control_characters() {
            Err(e) => e,
            Ok(()) => cx.toml_error(&toml::from_str::<toml::Table>(text).unwrap_err()),
        }
    }

    #[test]
    fn control_characters_are_named_at_their_line() {
        for (text, line, name) in [
            (
                "# a comment\n# with a \x0c form feed\na = 1\n",
                2,
                "U+000C (form feed)",
            ),
            ("a = 1 # \0\n", 1, "U+0000 (NUL)"),
            ("a = 1\rb = 2\n", 1, "carriage return"),
            ("[t]\nk = \"x\x7f\"\n", 2, "U+007F (delete)"),
        ] {
            let e = err(text);
            assert_eq!(e.line, Some(line), "{text:?}: {e}");
            assert!(e.message.contains(name), "{text:?}: {e}");
        }
        assert_eq!(err("[t]\nk = \"x\x7f\"\n").field.as_deref(), Some("t.k"));
        // tab and CRLF line ends are TOML
        let cx = Cx {
            file: Path::new("s.toml"),
            text: "a\t= 1\r\nb = 2\r\n",
        };
        assert!(cx.no_control_characters().is_ok());
    }

    #[test]
    fn a_key_without_a_value_says_so() {
        let e = err("[camera]\nlook_from =");
        assert_eq!(e.line, Some(2));
        assert_eq!(e.field.as_deref(), Some("camera.look_from"));
        assert_eq!(
            e.message,
            "the file ends in the middle of an assignment: `look_from =` has no value"
        );
        let e = err("a = 1\nb = ");
        assert_eq!((e.line, e.field.as_deref()), (Some(2), Some("b")));
        // toml's own messages are kept where it gives one
        assert_eq!(err("a = [1,").message, "invalid array; expected `]`");
    }
}
