//! A link whose children of one kind do not stand together (`visual,
//! collision, visual`): urdfdom and Pinocchio read it, `urdf-rs` refuses
//! it ("duplicate field `visual`"), as its serde reading takes each
//! field's elements in one run. The order of a link's children of
//! different kinds means nothing, so before parsing each link's children
//! are gathered by kind, each kind where it first appears (and each kind's
//! own elements in their order).

use std::borrow::Cow;

use quick_xml::Reader;
use quick_xml::events::Event;

/// One direct child element of a `<link>`: its name and byte span.
struct Child {
    kind: Vec<u8>,
    from: usize,
    to: usize,
}

/// `text` with every link's children gathered by kind, and how many links
/// needed it. A document the reader cannot walk is left whole (the parser
/// names its fault).
pub(super) fn gather(text: &str) -> (Cow<'_, str>, usize) {
    let links = match scattered_links(text) {
        Some(links) if !links.is_empty() => links,
        _ => return (Cow::Borrowed(text), 0),
    };
    let mut out = String::with_capacity(text.len());
    let mut copied = 0;
    for children in &links {
        let (start, end) = (children[0].from, children[children.len() - 1].to);
        out.push_str(&text[copied..start]);
        out.push_str(&regrouped(text, children));
        copied = end;
    }
    out.push_str(&text[copied..]);
    (Cow::Owned(out), links.len())
}

/// The span from a link's first child to its last, rewritten: the
/// children in order of their kind's first appearance (stable), each in a
/// slot of the original; the text between the slots stays.
fn regrouped(text: &str, children: &[Child]) -> String {
    let first = |kind: &[u8]| children.iter().position(|c| c.kind == kind).unwrap_or(0);
    let mut order: Vec<&Child> = children.iter().collect();
    order.sort_by_key(|c| first(&c.kind));
    let mut out = String::new();
    for (k, child) in order.iter().enumerate() {
        if k > 0 {
            out.push_str(&text[children[k - 1].to..children[k].from]);
        }
        out.push_str(&text[child.from..child.to]);
    }
    out
}

/// Each link (right under `<robot>`) whose children of some kind do not
/// stand together, with its children in document order; None if the
/// document cannot be walked to its end.
fn scattered_links(text: &str) -> Option<Vec<Vec<Child>>> {
    let mut reader = Reader::from_str(text);
    let mut depth = 0usize;
    let mut in_link = false;
    let mut open: Option<(Vec<u8>, usize)> = None;
    let (mut children, mut out) = (Vec::new(), Vec::new());
    loop {
        let at = reader.buffer_position() as usize;
        let event = reader.read_event().ok()?;
        let end = reader.buffer_position() as usize;
        match event {
            Event::Start(e) => {
                if depth == 1 && e.name().as_ref() == b"link" {
                    in_link = true;
                } else if in_link && depth == 2 {
                    open = Some((e.name().as_ref().to_vec(), at));
                }
                depth += 1;
            }
            Event::Empty(e) if in_link && depth == 2 => {
                children.push(Child {
                    kind: e.name().as_ref().to_vec(),
                    from: at,
                    to: end,
                });
            }
            Event::End(_) => {
                depth = depth.saturating_sub(1);
                if in_link && depth == 2 {
                    if let Some((kind, from)) = open.take() {
                        children.push(Child {
                            kind,
                            from,
                            to: end,
                        });
                    }
                } else if in_link && depth == 1 {
                    in_link = false;
                    if scattered(&children) {
                        out.push(std::mem::take(&mut children));
                    }
                    children.clear();
                }
            }
            Event::Eof => return Some(out),
            _ => {}
        }
    }
}

/// Whether some kind comes in more than one run (`v c v`).
fn scattered(children: &[Child]) -> bool {
    let runs = children
        .windows(2)
        .filter(|w| w[0].kind != w[1].kind)
        .count()
        + 1;
    let mut kinds: Vec<&[u8]> = children.iter().map(|c| c.kind.as_slice()).collect();
    kinds.sort_unstable();
    kinds.dedup();
    !children.is_empty() && runs > kinds.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_links_children_are_gathered_by_kind() {
        let text = r#"<robot><link name="a"><inertial/><visual name="v1"/><collision name="c1"/>
<visual name="v2"><geometry/></visual><collision name="c2"/></link><link name="b"><visual/><collision/></link></robot>"#;
        let (out, links) = gather(text);
        assert_eq!(links, 1);
        assert_eq!(
            out,
            r#"<robot><link name="a"><inertial/><visual name="v1"/><visual name="v2"><geometry/></visual>
<collision name="c1"/><collision name="c2"/></link><link name="b"><visual/><collision/></link></robot>"#
        );
        // Another kind between two visuals, and one after them: gathered
        // too, each kind where it first stands.
        let (out, _) = gather(
            r#"<robot><link name="a"><visual n="1"/><inertial/><collision/><visual n="2"/></link></robot>"#,
        );
        assert_eq!(
            out,
            r#"<robot><link name="a"><visual n="1"/><visual n="2"/><inertial/><collision/></link></robot>"#
        );
        let grouped = r#"<robot><link name="a"><collision/><collision/><visual/></link></robot>"#;
        assert!(matches!(gather(grouped), (Cow::Borrowed(_), 0)));
    }
}
