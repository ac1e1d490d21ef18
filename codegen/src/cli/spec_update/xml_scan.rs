//! A scan of an XML text into its tags with the byte ranges of their attribute values, for
//! rewriting a URDF's numbers in place (everything between the values kept byte for byte,
//! comments included). Comments, processing instructions, CDATA and declarations are skipped.

use std::borrow::Cow;
use std::ops::Range;

use quick_xml::events::Event;

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

/// The tags of `text`, in order (read by `quick-xml`, whose events borrow from `text`, so each
/// tag's and each raw attribute value's place in it is known); `Err` for text that is not
/// well-formed XML (an unterminated comment or tag, an unquoted value, …).
pub(super) fn scan(text: &str) -> Result<Vec<Tag>, String> {
    let mut reader = quick_xml::Reader::from_str(text);
    let offset = |pos: u64| usize::try_from(pos).unwrap_or(usize::MAX).min(text.len());
    let mut tags = Vec::new();
    loop {
        let start = offset(reader.buffer_position());
        let event = reader
            .read_event()
            .map_err(|e| format!("not well-formed XML near byte {start}: {e}"))?;
        let range = start..offset(reader.buffer_position());
        let (e, end, empty) = match event {
            Event::Eof => return Ok(tags),
            Event::Start(e) => (e, false, false),
            Event::Empty(e) => (e, false, true),
            Event::End(e) => {
                tags.push(Tag {
                    name: String::from_utf8_lossy(e.name().as_ref()).into_owned(),
                    range,
                    end: true,
                    empty: false,
                    attrs: Vec::new(),
                });
                continue;
            }
            _ => continue,
        };
        let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
        let mut attrs = Vec::new();
        for a in e.attributes() {
            let a = a.map_err(|err| format!("an attribute of `<{name}`: {err}"))?;
            let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
            // The raw value borrows from `text`: its place is the pointers' difference.
            let Cow::Borrowed(v) = a.value else {
                return Err(format!(
                    "attribute `{key}` of `<{name}` could not be placed"
                ));
            };
            let at = (v.as_ptr() as usize).wrapping_sub(text.as_ptr() as usize);
            if at.checked_add(v.len()).is_none_or(|e| e > text.len()) {
                return Err(format!(
                    "attribute `{key}` of `<{name}` could not be placed"
                ));
            }
            attrs.push((key, at..at + v.len()));
        }
        tags.push(Tag {
            name,
            range,
            end,
            empty,
            attrs,
        });
    }
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

    /// Markup inside CDATA, a DOCTYPE, a `>` inside a value, single quotes and an entity: the
    /// ranges are the raw values' places in the text.
    #[test]
    fn raw_values_are_placed_in_the_text() {
        let text = "<!DOCTYPE robot>\n<robot>\n<![CDATA[<link name=\"no\">]]>\n<link name='a&amp;b' x=\"1>2\"\n  y = \"3\"/>\n</robot>";
        let tags = scan(text).unwrap();
        let names: Vec<&str> = tags.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["robot", "link", "robot"]);
        let link = &tags[1];
        assert_eq!(&text[link.attr("name").unwrap()], "a&amp;b");
        assert_eq!(&text[link.attr("x").unwrap()], "1>2");
        assert_eq!(&text[link.attr("y").unwrap()], "3");
        assert_eq!(
            &text[link.range.clone()],
            "<link name='a&amp;b' x=\"1>2\"\n  y = \"3\"/>"
        );
        assert!(link.empty);
        assert_eq!(&text[link.attr_insert_at()..link.range.end], "/>");
        assert_eq!(&text[tags[2].range.clone()], "</robot>");
        assert!(scan("<robot><link></robot>").is_err());
    }
}
