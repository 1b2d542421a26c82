//! XML namespace prefixes a URDF uses without declaring them (Drake's
//! `drake:acceleration` without `xmlns:drake`): every other URDF reader
//! (Pinocchio, MuJoCo, ROS) ignores what it does not know, but the XML
//! parser under `urdf-rs` refuses an unbound prefix. So the missing
//! declarations are added to the root element before parsing; the elements
//! and attributes in them are then ignored like any unknown tag.

use std::borrow::Cow;
use std::collections::BTreeSet;

/// `text` with a declaration on its root element for every prefix it uses
/// but the root does not declare, and the prefixes so declared.
pub(super) fn declare_undeclared(text: &str) -> (Cow<'_, str>, Vec<String>) {
    let b = text.as_bytes();
    let mut used: BTreeSet<&str> = BTreeSet::new();
    let mut declared: BTreeSet<&str> = BTreeSet::new();
    let mut root_name_end = None;
    let mut i = 0;
    while let Some(off) = text.get(i..).and_then(|t| t.find('<')) {
        let start = i + off;
        let rest = &text[start..];
        let skip_to = |end: &str| rest.find(end).map_or(rest.len(), |e| e + end.len());
        if rest.starts_with("<!--") {
            i = start + skip_to("-->");
            continue;
        }
        if rest.starts_with("<![CDATA[") {
            i = start + skip_to("]]>");
            continue;
        }
        if rest.starts_with("<?") {
            i = start + skip_to("?>");
            continue;
        }
        if rest.starts_with("<!") {
            i = start + skip_to(">");
            continue;
        }
        let closing = b.get(start + 1) == Some(&b'/');
        let mut j = start + 1 + usize::from(closing);
        let name_start = j;
        while j < b.len() && !b[j].is_ascii_whitespace() && !matches!(b[j], b'>' | b'/') {
            j += 1;
        }
        note_prefix(&text[name_start..j], &mut used);
        let is_root = root_name_end.is_none() && !closing;
        if is_root {
            root_name_end = Some(j);
        }
        // Attributes up to the tag's end, quoted values skipped whole.
        while j < b.len() {
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            match b.get(j) {
                None => break,
                Some(b'>') => {
                    j += 1;
                    break;
                }
                Some(b'/') => {
                    j += 1;
                    continue;
                }
                Some(_) => {}
            }
            let a0 = j;
            while j < b.len() && !b[j].is_ascii_whitespace() && !matches!(b[j], b'=' | b'>' | b'/')
            {
                j += 1;
            }
            let attr = &text[a0..j];
            match attr.strip_prefix("xmlns:") {
                Some(p) if is_root => {
                    declared.insert(p);
                }
                Some(_) => {}
                None => note_prefix(attr, &mut used),
            }
            while j < b.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            if b.get(j) == Some(&b'=') {
                j += 1;
                while j < b.len() && b[j].is_ascii_whitespace() {
                    j += 1;
                }
                if let Some(&q) = b.get(j).filter(|q| matches!(q, b'"' | b'\'')) {
                    j += 1;
                    while j < b.len() && b[j] != q {
                        j += 1;
                    }
                    j += 1;
                }
            }
            if j == a0 {
                // A stray character: step over it (whole, never into a
                // UTF-8 sequence) rather than loop.
                j += 1;
                while j < b.len() && !text.is_char_boundary(j) {
                    j += 1;
                }
            }
        }
        i = j.min(b.len());
    }
    let missing: Vec<String> = used
        .difference(&declared)
        .map(|p| (*p).to_string())
        .collect();
    let Some(at) = root_name_end.filter(|_| !missing.is_empty()) else {
        return (Cow::Borrowed(text), Vec::new());
    };
    let mut out = String::with_capacity(text.len() + 48 * missing.len());
    out.push_str(&text[..at]);
    for p in &missing {
        out.push_str(&format!(" xmlns:{p}=\"urn:testbed:undeclared:{p}\""));
    }
    out.push_str(&text[at..]);
    (Cow::Owned(out), missing)
}

/// Records the prefix of a qualified name (`drake:acceleration`).
fn note_prefix<'a>(name: &'a str, used: &mut BTreeSet<&'a str>) {
    if let Some((p, local)) = name.split_once(':')
        && !p.is_empty()
        && !local.is_empty()
        && p != "xmlns"
        && p != "xml"
    {
        used.insert(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Any text, markup-like or not: no panic, and only prefixes the
        /// text really has are declared.
        #[test]
        fn any_text_is_scanned_without_panic(text in "[<>/='\" a-zé:!?-]{0,80}") {
            let (out, added) = declare_undeclared(&text);
            for p in &added {
                let used = format!("{p}:");
                proptest::prop_assert!(text.contains(&used), "{} not in {}", used, text);
            }
            proptest::prop_assert!(out.len() >= text.len());
        }
    }

    #[test]
    fn undeclared_prefixes_are_declared_on_the_root_only() {
        let text = r#"<?xml version="1.0"?>
<!-- <fake:tag> in a comment is not a use -->
<robot name="r" xmlns:xacro="http://ros.org/wiki/xacro">
  <joint name="j" type="revolute"><limit effort="1" drake:acceleration="3.0"/>
    <xacro:property name="x" value="a>b"/>
    <gz:plugin/></joint>
</robot>"#;
        let (out, added) = declare_undeclared(text);
        assert_eq!(added, ["drake", "gz"]);
        assert!(out.contains(r#"<robot xmlns:drake="urn:testbed:undeclared:drake" xmlns:gz="urn:testbed:undeclared:gz" name="r""#), "{out}");
        // Not XML, or cut short, or not ASCII: no panic, and nothing added
        // that was not used.
        for odd in [
            "<",
            "<a b=",
            "<a b='x",
            "<é:x/>",
            "<a é=\"1\" /é>",
            "<!--",
            "<a/><b:c",
        ] {
            let (_, added) = declare_undeclared(odd);
            assert!(added.len() <= 1, "{odd}: {added:?}");
        }
        // Nothing to add: the text is untouched.
        let plain = r#"<robot name="r"><link name="a"/></robot>"#;
        let (out, added) = declare_undeclared(plain);
        assert!(added.is_empty() && matches!(out, Cow::Borrowed(_)));
    }
}
