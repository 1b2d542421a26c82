//! An MJCF file's `<include>`s inlined, so that its text alone is the
//! model: the scenario keeps the text, the plant node and `replay` read it
//! again from there (a log's attachment needs no other file). As in
//! MuJoCo, an included file's root `<mujoco>` element is replaced by its
//! children, and every path is relative to the main file's folder.

use std::path::Path;

use crate::ModelError;

/// Includes nest no deeper than this: deeper is a file including itself.
const MAX_DEPTH: usize = 16;

/// `text` with every `<include file>` replaced by that file's contents.
pub(crate) fn inline(text: &str, dir: &Path) -> Result<String, ModelError> {
    inline_at(text, dir, 0)
}

fn inline_at(text: &str, dir: &Path, depth: usize) -> Result<String, ModelError> {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = next_include(rest) {
        out.push_str(&rest[..i]);
        let tag_end = rest[i..]
            .find('>')
            .map(|e| i + e + 1)
            .ok_or_else(|| refuse("<include>", "the tag is not closed"))?;
        let tag = &rest[i..tag_end];
        let file = attribute(tag, "file").ok_or_else(|| refuse(tag, "it names no file"))?;
        if depth >= MAX_DEPTH {
            return Err(refuse(
                tag,
                &format!("includes nest more than {MAX_DEPTH} deep: a file includes itself"),
            ));
        }
        let path = dir.join(file);
        let inner = std::fs::read_to_string(&path)
            .map_err(|e| refuse(tag, &format!("cannot read {}: {e}", path.display())))?;
        out.push_str(&inline_at(children(&inner), dir, depth + 1)?);
        rest = &rest[tag_end..];
        // `<include …></include>` written in full.
        if !tag.ends_with("/>") {
            rest = rest.trim_start().strip_prefix("</include>").unwrap_or(rest);
        }
    }
    out.push_str(rest);
    Ok(out)
}

/// Text given alone (a log's attachment, a string) names no other file:
/// an `<include>` there is refused, so that reading a model never reads
/// files its reader did not name.
pub(crate) fn refuse_includes(text: &str) -> Result<(), ModelError> {
    let Some(i) = next_include(text) else {
        return Ok(());
    };
    let tag = text[i..].find('>').map_or(&text[i..], |e| &text[i..=i + e]);
    Err(refuse(
        tag,
        "an include in a model given as text: read the file itself, whose includes are inlined relative to its folder",
    ))
}

fn refuse(element: &str, reason: &str) -> ModelError {
    ModelError::MjcfParse(format!("{element}: {reason}"))
}

/// Where the next `<include` tag starts, outside comments (a commented
/// include, as in Meta-World's usage notes, includes nothing).
fn next_include(text: &str) -> Option<usize> {
    next_tag(text, "include")
}

/// Where the next `<name` tag starts, outside comments.
pub(crate) fn next_tag(text: &str, name: &str) -> Option<usize> {
    let open = format!("<{name}");
    let mut from = 0;
    loop {
        let i = from + text[from..].find(&open)?;
        match text[from..i].find("<!--") {
            Some(c) => from = from + c + text[from + c..].find("-->")? + 3,
            None => {
                let next = text[i + open.len()..].chars().next();
                if next.is_some_and(|c| c.is_whitespace() || c == '/' || c == '>') {
                    return Some(i);
                }
                from = i + 1;
            }
        }
    }
}

/// Every `<name …>` tag outside comments, whole.
pub(crate) fn tags<'a>(text: &'a str, name: &'a str) -> impl Iterator<Item = &'a str> + 'a {
    let mut rest = text;
    std::iter::from_fn(move || {
        let i = next_tag(rest, name)?;
        let end = rest[i..].find('>').map_or(rest.len(), |e| i + e + 1);
        let tag = &rest[i..end];
        rest = &rest[end..];
        Some(tag)
    })
}

/// The value of `name="…"` (or single-quoted) in a tag.
pub(crate) fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let mut from = 0;
    while let Some(i) = tag[from..].find(name) {
        let at = from + i;
        let before = tag[..at].chars().next_back();
        let after = tag[at + name.len()..].trim_start();
        if before.is_some_and(char::is_whitespace)
            && let Some(value) = after.strip_prefix('=')
        {
            let value = value.trim_start();
            let quote = value.chars().next()?;
            if quote == '"' || quote == '\'' {
                let body = &value[1..];
                return body.find(quote).map(|end| &body[..end]);
            }
        }
        from = at + name.len();
    }
    None
}

/// What lies inside the root element of an included file: `<mujoco>`, or
/// `<mujocoinclude>` as older models (Adroit, Meta-World) write it.
fn children(text: &str) -> &str {
    let root = prolog_end(text);
    let Some(body) = text[root..].strip_prefix('<') else {
        return &text[root..];
    };
    let name_len = body
        .find(|c: char| c.is_whitespace() || c == '>' || c == '/')
        .unwrap_or(body.len());
    let name = &body[..name_len];
    if name != "mujoco" && name != "mujocoinclude" {
        return &text[root..];
    }
    let Some(open_end) = text[root..].find('>').map(|e| root + e + 1) else {
        return "";
    };
    if text[..open_end].ends_with("/>") {
        return "";
    }
    let close = text.rfind(&format!("</{name}>")).unwrap_or(text.len());
    text.get(open_end..close).unwrap_or("")
}

/// Where the root element starts: past the XML declaration, comments and
/// blank space.
fn prolog_end(text: &str) -> usize {
    let mut at = 0;
    loop {
        let rest = &text[at..];
        let trimmed = rest.trim_start_matches(|c: char| c.is_whitespace() || c == '\u{feff}');
        at += rest.len() - trimmed.len();
        let close = if trimmed.starts_with("<?") {
            "?>"
        } else if trimmed.starts_with("<!--") {
            "-->"
        } else {
            return at;
        };
        match trimmed.find(close) {
            Some(e) => at += e + close.len(),
            None => return at,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_attribute_is_found_by_its_whole_name() {
        assert_eq!(
            attribute(r#"<include xfile="a" file='b.xml'/>"#, "file"),
            Some("b.xml")
        );
        assert_eq!(attribute("<include/>", "file"), None);
    }

    #[test]
    fn an_included_root_gives_its_children() {
        assert_eq!(children("<?xml?><mujoco model='x'><a/></mujoco>"), "<a/>");
        assert_eq!(children("<mujoco/>"), "");
        assert_eq!(
            children("<!-- <mujoco> --><mujocoinclude>\n<body/>\n</mujocoinclude>\n"),
            "\n<body/>\n"
        );
    }

    #[test]
    fn a_commented_include_includes_nothing() {
        let text = r#"<mujoco><!-- <include file="gone.xml"/> --><include file="x.xml"/></mujoco>"#;
        assert_eq!(next_include(text), text.find(r#"<include file="x"#));
        assert_eq!(next_include("<!-- <include file='a'/> -->"), None);
        assert_eq!(next_include("<!-- <include file='a'/>"), None);
    }

    #[test]
    fn a_file_that_includes_itself_is_refused() {
        let dir = std::env::temp_dir().join(format!("mjcf-include-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("loop.xml"),
            r#"<mujoco><include file="loop.xml"/></mujoco>"#,
        )
        .unwrap();
        let e = inline(r#"<mujoco><include file="loop.xml"/></mujoco>"#, &dir).unwrap_err();
        assert!(e.to_string().contains("includes itself"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
