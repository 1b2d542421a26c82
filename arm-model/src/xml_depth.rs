//! How deep a document's elements nest, found without parsing it: the XML
//! reader recurses once per level, and 50 000 nested elements (350 KB)
//! overflowed its stack (#31 row 15). A URDF needs a handful of levels.

/// Elements may nest this deep; a URDF's deepest is about 6
/// (robot/link/visual/geometry/mesh), a xacro-expanded one a few more.
pub const MAX_XML_DEPTH: usize = 100;

/// The deepest element nesting of `text`, scanning tags only (comments,
/// CDATA, processing instructions and declarations skipped; quoted
/// attribute values may hold `>`). Stops counting past `limit`.
pub fn depth(text: &str, limit: usize) -> usize {
    let b = text.as_bytes();
    let (mut i, mut depth, mut deepest) = (0, 0usize, 0usize);
    while let Some(off) = b[i..].iter().position(|&c| c == b'<') {
        i += off + 1;
        let rest = &b[i..];
        let skip_to = |end: &[u8]| {
            rest.windows(end.len())
                .position(|w| w == end)
                .map_or(b.len(), |p| i + p + end.len())
        };
        if rest.starts_with(b"!--") {
            i = skip_to(b"-->");
        } else if rest.starts_with(b"![CDATA[") {
            i = skip_to(b"]]>");
        } else if rest.starts_with(b"?") {
            i = skip_to(b"?>");
        } else if rest.starts_with(b"!") {
            i = skip_to(b">");
        } else if rest.starts_with(b"/") {
            depth = depth.saturating_sub(1);
            i = skip_to(b">");
        } else {
            let (end, self_closing) = tag_end(b, i);
            i = end;
            if !self_closing {
                depth += 1;
                deepest = deepest.max(depth);
                if deepest > limit {
                    return deepest;
                }
            }
        }
    }
    deepest
}

/// Where the start tag beginning at `i` ends, and whether it closes itself.
fn tag_end(b: &[u8], mut i: usize) -> (usize, bool) {
    let mut quote = None;
    let mut last = 0u8;
    while i < b.len() {
        let c = b[i];
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == b'"' || c == b'\'' => quote = Some(c),
            None if c == b'>' => return (i + 1, last == b'/'),
            None => {}
        }
        if !c.is_ascii_whitespace() {
            last = c;
        }
        i += 1;
    }
    (b.len(), false)
}

/// A start tag with too many attributes.
#[derive(Debug, PartialEq)]
pub struct WideTag {
    /// The element's name, cut to 80 characters.
    pub element: String,
    /// Its line, from 1.
    pub line: usize,
    /// The attributes counted (`limit` + 1: counting stops there).
    pub count: usize,
}

/// The first start tag of `text` with more than `limit` attributes, if
/// any, in one pass over the tags (an attribute counted by its `=` outside
/// quotes), skipping what `depth` skips.
pub fn widest_tag(text: &str, limit: usize) -> Option<WideTag> {
    let b = text.as_bytes();
    let mut i = 0;
    while let Some(off) = b[i..].iter().position(|&c| c == b'<') {
        let start = i + off;
        i = start + 1;
        let rest = &b[i..];
        let skip_to = |end: &[u8]| {
            rest.windows(end.len())
                .position(|w| w == end)
                .map_or(b.len(), |p| i + p + end.len())
        };
        if rest.starts_with(b"!--") {
            i = skip_to(b"-->");
        } else if rest.starts_with(b"![CDATA[") {
            i = skip_to(b"]]>");
        } else if rest.starts_with(b"?") {
            i = skip_to(b"?>");
        } else if rest.starts_with(b"!") || rest.starts_with(b"/") {
            i = skip_to(b">");
        } else {
            let (mut quote, mut count) = (None, 0usize);
            while i < b.len() {
                let c = b[i];
                i += 1;
                match quote {
                    Some(q) if c == q => quote = None,
                    Some(_) => {}
                    None if c == b'"' || c == b'\'' => quote = Some(c),
                    None if c == b'>' => break,
                    None if c == b'=' => {
                        count += 1;
                        if count > limit {
                            let name: String = text[start + 1..]
                                .split(|c: char| c.is_whitespace() || c == '/' || c == '>')
                                .next()
                                .unwrap_or("")
                                .chars()
                                .take(80)
                                .collect();
                            let line = b[..start].iter().filter(|&&c| c == b'\n').count() + 1;
                            return Some(WideTag {
                                element: name,
                                line,
                                count,
                            });
                        }
                    }
                    None => {}
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nesting_is_counted_from_tags_alone() {
        let urdf = r#"<?xml version="1.0"?><!-- <a><b> --><robot name="r">
            <link name="a"><visual><geometry><box size="1 1 1"/></geometry></visual></link>
            <joint name="j" type="fixed" note="a > b"><parent link="a"/></joint></robot>"#;
        assert_eq!(depth(urdf, MAX_XML_DEPTH), 4);
        let deep = "<a>".repeat(50_000) + &"</a>".repeat(50_000);
        assert_eq!(depth(&deep, MAX_XML_DEPTH), MAX_XML_DEPTH + 1);
        assert_eq!(depth("<![CDATA[<a><a>]]><x/>", 10), 0);
    }

    /// Attributes are counted per tag, `=` in quotes and comments not.
    #[test]
    fn attributes_are_counted_per_tag() {
        let ok = r#"<robot name="r"><!-- a=1 b=2 c=3 --><link name="a=b" x="1"/></robot>"#;
        assert_eq!(widest_tag(ok, 2), None);
        let wide = "<robot>\n<origin a=\"1\" b='2' c=\"3\"/></robot>";
        assert_eq!(
            widest_tag(wide, 2),
            Some(WideTag {
                element: "origin".into(),
                line: 2,
                count: 3
            })
        );
    }
}
