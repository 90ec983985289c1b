//! Where in a TOML text a byte offset is: its line, and the dotted key
//! path (`materials.red.albedo`, `shapes[1].file`) of the statement there.
//!
//! Why a hand-written scanner: the `toml` crate's errors carry a byte span
//! and a message, but the key path it knows is private (it appears only
//! inside the multi-line `Display` text), and a span-keeping document parse
//! (`toml_edit`) is unavailable exactly when it is needed for syntax errors.
//! `Spanned` values give spans for the values the loader checks itself, not
//! for the ones serde rejects while deserializing. So the path of a
//! rejected value is recovered from its span's position in the text by
//! following table headers, keys, strings, comments and bracket nesting.
//! Array-of-tables entries are numbered from 0; values nested in inline
//! tables are attributed to the enclosing key.

use std::collections::HashMap;

/// The 1-based line containing byte `offset` of `text`.
pub fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The dotted key path (`materials.red.albedo`, `shapes[1].file`) of the
/// TOML statement containing byte `offset`, from a lightweight scan that
/// follows table headers, keys, strings, comments and bracket nesting.
/// Array-of-tables entries are numbered from 0. Values nested in inline
/// tables are attributed to the enclosing key.
pub(crate) fn key_path_at(text: &str, offset: usize) -> Option<String> {
    let b = text.as_bytes();
    let mut header = String::new();
    let mut aot: HashMap<String, usize> = HashMap::new();
    let mut i = 0;
    let join = |h: &str, k: &str| {
        if h.is_empty() {
            k.to_string()
        } else {
            format!("{h}.{k}")
        }
    };
    while i < b.len() {
        // Skip blank space and comments between statements.
        match b[i] {
            b' ' | b'\t' | b'\r' | b'\n' => {
                i += 1;
                continue;
            }
            b'#' => {
                i = skip_line(b, i);
                continue;
            }
            _ => {}
        }
        let start = i;
        if b[i] == b'[' {
            let double = b.get(i + 1) == Some(&b'[');
            let name_start = i + if double { 2 } else { 1 };
            let close = scan_key_until(b, name_start, b']');
            let name = normalize_key(&text[name_start..close]);
            let end = skip_line(b, close);
            if double {
                let n = aot.entry(name.clone()).or_insert(0);
                header = format!("{name}[{n}]");
                *n += 1;
            } else {
                header = name;
            }
            if (start..end).contains(&offset) {
                return Some(header);
            }
            i = end;
        } else {
            let eq = scan_key_until(b, i, b'=');
            if b.get(eq) != Some(&b'=') {
                // Not a key-value pair (a syntax error): no field to name.
                if (start..eq.max(start + 1)).contains(&offset) {
                    return None;
                }
                i = eq.max(start + 1);
                continue;
            }
            let key = normalize_key(&text[start..eq]);
            let end = skip_value(b, (eq + 1).min(b.len()));
            if (start..end.max(start + 1)).contains(&offset) {
                return Some(join(&header, &key));
            }
            i = end.max(start + 1);
        }
    }
    (!header.is_empty() && offset >= text.len()).then_some(header)
}

fn skip_line(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i] != b'\n' {
        i += 1;
    }
    i
}

/// Index of the first `stop` byte outside quotes at or after `i`, or the end
/// of the line.
fn scan_key_until(b: &[u8], mut i: usize, stop: u8) -> usize {
    while i < b.len() && b[i] != b'\n' {
        match b[i] {
            c if c == stop => return i,
            q @ (b'"' | b'\'') => {
                i += 1;
                while i < b.len() && b[i] != q && b[i] != b'\n' {
                    i += if q == b'"' && b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            _ => i += 1,
        }
    }
    i.min(b.len())
}

/// End of the value starting at `i`: the first newline outside strings,
/// comments and brackets.
fn skip_value(b: &[u8], mut i: usize) -> usize {
    let mut depth = 0usize;
    while i < b.len() {
        match b[i] {
            b'\n' if depth == 0 => return i,
            b'[' | b'{' => depth += 1,
            b']' | b'}' => depth = depth.saturating_sub(1),
            b'#' => {
                i = skip_line(b, i);
                continue;
            }
            q @ (b'"' | b'\'') => {
                let triple = b.get(i + 1) == Some(&q) && b.get(i + 2) == Some(&q);
                if triple {
                    i += 3;
                    while i < b.len()
                        && !(b[i] == q && b.get(i + 1) == Some(&q) && b.get(i + 2) == Some(&q))
                    {
                        i += if q == b'"' && b[i] == b'\\' { 2 } else { 1 };
                    }
                    i += 3;
                } else {
                    i += 1;
                    while i < b.len() && b[i] != q && b[i] != b'\n' {
                        i += if q == b'"' && b[i] == b'\\' { 2 } else { 1 };
                    }
                    i += 1;
                }
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    b.len()
}

/// A key as one segment of a dotted path, spelt as TOML would: bare when it
/// is (`red`, `skin-1`), else quoted with escapes (`"my red"`, `"a\nb"`),
/// so that a field path never carries a raw newline, quote or control
/// character into a message.
pub(crate) fn key_segment(key: &str) -> String {
    let bare = !key.is_empty()
        && key
            .bytes()
            .all(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'-');
    if bare {
        key.to_string()
    } else {
        quoted(key)
    }
}

/// `s` as a TOML basic string: in double quotes, with `"`, `\` and
/// control characters escaped.
pub fn quoted(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `a . "b c"` → `a."b c"`; bare keys keep their spelling.
fn normalize_key(k: &str) -> String {
    let mut out = String::new();
    let mut in_q: Option<char> = None;
    for c in k.trim().chars() {
        match in_q {
            Some(q) => {
                out.push(c);
                if c == q {
                    in_q = None;
                }
            }
            None if c == '"' || c == '\'' => {
                in_q = Some(c);
                out.push(c);
            }
            None if c.is_whitespace() => {}
            None => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_paths_follow_headers_arrays_and_strings() {
        let t =
            "a = 1\n[camera]\nlook_from = [\n  0, # ] comment\n  1,\n  2]\nname = \"x = [ #\"\n\
                 [[shapes]]\ntype = 'quad'\n[[shapes]]\n  file = \"\"\"\nmulti = line\n\"\"\"\n\
                 [ materials . \"my red\" ]\nalbedo = {r = 1}\n";
        let at = |needle: &str| key_path_at(t, t.find(needle).unwrap());
        assert_eq!(at("a = 1").as_deref(), Some("a"));
        assert_eq!(at("[camera]").as_deref(), Some("camera"));
        assert_eq!(at("1,").as_deref(), Some("camera.look_from"));
        assert_eq!(at("2]").as_deref(), Some("camera.look_from"));
        assert_eq!(at("\"x =").as_deref(), Some("camera.name"));
        assert_eq!(at("'quad'").as_deref(), Some("shapes[0].type"));
        assert_eq!(at("multi").as_deref(), Some("shapes[1].file"));
        assert_eq!(at("r = 1").as_deref(), Some("materials.\"my red\".albedo"));
        assert_eq!(line_of(t, t.find("2]").unwrap()), 6);
        assert_eq!(line_of(t, 0), 1);
        assert_eq!(line_of(t, usize::MAX), t.lines().count() + 1);
    }

    #[test]
    fn keys_are_quoted_and_escaped_unless_bare() {
        assert_eq!(key_segment("red_1-b"), "red_1-b");
        assert_eq!(key_segment("my red"), "\"my red\"");
        assert_eq!(key_segment(""), "\"\"");
        assert_eq!(
            key_segment("a\n\"b\\\u{c}\u{3b7}"),
            "\"a\\n\\\"b\\\\\\u000C\u{3b7}\""
        );
    }
}
