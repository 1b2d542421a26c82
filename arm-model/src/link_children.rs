//! A link whose `<visual>` and `<collision>` elements interleave
//! (`visual, collision, visual`): urdfdom and Pinocchio read it, `urdf-rs`
//! refuses it ("duplicate field `visual`"), as its serde reading takes each
//! field's elements in one run. The order of a link's visuals among its
//! collisions means nothing, so each link's visuals are gathered where its
//! first visual stands, and its collisions where its first collision
//! stands, before parsing (each kind keeps its own order).

use std::borrow::Cow;

use quick_xml::Reader;
use quick_xml::events::Event;

/// The children of a link that may repeat, gathered by kind.
const GATHERED: [&str; 2] = ["visual", "collision"];

/// One direct child of a `<link>` of a kind in [`GATHERED`]: its kind
/// and its byte span.
struct Child {
    kind: usize,
    from: usize,
    to: usize,
}

/// `text` with every link's visuals and collisions gathered, and how many
/// links needed it. A document the reader cannot walk is left whole (the
/// parser names its fault).
pub(super) fn gather(text: &str) -> (Cow<'_, str>, usize) {
    let Some(links) = interleaved_links(text) else {
        return (Cow::Borrowed(text), 0);
    };
    if links.is_empty() {
        return (Cow::Borrowed(text), 0);
    }
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

/// The span from a link's first gathered child to its last, rewritten:
/// each child's slot, in order, gets the next child of the kind whose
/// first slot it falls in; the text between children stays.
fn regrouped(text: &str, children: &[Child]) -> String {
    let first_kind = children[0].kind;
    let mut order: Vec<&Child> = children.iter().filter(|c| c.kind == first_kind).collect();
    order.extend(children.iter().filter(|c| c.kind != first_kind));
    let mut out = String::new();
    for (k, slot) in children.iter().enumerate() {
        if k > 0 {
            out.push_str(&text[children[k - 1].to..slot.from]);
        }
        let child = order[k];
        out.push_str(&text[child.from..child.to]);
    }
    out
}

/// Each link (right under `<robot>`) whose gathered children interleave,
/// with those children in document order; None if the document cannot be
/// walked to its end.
fn interleaved_links(text: &str) -> Option<Vec<Vec<Child>>> {
    let mut reader = Reader::from_str(text);
    let mut depth = 0usize;
    let mut in_link = false;
    let mut open: Option<(usize, usize)> = None;
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
                    open = kind_of(e.name().as_ref()).map(|k| (k, at));
                }
                depth += 1;
            }
            Event::Empty(e) => {
                if in_link
                    && depth == 2
                    && let Some(kind) = kind_of(e.name().as_ref())
                {
                    children.push(Child {
                        kind,
                        from: at,
                        to: end,
                    });
                }
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
                    if interleaves(&children) {
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

fn kind_of(name: &[u8]) -> Option<usize> {
    GATHERED.iter().position(|g| g.as_bytes() == name)
}

/// Whether a kind comes in more than one run (`v c v`).
fn interleaves(children: &[Child]) -> bool {
    let runs = children
        .windows(2)
        .filter(|w| w[0].kind != w[1].kind)
        .count()
        + 1;
    let kinds = (0..GATHERED.len())
        .filter(|k| children.iter().any(|c| c.kind == *k))
        .count();
    !children.is_empty() && runs > kinds
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_links_visuals_and_collisions_are_gathered_by_kind() {
        let text = r#"<robot><link name="a"><inertial/><visual name="v1"/><collision name="c1"/>
<visual name="v2"><geometry/></visual><collision name="c2"/></link><link name="b"><visual/><collision/></link></robot>"#;
        let (out, links) = gather(text);
        assert_eq!(links, 1);
        assert_eq!(
            out,
            r#"<robot><link name="a"><inertial/><visual name="v1"/><visual name="v2"><geometry/></visual>
<collision name="c1"/><collision name="c2"/></link><link name="b"><visual/><collision/></link></robot>"#
        );
        let grouped = r#"<robot><link name="a"><collision/><collision/><visual/></link></robot>"#;
        assert!(matches!(gather(grouped), (Cow::Borrowed(_), 0)));
    }
}
