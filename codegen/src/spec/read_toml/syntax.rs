//! TOML syntax errors: the parser's own messages, one per line, at their spans (or, for the
//! parser's recursion limit on dotted keys, which comes without a span, at the deepest key).

use std::ops::Range;

use crate::diag::{Diagnostic, Diagnostics};

/// Reports the parser's `errors`: the first syntax error of each line; later ones on a line
/// are mostly echoes.
pub(super) fn report(source: &str, errors: Vec<toml::de::Error>, diags: &mut Diagnostics) {
    let mut lines_seen = Vec::new();
    for e in errors {
        let line = e
            .span()
            .map(|s| source[..s.start.min(source.len())].matches('\n').count());
        if line.is_some() && lines_seen.contains(&line) {
            continue;
        }
        lines_seen.push(line);
        // The reader's recursion limit on dotted keys comes without a span: find the key.
        let (span, hint) = match e.span() {
            Some(s) => (s, "see https://toml.io for the syntax"),
            None if !e.message().contains("recursion") => {
                (0..0, "see https://toml.io for the syntax")
            }
            None => (
                deepest_dotted_key(source).unwrap_or(0..0),
                "a key has at most 80 dotted parts; nocdyn's keys have at most four, e.g. scene.payload.inertia.ixx",
            ),
        };
        diags.push(
            Diagnostic::error(format!("TOML syntax error: {}", e.message().trim_end()))
                .with_span(span)
                .with_hint(hint),
        );
    }
}

/// The span of the dotted key (`a.b.c`, in a header or before `=`) with the most parts, when it
/// has more than one: where the TOML reader's recursion limit on keys struck (the first key
/// over it, more than 80 parts). Strings are skipped whole, so only dotted runs of bare or
/// quoted parts count.
fn deepest_dotted_key(source: &str) -> Option<Range<usize>> {
    const LIMIT: usize = 80;
    let b = source.as_bytes();
    let bare = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'-';
    // The end of the key part starting at `i`: a bare word or a quoted string.
    let part = |i: usize| -> Option<usize> {
        match *b.get(i)? {
            q @ (b'"' | b'\'') => {
                let mut j = i + 1;
                while j < b.len() && b[j] != q && b[j] != b'\n' {
                    j += if q == b'"' && b[j] == b'\\' { 2 } else { 1 };
                }
                (j < b.len() && b[j] == q).then_some(j + 1)
            }
            c if bare(c) => Some(i + b[i..].iter().take_while(|&&c| bare(c)).count()),
            _ => None,
        }
    };
    let blank = |mut j: usize| {
        while j < b.len() && matches!(b[j], b' ' | b'\t') {
            j += 1;
        }
        j
    };
    let mut best: Option<(usize, Range<usize>)> = None;
    let mut i = 0;
    while i < b.len() {
        let Some(mut end) = part(i) else {
            i += 1;
            continue;
        };
        let mut parts = 1;
        loop {
            let dot = blank(end);
            if b.get(dot) != Some(&b'.') {
                break;
            }
            match part(blank(dot + 1)) {
                Some(e) => {
                    end = e;
                    parts += 1;
                }
                None => break,
            }
        }
        if parts > 1 && best.as_ref().is_none_or(|(n, _)| parts > *n && *n <= LIMIT) {
            best = Some((parts, i..end));
        }
        i = end.max(i + 1);
    }
    best.map(|(_, span)| span)
}
