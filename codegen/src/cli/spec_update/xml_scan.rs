//! A scan of an XML text into its tags with the byte ranges of their attribute values, for
//! rewriting a URDF's numbers in place (everything between the values kept byte for byte,
//! comments included). Comments, processing instructions, CDATA and declarations are skipped;
//! the text is not validated (the spec loader has read it already).

use std::ops::Range;

/// A start, end or empty-element tag.
#[derive(Clone, Debug)]
pub(super) struct Tag {
    pub name: String,
    /// From `<` to `>` inclusive.
    pub range: Range<usize>,
    /// `</name>`.
    pub end: bool,
    /// `<name … />`.
    pub empty: bool,
    /// Attribute names with the ranges of their values (without the quotes).
    pub attrs: Vec<(String, Range<usize>)>,
}

impl Tag {
    pub(super) fn attr(&self, name: &str) -> Option<Range<usize>> {
        self.attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, r)| r.clone())
    }
    /// Where a new attribute goes: before `/>` or `>`.
    pub(super) fn attr_insert_at(&self) -> usize {
        self.range.end - if self.empty { 2 } else { 1 }
    }
}

/// The tags of `text`, in order; `Err` for an unterminated comment or tag.
pub(super) fn scan(text: &str) -> Result<Vec<Tag>, String> {
    let b = text.as_bytes();
    let mut tags = Vec::new();
    let mut i = 0;
    let find = |from: usize, pat: &str| text[from..].find(pat).map(|k| from + k);
    while let Some(k) = find(i, "<") {
        i = k;
        let skip = [
            ("<!--", "-->"),
            ("<?", "?>"),
            ("<![CDATA[", "]]>"),
            ("<!", ">"),
        ]
        .iter()
        .find(|(open, _)| text[i..].starts_with(open));
        if let Some((_, close)) = skip {
            i = find(i, close).ok_or("an unterminated comment or declaration")? + close.len();
            continue;
        }
        let start = i;
        i += 1;
        let end = b.get(i) == Some(&b'/');
        if end {
            i += 1;
        }
        let name_start = i;
        while i < b.len() && !b[i].is_ascii_whitespace() && b[i] != b'/' && b[i] != b'>' {
            i += 1;
        }
        let name = text[name_start..i].to_string();
        let mut attrs = Vec::new();
        let empty;
        loop {
            while i < b.len() && b[i].is_ascii_whitespace() {
                i += 1;
            }
            match b.get(i) {
                None => return Err(format!("an unterminated tag `<{name}`")),
                Some(b'>') => {
                    empty = false;
                    i += 1;
                    break;
                }
                Some(b'/') if b.get(i + 1) == Some(&b'>') => {
                    empty = true;
                    i += 2;
                    break;
                }
                _ => {}
            }
            let a = i;
            while i < b.len() && b[i] != b'=' && !b[i].is_ascii_whitespace() && b[i] != b'>' {
                i += 1;
            }
            let attr = text[a..i].to_string();
            while i < b.len() && (b[i].is_ascii_whitespace() || b[i] == b'=') {
                i += 1;
            }
            let Some(&q) = b.get(i).filter(|q| **q == b'"' || **q == b'\'') else {
                return Err(format!(
                    "attribute `{attr}` of `<{name}` without a quoted value"
                ));
            };
            let v = i + 1;
            let close = text[v..]
                .find(q as char)
                .ok_or_else(|| format!("an unterminated value of `{attr}`"))?;
            attrs.push((attr, v..v + close));
            i = v + close + 1;
        }
        tags.push(Tag {
            name,
            range: start..i,
            end,
            empty,
            attrs,
        });
    }
    Ok(tags)
}

/// The index of the end tag that closes start tag `open` (`None` for an empty element or
/// when it is not closed).
pub(super) fn closing(tags: &[Tag], open: usize) -> Option<usize> {
    if tags[open].empty || tags[open].end {
        return None;
    }
    let mut depth = 0usize;
    for (k, t) in tags.iter().enumerate().skip(open + 1) {
        if t.empty {
            continue;
        }
        if t.end {
            if depth == 0 {
                return (t.name == tags[open].name).then_some(k);
            }
            depth -= 1;
        } else {
            depth += 1;
        }
    }
    None
}

/// The direct children of start tag `open` named `name` (indices of their start or empty tags).
pub(super) fn children(tags: &[Tag], open: usize, name: &str) -> Vec<usize> {
    let Some(close) = closing(tags, open) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut depth = 0usize;
    for (k, t) in tags.iter().enumerate().take(close).skip(open + 1) {
        if t.end {
            depth = depth.saturating_sub(1);
            continue;
        }
        if depth == 0 && t.name == name {
            out.push(k);
        }
        if !t.empty {
            depth += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_attributes_and_nesting_skip_comments() {
        let text = "<?xml version=\"1.0\"?>\n<!-- <link name=\"no\"/> -->\n<robot name='r'>\n  <link name=\"a\">\n    <inertial><mass value=\"2.5\"/></inertial>\n  </link>\n</robot>\n";
        let tags = scan(text).unwrap();
        let names: Vec<&str> = tags.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "robot", "link", "inertial", "mass", "inertial", "link", "robot"
            ]
        );
        let link = 1;
        assert_eq!(&text[tags[link].attr("name").unwrap()], "a");
        let inertial = children(&tags, link, "inertial");
        assert_eq!(inertial, [2]);
        let mass = children(&tags, 2, "mass");
        assert_eq!(&text[tags[mass[0]].attr("value").unwrap()], "2.5");
        assert_eq!(closing(&tags, 0), Some(6));
        assert!(tags[3].empty);
        assert!(scan("<a b=1/>").is_err());
        assert!(scan("<!-- open").is_err());
    }
}
