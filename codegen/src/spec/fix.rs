//! `codegen fix-home`: the corrections that the spec reader makes at home (loops closed by
//! moving a joint's frame on the platform or child side, a parallelogram's length taken from
//! the home geometry), written back into the spec text. Each is a warning's [`Fix`]: set a key
//! of the table that holds the warning's span.

use std::ops::Range;

use crate::diag::{Diagnostics, Fix};

/// The spec text with every fix of `warnings` applied, and how many were applied. Fixes are
/// applied from the end of the text backwards, so that each span still points where it did.
pub fn apply_fixes(source: &str, warnings: &Diagnostics) -> (String, usize) {
    let mut fixes: Vec<(Range<usize>, &Fix)> = warnings
        .iter()
        .filter_map(|d| Some((d.span.clone()?, d.fix.as_ref()?)))
        .collect();
    fixes.sort_by_key(|(span, _)| std::cmp::Reverse(span.start));
    let mut text = source.to_string();
    let mut applied = 0;
    for (span, fix) in fixes {
        if let Some(t) = apply(&text, span.start, fix) {
            text = t;
            applied += 1;
        }
    }
    (text, applied)
}

/// `fix` applied at byte `at`: the value of `key = …` on `at`'s line replaced, or a line
/// `key = value` added after it.
fn apply(text: &str, at: usize, fix: &Fix) -> Option<String> {
    let line_start = text.get(..at)?.rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[at..].find('\n').map_or(text.len(), |i| at + i);
    let line = &text[line_start..line_end];
    let indent = &line[..line.len() - line.trim_start().len()];
    let after_key = line
        .trim_start()
        .strip_prefix(fix.key.as_str())
        .map(str::trim_start)
        .and_then(|r| r.strip_prefix('='));
    match after_key {
        Some(rest) => {
            let value_start = line_end - rest.len() + (rest.len() - rest.trim_start().len());
            let value_end = value_end(text, value_start)?;
            Some(format!(
                "{}{}{}",
                &text[..value_start],
                fix.value,
                &text[value_end..]
            ))
        }
        None => Some(format!(
            "{}\n{indent}{} = {}{}",
            &text[..line_end],
            fix.key,
            fix.value,
            &text[line_end..]
        )),
    }
}

/// The end of the TOML value starting at `start`: an inline table or array to its matching
/// bracket (strings skipped), anything else to the end of the line or a comment.
fn value_end(text: &str, start: usize) -> Option<usize> {
    let bytes = text.as_bytes();
    match bytes.get(start)? {
        b'{' | b'[' => {
            let mut depth = 0usize;
            let mut in_string: Option<u8> = None;
            let mut i = start;
            while i < bytes.len() {
                let b = bytes[i];
                match in_string {
                    Some(q) if b == b'\\' && q == b'"' => i += 1,
                    Some(q) if b == q => in_string = None,
                    Some(_) => {}
                    None => match b {
                        b'"' | b'\'' => in_string = Some(b),
                        b'{' | b'[' => depth += 1,
                        b'}' | b']' => {
                            depth -= 1;
                            if depth == 0 {
                                return Some(i + 1);
                            }
                        }
                        _ => {}
                    },
                }
                i += 1;
            }
            None
        }
        _ => {
            let end = text[start..].find('\n').map_or(text.len(), |i| start + i);
            let value = &text[start..end];
            let value = value.find('#').map_or(value, |c| &value[..c]);
            Some(start + value.trim_end().len())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fix(key: &str, value: &str) -> Fix {
        Fix {
            key: key.into(),
            value: value.into(),
        }
    }

    #[test]
    fn replaces_a_value_or_adds_a_line() {
        let text = "[[joint]]\nname = \"tip\"\nchild_origin = { xyz = [0.5, 0.0, 0.0], rpy = [0.0, \"9}0deg\", 0.0] }  # pin\naxis = [0.0, 0.0, 1.0]\n";
        let at = text.find("child_origin").unwrap();
        let out = apply(text, at, &fix("child_origin", "{ xyz = [0.5, 1e-6, 0.0] }")).unwrap();
        assert_eq!(
            out,
            "[[joint]]\nname = \"tip\"\nchild_origin = { xyz = [0.5, 1e-6, 0.0] }  # pin\naxis = [0.0, 0.0, 1.0]\n"
        );
        let at = text.find("\"tip\"").unwrap();
        let no_origin = text.replace(
            "child_origin = { xyz = [0.5, 0.0, 0.0], rpy = [0.0, \"9}0deg\", 0.0] }  # pin\n",
            "",
        );
        let out = apply(
            &no_origin,
            at,
            &fix("child_origin", "{ xyz = [1.0, 0.0, 0.0] }"),
        )
        .unwrap();
        assert_eq!(
            out,
            "[[joint]]\nname = \"tip\"\nchild_origin = { xyz = [1.0, 0.0, 0.0] }\naxis = [0.0, 0.0, 1.0]\n"
        );
        let text = "length = 1.055 # m\n";
        let out = apply(text, 9, &fix("length", "1.05499")).unwrap();
        assert_eq!(out, "length = 1.05499 # m\n");
    }
}
