//! The tag scanner: start tags with their attributes, spans and nesting ([`scan`]), the
//! document it gives ([`Doc`]), and the source with the elements nocdyn ignores blanked out
//! ([`strip_ignored`]).

use std::ops::Range;

use crate::diag::{Diagnostic, Diagnostics};

/// One XML attribute: name, raw value and the value's span (inside the quotes).
#[derive(Clone, Debug)]
pub(super) struct Attr<'s> {
    pub(super) name: &'s str,
    pub(super) value: &'s str,
    pub(super) span: Range<usize>,
}

/// The source with the elements nocdyn ignores blanked out — `<visual>`, `<collision>`,
/// top-level `<material>`, `<gazebo>`, `<transmission>` — so that urdf-rs does not reject a file
/// for them (e.g. a `<texture/>` without `filename`, as in iCub's URDF). Blanks keep every byte
/// offset and line, so spans into the source stay right.
pub(super) fn strip_ignored(source: &str, doc: &Doc<'_>) -> String {
    let mut out = source.as_bytes().to_vec();
    for t in &doc.tags {
        let top = t.parent == Some(doc.robot);
        // A top-level joint's `<limit>`, `<safety_controller>` and `<calibration>`: the limit
        // is read from the scanned tag (a range only when well formed, else none), the others
        // not at all; urdf-rs would reject a `<limit>` without `velocity`, a
        // `<safety_controller>` without `k_velocity` or a word in any of them, at the `<robot>`
        // tag and in its own words.
        let in_joint = t
            .parent
            .is_some_and(|p| doc.tags[p].name == "joint" && doc.tags[p].parent == Some(doc.robot));
        let ignored = matches!(t.name, "visual" | "collision")
            || (top && matches!(t.name, "material" | "gazebo" | "transmission"))
            || (in_joint && matches!(t.name, "limit" | "safety_controller" | "calibration"));
        if !ignored {
            continue;
        }
        let start = t.span.start;
        let self_closing = source[t.span.clone()].ends_with("/>");
        let end = if self_closing {
            t.span.end
        } else {
            let close = format!("</{}", t.name);
            match source[t.span.end..].find(&close) {
                Some(k) => match source[t.span.end + k..].find('>') {
                    Some(g) => t.span.end + k + g + 1,
                    None => continue,
                },
                None => continue,
            }
        };
        for b in &mut out[start..end] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
    }
    // Only ASCII bytes were replaced, by ASCII spaces, inside whole elements: still UTF-8.
    String::from_utf8(out).unwrap_or_else(|_| source.to_owned())
}

/// One start (or empty-element) tag.
#[derive(Clone, Debug)]
pub(super) struct Tag<'s> {
    pub(super) name: &'s str,
    /// The whole `<…>`.
    pub(super) span: Range<usize>,
    pub(super) attrs: Vec<Attr<'s>>,
    /// Index of the enclosing element's tag.
    pub(super) parent: Option<usize>,
}

impl<'s> Tag<'s> {
    pub(super) fn attr(&self, name: &str) -> Option<&Attr<'s>> {
        self.attrs.iter().find(|a| a.name == name)
    }
    /// Span of the element's name attribute value, else of the tag.
    pub(super) fn name_span(&self) -> Range<usize> {
        self.attr("name")
            .map_or(self.span.clone(), |a| a.span.clone())
    }
}

/// The deepest element nesting read (`<robot>` is level 1). URDF needs six levels or so; the
/// XML reader behind urdf-rs recurses once per level and overflows its stack at a few
/// thousand.
pub(crate) const MAX_XML_DEPTH: usize = 64;

/// An error at the first character of `src[from..to]` that is not white space (a BOM at the
/// very start counts as white space), if any: the text lies outside the root element.
fn text_outside_root(src: &str, from: usize, to: usize) -> Option<Diagnostic> {
    let text = &src[from..to];
    let (k, c) = text
        .char_indices()
        .find(|&(k, c)| !(c.is_ascii_whitespace() || (c == '\u{feff}' && from + k == 0)))?;
    Some(
        Diagnostic::error("XML: text outside the root element")
            .with_span(from + k..from + k + c.len_utf8())
            .with_hint(
                "a URDF file is one <robot> element, with only comments and white space around it",
            ),
    )
}

/// A tolerant scanner of start tags with nesting. Reports unbalanced or malformed tags, text
/// outside the root element, a second root element and nesting deeper than [`MAX_XML_DEPTH`]
/// (then stops: what follows would be noise). Iterative: any depth of input is safe here.
pub(super) fn scan<'s>(src: &'s str, diags: &mut Diagnostics) -> Vec<Tag<'s>> {
    let mut s = Scanner {
        src,
        tags: Vec::new(),
        stack: Vec::new(),
        root_seen: false,
    };
    let mut i = 0;
    while let Some(lt) = find_from(src, i, "<") {
        if s.stack.is_empty()
            && let Some(d) = text_outside_root(src, i, lt)
        {
            diags.push(d);
            return s.tags;
        }
        let rest = &src[lt..];
        let skip_to = |pat: &str| find_from(src, lt, pat).map(|p| p + pat.len());
        let next = if rest.starts_with("<!--") {
            skip_to("-->")
        } else if rest.starts_with("<![CDATA[") {
            skip_to("]]>")
        } else if rest.starts_with("<?") {
            skip_to("?>")
        } else if rest.starts_with("<!") {
            skip_to(">")
        } else if rest.starts_with("</") {
            let Ok(next) = s.close_tag(lt, diags) else {
                return s.tags;
            };
            next
        } else {
            let Ok(next) = s.start_tag(lt, diags) else {
                return s.tags;
            };
            next
        };
        match next {
            Some(n) => i = n,
            None => {
                diags.push(Diagnostic::error("XML: unterminated markup").with_span(lt..src.len()));
                return s.tags;
            }
        }
    }
    if let Some(&open) = s.stack.last() {
        diags.push(
            Diagnostic::error(format!("XML: <{}> is never closed", s.tags[open].name))
                .with_span(s.tags[open].span.clone()),
        );
    } else if let Some(d) = text_outside_root(src, i, src.len()) {
        diags.push(d);
    }
    s.tags
}

/// The first `pat` in `src` at or after `from`.
fn find_from(src: &str, from: usize, pat: &str) -> Option<usize> {
    src.get(from..).and_then(|s| s.find(pat)).map(|p| from + p)
}

/// Scanning stops: the error is reported.
struct Stop;

/// The scanner's state: the tags read, the open elements, and whether the root was seen.
struct Scanner<'s> {
    src: &'s str,
    tags: Vec<Tag<'s>>,
    /// Indices in `tags` of the open elements, innermost last.
    stack: Vec<usize>,
    root_seen: bool,
}

impl<'s> Scanner<'s> {
    /// The closing tag at `lt`: it closes the innermost open element. Where scanning goes on
    /// (`None`: the tag is unterminated).
    fn close_tag(&mut self, lt: usize, diags: &mut Diagnostics) -> Result<Option<usize>, Stop> {
        let src = self.src;
        let end = find_from(src, lt, ">");
        if let Some(end) = end {
            let name = src[lt + 2..end].trim();
            match self.stack.pop() {
                Some(open) if self.tags[open].name == name => {}
                Some(open) => {
                    diags.push(
                        Diagnostic::error(format!(
                            "XML: closing tag </{name}> does not match <{}>",
                            self.tags[open].name
                        ))
                        .with_span(lt..end + 1)
                        .with_hint(format!(
                            "<{}> opened {} is not closed",
                            self.tags[open].name,
                            line_col(src, self.tags[open].span.start)
                        )),
                    );
                    return Err(Stop);
                }
                None => {
                    diags.push(
                        Diagnostic::error(format!("XML: unexpected closing tag </{name}>"))
                            .with_span(lt..end + 1),
                    );
                    return Err(Stop);
                }
            }
        }
        Ok(end.map(|e| e + 1))
    }

    /// The start tag at `lt`: checked (well formed, not a second root, not too deep) and kept.
    /// Where scanning goes on.
    fn start_tag(&mut self, lt: usize, diags: &mut Diagnostics) -> Result<Option<usize>, Stop> {
        let src = self.src;
        let StartTag {
            name,
            attrs,
            self_closing,
            end,
            stop: j,
        } = read_start_tag(src, lt);
        let Some(end) = end.filter(|_| !name.is_empty()) else {
            diags.push(
                Diagnostic::error(format!("XML: malformed tag <{name}"))
                    .with_span(lt..j.clamp(lt + 1, src.len())),
            );
            return Err(Stop);
        };
        // An attribute written twice is not XML. urdf-rs refused it at the <robot> tag, but not
        // in the elements blanked out for it: `<limit velocity="1" velocity="0"/>` was read
        // with its first value, exit 0 (QA).
        if let Some((_, a)) = attrs
            .iter()
            .enumerate()
            .find(|(k, a)| attrs[..*k].iter().any(|b| b.name == a.name))
        {
            diags.push(
                Diagnostic::error(format!(
                    "XML: attribute `{}` written twice in <{name}>",
                    a.name
                ))
                .with_span(a.span.clone())
                .with_hint("an XML attribute may appear once per element"),
            );
            return Err(Stop);
        }
        if self.stack.is_empty() && std::mem::replace(&mut self.root_seen, true) {
            diags.push(
                Diagnostic::error(format!("XML: a second root element <{name}>"))
                    .with_span(lt..end)
                    .with_hint("a URDF file has one top-level <robot> element"),
            );
            return Err(Stop);
        }
        if self.stack.len() >= MAX_XML_DEPTH {
            diags.push(
                Diagnostic::error(format!(
                    "XML: <{name}> is nested deeper than {MAX_XML_DEPTH} elements"
                ))
                .with_span(lt..end)
                .with_hint("a URDF robot needs a few levels (robot, link, inertial, origin); is this the right file?"),
            );
            return Err(Stop);
        }
        self.tags.push(Tag {
            name,
            span: lt..end,
            attrs,
            parent: self.stack.last().copied(),
        });
        if !self_closing {
            self.stack.push(self.tags.len() - 1);
        }
        Ok(Some(end))
    }
}

/// A start tag as read, before its checks.
struct StartTag<'s> {
    name: &'s str,
    attrs: Vec<Attr<'s>>,
    /// `<…/>`.
    self_closing: bool,
    /// After its `>`, if the tag is well formed.
    end: Option<usize>,
    /// Where reading stopped.
    stop: usize,
}

/// The name and attributes of the start tag at `lt`, up to its `>` (or to what it cannot read).
fn read_start_tag(src: &str, lt: usize) -> StartTag<'_> {
    let b = src.as_bytes();
    let is_name = |c: u8| !(c.is_ascii_whitespace() || c == b'/' || c == b'>' || c == b'=');
    let skip_ws = |mut j: usize| {
        while j < b.len() && b[j].is_ascii_whitespace() {
            j += 1;
        }
        j
    };
    let mut j = lt + 1;
    while j < b.len() && is_name(b[j]) {
        j += 1;
    }
    let name = &src[lt + 1..j];
    let mut attrs = Vec::new();
    let mut self_closing = false;
    let mut end = None;
    loop {
        j = skip_ws(j);
        if j >= b.len() {
            break;
        }
        if b[j] == b'>' {
            end = Some(j + 1);
            break;
        }
        if b[j] == b'/' && b.get(j + 1) == Some(&b'>') {
            self_closing = true;
            end = Some(j + 2);
            break;
        }
        let an = j;
        while j < b.len() && is_name(b[j]) {
            j += 1;
        }
        let aname = &src[an..j];
        j = skip_ws(j);
        if aname.is_empty() || b.get(j) != Some(&b'=') {
            break;
        }
        j = skip_ws(j + 1);
        let Some(&q) = b.get(j).filter(|&&q| q == b'"' || q == b'\'') else {
            break;
        };
        let vs = j + 1;
        let Some(ve) = src[vs..].find(q as char).map(|p| vs + p) else {
            break;
        };
        attrs.push(Attr {
            name: aname,
            value: &src[vs..ve],
            span: vs..ve,
        });
        j = ve + 1;
    }
    StartTag {
        name,
        attrs,
        self_closing,
        end,
        stop: j,
    }
}

/// `line L, column C` of a byte offset.
fn line_col(src: &str, at: usize) -> String {
    let (line, col) = crate::diag::line_column(src, at);
    format!("at line {line}, column {col}")
}

/// The scanned tags with lookups.
pub(super) struct Doc<'s> {
    pub(super) tags: Vec<Tag<'s>>,
    pub(super) robot: usize,
    /// The children of each tag, in document order (lookups stay linear in the file).
    kids: Vec<Vec<usize>>,
}

impl<'s> Doc<'s> {
    pub(super) fn new(tags: Vec<Tag<'s>>, robot: usize) -> Self {
        let mut kids = vec![Vec::new(); tags.len()];
        for (i, t) in tags.iter().enumerate() {
            if let Some(p) = t.parent {
                kids[p].push(i);
            }
        }
        Doc { tags, robot, kids }
    }

    /// Direct children of `parent` named `name`.
    pub(super) fn children(
        &self,
        parent: usize,
        name: &'s str,
    ) -> impl Iterator<Item = usize> + '_ {
        self.kids[parent]
            .iter()
            .copied()
            .filter(move |&i| self.tags[i].name == name)
    }
    pub(super) fn child(&self, parent: usize, name: &'s str) -> Option<usize> {
        self.children(parent, name).next()
    }
    /// Follows `path` down from `from`.
    pub(super) fn descend(&self, from: usize, path: &[&'s str]) -> Option<usize> {
        path.iter().try_fold(from, |t, p| self.child(t, p))
    }
}
