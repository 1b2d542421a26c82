//! `<texture/>` and `<mesh/>` elements without a `filename`: the URDF
//! reader under `urdf-rs` refuses them (its structs require the field), but
//! Pinocchio, MuJoCo and ROS read such files (romeo and icub in
//! example-robot-data have a bare `<texture />` in their materials).
//! Neither a texture nor a mesh moves the arm, so the missing attribute is
//! filled with an empty name before parsing, and the model notes it.

use std::borrow::Cow;

/// The elements whose `filename` may be missing.
const ELEMENTS: [&str; 2] = ["texture", "mesh"];

/// `text` with `filename=""` added to every such element without one, and
/// how many were filled per element name.
pub(super) fn fill_missing(text: &str) -> (Cow<'_, str>, Vec<(&'static str, usize)>) {
    let mut inserts = Vec::new();
    let mut filled = Vec::new();
    for name in ELEMENTS {
        let before = inserts.len();
        inserts.extend(missing(text, name));
        if inserts.len() > before {
            filled.push((name, inserts.len() - before));
        }
    }
    if inserts.is_empty() {
        return (Cow::Borrowed(text), filled);
    }
    inserts.sort_unstable();
    let mut out = String::with_capacity(text.len() + 12 * inserts.len());
    let mut copied = 0;
    for at in inserts {
        out.push_str(&text[copied..at]);
        out.push_str(" filename=\"\"");
        copied = at;
    }
    out.push_str(&text[copied..]);
    (Cow::Owned(out), filled)
}

/// Offsets just past `<name` of each `name` element with no `filename`.
fn missing(text: &str, name: &str) -> Vec<usize> {
    let open = format!("<{name}");
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(off) = text[from..].find(&open) {
        let after = from + off + open.len();
        from = after;
        // `<meshes>` or `<texture_x>` are other elements.
        let whole_name =
            text[after..].starts_with(|c: char| c.is_ascii_whitespace() || c == '/' || c == '>');
        if whole_name && !has_filename(&text[after..tag_end(text, after)]) {
            out.push(after);
        }
    }
    out
}

/// Where the tag starting before `from` ends (its `>`, quoted values
/// skipped), or the end of the text.
fn tag_end(text: &str, from: usize) -> usize {
    let mut quote = None;
    for (i, c) in text[from..].char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '>') => return from + i,
            _ => {}
        }
    }
    text.len()
}

/// Whether a tag's attribute text names a `filename`.
fn has_filename(attrs: &str) -> bool {
    attrs.match_indices("filename").any(|(i, _)| {
        let before_ok = attrs[..i].ends_with(|c: char| c.is_ascii_whitespace());
        let after = attrs[i + "filename".len()..].trim_start();
        before_ok && after.starts_with('=')
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bare_textures_and_meshes_get_an_empty_filename() {
        let text = r#"<material name="g"><texture /></material><mesh scale="1 1 1"/><meshes/><mesh filename="a.stl"/><texture filename='t.png'>"#;
        let (out, filled) = fill_missing(text);
        assert_eq!(
            out,
            r#"<material name="g"><texture filename="" /></material><mesh filename="" scale="1 1 1"/><meshes/><mesh filename="a.stl"/><texture filename='t.png'>"#
        );
        assert_eq!(filled, [("texture", 1), ("mesh", 1)]);
        let (same, none) = fill_missing("<robot><mesh filename=\"x\"/></robot>");
        assert!(matches!(same, Cow::Borrowed(_)) && none.is_empty());
    }
}
