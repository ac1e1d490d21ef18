//! Diagnostics: problems found in a spec, each with a severity, a message, the key path of the
//! offending entry, its byte span in the source and an optional hint.
//!
//! [`Diagnostics`] owns the file name and the source text, so it renders itself (through
//! `codespan-reporting`, colour-free and deterministic) wherever it ends up: the CLI, a build
//! script's panic message, a `compile_error!` or a snapshot test.

use std::fmt;
use std::ops::Range;

use codespan_reporting::diagnostic as cs;
use codespan_reporting::files::{self, Files, SimpleFile};
use codespan_reporting::term;

/// The most diagnostics [`Diagnostics::render`] shows; the rest are counted in a last line.
pub const MAX_RENDERED: usize = 100;

/// Source lines longer than this (bytes) are shown cut to a window around the span.
const LONG_LINE: usize = 240;

/// How bad a [`Diagnostic`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// The spec is rejected.
    Error,
    /// The spec is accepted, but something was changed or looks suspicious.
    Warning,
}

/// One problem in a spec.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// What is wrong, one sentence, no trailing full stop.
    pub message: String,
    /// The key path of the offending entry, e.g. `joint "j3".axis` or `body[2].mass`.
    pub key: Option<String>,
    /// Byte range of the offending key or value in the source.
    pub span: Option<Range<usize>>,
    /// How to fix it, e.g. `did you mean "inertia"?`.
    pub hint: Option<String>,
    /// A change that applies the warning's correction to the spec (`codegen fix-home`).
    pub fix: Option<Fix>,
}

/// A change of the spec text that a [`Diagnostic`] proposes: set the key `key` of the table
/// that holds the diagnostic's span to `value` (TOML text). When the span is that key, its
/// value is replaced; otherwise a line `key = value` is added after the span's line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fix {
    /// The key to set, within the table of the span (e.g. `child_origin`).
    pub key: String,
    /// Its new value, as TOML text (e.g. `{ xyz = [0.5, 0.0, 0.0] }`).
    pub value: String,
}

impl Diagnostic {
    /// A new error with `message` and nothing else.
    pub fn error(message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            message: message.into(),
            key: None,
            span: None,
            hint: None,
            fix: None,
        }
    }

    /// A new warning with `message` and nothing else.
    pub fn warning(message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(message)
        }
    }

    /// Sets the key path.
    pub fn with_key(mut self, key: impl Into<String>) -> Self {
        self.key = Some(key.into());
        self
    }

    /// Sets the byte span (`None` leaves it unset).
    pub fn with_span(mut self, span: impl Into<Option<Range<usize>>>) -> Self {
        self.span = span.into();
        self
    }

    /// Sets the hint.
    pub fn with_hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }

    /// Sets the proposed change of the spec text.
    pub fn with_fix(mut self, key: impl Into<String>, value: impl Into<String>) -> Self {
        self.fix = Some(Fix {
            key: key.into(),
            value: value.into(),
        });
        self
    }

    /// `true` for [`Severity::Error`].
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// The diagnostics of one source file, together with that file's name and text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostics {
    file_name: String,
    source: String,
    list: Vec<Diagnostic>,
}

impl Diagnostics {
    /// An empty list for the file `file_name` whose text is `source`.
    pub fn new(file_name: &str, source: &str) -> Self {
        Diagnostics {
            file_name: file_name.to_owned(),
            source: source.to_owned(),
            list: Vec::new(),
        }
    }

    /// Appends `d`.
    pub fn push(&mut self, d: Diagnostic) {
        self.list.push(d);
    }

    /// Appends `d` and returns it for further changes.
    pub fn push_mut(&mut self, d: Diagnostic) -> &mut Diagnostic {
        let i = self.list.len();
        self.list.push(d);
        &mut self.list[i]
    }

    /// Appends all diagnostics of `other` (whose file should be the same).
    pub fn extend(&mut self, other: Diagnostics) {
        self.list.extend(other.list);
    }

    /// Removes and returns the diagnostics for which `pred` holds, keeping the others.
    pub fn take_if(&mut self, pred: impl Fn(&Diagnostic) -> bool) -> Vec<Diagnostic> {
        let (taken, kept) = std::mem::take(&mut self.list).into_iter().partition(pred);
        self.list = kept;
        taken
    }

    /// `true` when at least one diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.list.iter().any(Diagnostic::is_error)
    }

    /// Number of diagnostics (errors and warnings).
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// `true` when there are no diagnostics at all.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The diagnostics in order.
    pub fn iter(&self) -> impl Iterator<Item = &Diagnostic> {
        self.list.iter()
    }

    /// The file name given to [`Diagnostics::new`].
    pub fn file_name(&self) -> &str {
        &self.file_name
    }

    /// The source text given to [`Diagnostics::new`].
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of errors.
    pub fn error_count(&self) -> usize {
        self.list.iter().filter(|d| d.is_error()).count()
    }

    /// Stable sort by position in the source, diagnostics without a span last; then the same
    /// problem at the same place is kept once, its key counting the repeats.
    pub fn sort_by_position(&mut self) {
        self.list
            .sort_by_key(|d| d.span.as_ref().map_or((1, 0, 0), |s| (0, s.start, s.end)));
        self.merge_repeats();
    }

    /// The same problem at the same place reported once: a `[[pattern]]` entry's mistake
    /// found after expansion (a negative mass) came once per copy, each naming its copy, all
    /// pointing at one line. The first is kept, its key saying how many more there were.
    /// Diagnostics with a [`Fix`] are left as they are (each fixes its own entry).
    fn merge_repeats(&mut self) {
        let same = |a: &Diagnostic, b: &Diagnostic| {
            a.span.is_some()
                && a.fix.is_none()
                && b.fix.is_none()
                && (a.severity, &a.message, &a.span, &a.hint)
                    == (b.severity, &b.message, &b.span, &b.hint)
        };
        // Sorted by position, the repeats of one are among the diagnostics of its span, which
        // are next to each other (but may alternate with other problems of the same entry).
        let mut out: Vec<(Diagnostic, usize)> = Vec::with_capacity(self.list.len());
        for d in std::mem::take(&mut self.list) {
            let first = out
                .iter_mut()
                .rev()
                .take_while(|(e, _)| e.span == d.span)
                .find(|(e, _)| same(e, &d));
            match first {
                Some((_, n)) => *n += 1,
                None => out.push((d, 0)),
            }
        }
        self.list = out
            .into_iter()
            .map(|(mut d, n)| {
                if n > 0 {
                    let more = format!("and {n} more made from this text");
                    d.key = Some(match d.key.take() {
                        Some(k) => format!("{k}, {more}"),
                        None => more,
                    });
                }
                d
            })
            .collect();
    }

    /// Removes and returns the warnings, keeping the errors.
    pub fn take_warnings(&mut self) -> Diagnostics {
        let (errors, warnings) = std::mem::take(&mut self.list)
            .into_iter()
            .partition(Diagnostic::is_error);
        self.list = errors;
        Diagnostics {
            file_name: self.file_name.clone(),
            source: self.source.clone(),
            list: warnings,
        }
    }

    /// Colour-free rendering through `codespan-reporting`: for every diagnostic, its severity and
    /// message, `file:line:column`, the source line with carets under the span labelled with the
    /// key, and the hint. Deterministic (no colours, no absolute paths beyond the given name).
    ///
    /// At most [`MAX_RENDERED`] diagnostics are shown, and a long source line only around the
    /// span: the text stays proportional to the input however many errors one line has.
    pub fn render(&self) -> String {
        let file = SimpleFile::new(self.file_name.as_str(), self.source.as_str());
        let config = term::Config {
            chars: term::Chars::ascii(),
            ..term::Config::default()
        };
        let mut out = String::new();
        for d in self.list.iter().take(MAX_RENDERED) {
            let span = d.span.clone().map(|s| clamp_span(&self.source, s));
            let excerpt = span
                .as_ref()
                .and_then(|s| Excerpt::of(&self.file_name, &self.source, s));
            let mut notes = Vec::new();
            let mut labels = Vec::new();
            match (&span, &d.key) {
                (Some(s), key) => {
                    let range = excerpt.as_ref().map_or(s.clone(), |e| e.range.clone());
                    let mut label = cs::Label::primary((), range);
                    if let Some(k) = key {
                        label = label.with_message(k);
                    }
                    labels.push(label);
                }
                (None, Some(k)) => notes.push(format!("in {}: {k}", self.file_name)),
                (None, None) => notes.push(format!("in {}", self.file_name)),
            }
            if let Some(h) = &d.hint {
                notes.push(format!("hint: {h}"));
            }
            let severity = match d.severity {
                Severity::Error => cs::Severity::Error,
                Severity::Warning => cs::Severity::Warning,
            };
            let diag = cs::Diagnostic::new(severity)
                .with_message(&d.message)
                .with_labels(labels)
                .with_notes(notes.clone());
            let rendered = match &excerpt {
                Some(e) => term::emit_into_string(&config, e, &diag),
                None => term::emit_into_string(&config, &file, &diag),
            };
            match rendered {
                Ok(s) => out.push_str(&s),
                Err(_) => {
                    // Cannot happen with a clamped span; fall back to a plain line.
                    let sev = match d.severity {
                        Severity::Error => "error",
                        Severity::Warning => "warning",
                    };
                    out.push_str(&format!("{sev}: {}\n", d.message));
                    for n in &notes {
                        out.push_str(&format!("  = {n}\n"));
                    }
                    out.push('\n');
                }
            }
        }
        if let Some(rest) = self.list.get(MAX_RENDERED..) {
            let errors = rest.iter().filter(|d| d.is_error()).count();
            out.push_str(&format!(
                "... and {} more ({errors} errors, {} warnings) not shown\n",
                rest.len(),
                rest.len() - errors
            ));
        }
        out
    }
}

/// A long source line cut to a window around a span, keeping the file's line and column
/// numbers (codespan-reporting shows whole lines, once per diagnostic).
struct Excerpt<'a> {
    name: &'a str,
    /// The window, part of one line.
    text: &'a str,
    /// The span in `text`.
    range: Range<usize>,
    /// 0-based line of the window.
    line: usize,
    /// Characters of the line before the window.
    column: usize,
}

impl<'a> Excerpt<'a> {
    /// `None` when the line of `span.start` is short enough to show whole.
    fn of(name: &'a str, source: &'a str, span: &Range<usize>) -> Option<Self> {
        let start = source[..span.start].rfind('\n').map_or(0, |i| i + 1);
        let end = source[span.start..]
            .find('\n')
            .map_or(source.len(), |i| span.start + i);
        if end - start <= LONG_LINE {
            return None;
        }
        let fix = |mut i: usize| {
            while !source.is_char_boundary(i) {
                i -= 1;
            }
            i
        };
        let from = fix(span.start.saturating_sub(LONG_LINE / 4).max(start));
        let shown = fix(span
            .end
            .clamp(span.start, span.start + LONG_LINE / 2)
            .min(end));
        let to = fix((shown + LONG_LINE / 4).min(end));
        Some(Excerpt {
            name,
            text: &source[from..to],
            range: span.start - from..shown - from,
            line: source[..start].matches('\n').count(),
            column: source[start..from].chars().count(),
        })
    }
}

impl<'a> Files<'a> for Excerpt<'a> {
    type FileId = ();
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, (): ()) -> Result<&'a str, files::Error> {
        Ok(self.name)
    }

    fn source(&'a self, (): ()) -> Result<&'a str, files::Error> {
        Ok(self.text)
    }

    fn line_index(&'a self, (): (), _: usize) -> Result<usize, files::Error> {
        Ok(0)
    }

    fn line_number(&'a self, (): (), _: usize) -> Result<usize, files::Error> {
        Ok(self.line + 1)
    }

    fn column_number(&'a self, (): (), _: usize, byte: usize) -> Result<usize, files::Error> {
        let before = self.text.get(..byte).unwrap_or(self.text);
        Ok(self.column + before.chars().count() + 1)
    }

    fn line_range(&'a self, (): (), line: usize) -> Result<Range<usize>, files::Error> {
        match line {
            0 => Ok(0..self.text.len()),
            _ => Err(files::Error::LineTooLarge {
                given: line,
                max: 0,
            }),
        }
    }
}

/// The line and column (both from 1; the column in characters) of byte offset `at` in
/// `source`, for a place written into a message's text.
pub(crate) fn line_column(source: &str, at: usize) -> (usize, usize) {
    let before = source.get(..at).unwrap_or(source);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// Clamps `span` into `source` and onto char boundaries (codespan-reporting rejects others).
fn clamp_span(source: &str, span: Range<usize>) -> Range<usize> {
    let fix = |mut i: usize| {
        i = i.min(source.len());
        while !source.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    let start = fix(span.start);
    let end = fix(span.end).max(start);
    start..end
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.render())
    }
}

impl std::error::Error for Diagnostics {}

impl<'a> IntoIterator for &'a Diagnostics {
    type Item = &'a Diagnostic;
    type IntoIter = std::slice::Iter<'a, Diagnostic>;
    fn into_iter(self) -> Self::IntoIter {
        self.list.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_location_key_and_hint() {
        let src = "[mechanism]\nname = \"x\"\ninertai = 3\n";
        let mut d = Diagnostics::new("arm.toml", src);
        let start = src.find("inertai").unwrap();
        d.push(
            Diagnostic::error("unknown key \"inertai\"")
                .with_key("mechanism.inertai")
                .with_span(start..start + 7)
                .with_hint("did you mean \"inertia\"?"),
        );
        d.push(Diagnostic::warning("no span here").with_key("body[0]"));
        assert!(d.has_errors());
        assert_eq!(d.len(), 2);
        let r = d.render();
        assert!(r.contains("arm.toml:3:1"), "{r}");
        assert!(r.contains("^^^^^^^ mechanism.inertai"), "{r}");
        assert!(r.contains("hint: did you mean \"inertia\"?"), "{r}");
        assert!(r.contains("warning: no span here"), "{r}");
        assert!(r.contains("in arm.toml: body[0]"), "{r}");
        assert_eq!(r, d.to_string());
    }

    /// 2,000 errors on one 10 kB line: each shows a window of the line with the file's line
    /// and column, and only the first `MAX_RENDERED` are shown (every error printed the whole
    /// line: 20 MB of text, quadratic in the line's length).
    #[test]
    fn many_errors_on_a_long_line_render_in_proportion() {
        let n = 2000;
        let src = format!("v = [{}]\n", vec!["\"é\""; n].join(","));
        let mut d = Diagnostics::new("x.toml", &src);
        for (k, (at, _)) in src.match_indices("\"é\"").enumerate() {
            d.push(
                Diagnostic::error(format!("bad {k}"))
                    .with_key(format!("v[{k}]"))
                    .with_span(at..at + 4),
            );
        }
        let r = d.render();
        assert!(r.len() < 100_000, "{} bytes", r.len());
        // The 100th entry: 5 characters before the list, 4 per entry (`"é",`).
        let col = 6 + 4 * 99;
        assert!(
            r.contains(&format!("error: bad 99\n  --> x.toml:1:{col}\n")),
            "{r:.3000}"
        );
        assert!(r.contains("^^^ v[99]"), "{r:.3000}");
        assert!(!r.contains("bad 100\n"), "{r:.3000}");
        assert!(
            r.ends_with("... and 1900 more (1900 errors, 0 warnings) not shown\n"),
            "{}",
            &r[r.len() - 200..]
        );
    }

    #[test]
    fn out_of_range_spans_do_not_panic() {
        let mut d = Diagnostics::new("x.toml", "é");
        d.push(Diagnostic::error("m").with_span(1..100));
        #[allow(clippy::reversed_empty_ranges)]
        let reversed = 5..2;
        d.push(Diagnostic::error("m").with_span(reversed));
        let r = d.render();
        assert!(r.contains("x.toml:1:"), "{r}");
    }
}
