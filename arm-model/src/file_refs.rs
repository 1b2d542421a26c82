//! Attributes `urdf-rs` requires that Pinocchio, MuJoCo and ROS do without:
//! `<texture/>` and `<mesh/>` elements without a `filename` (romeo and icub
//! in example-robot-data have a bare `<texture />` in their materials), a
//! visual's `<material>` without a `name` (a color given in place), and
//! a joint `<limit>` without a `velocity`, an `<axis>` without `xyz`. None
//! of them moves the arm (the testbed uses no joint velocity limit), so the
//! missing attribute is filled before parsing (an empty name; a velocity of
//! 0, read as "none given"; a zero axis, which a fixed joint ignores as
//! urdfdom does, and a moving joint is refused for), and the model notes it.

use std::borrow::Cow;

/// The elements whose attribute may be missing, the attribute, and what
/// it is filled with.
const FILLS: [(&str, &str, &str); 5] = [
    ("texture", "filename", ""),
    ("material", "name", ""),
    ("mesh", "filename", ""),
    ("limit", "velocity", "0"),
    ("axis", "xyz", "0 0 0"),
];

/// `text` with each attribute of [`FILLS`] added to every element without
/// one, and how many were filled per element name.
pub(super) fn fill_missing(text: &str) -> (Cow<'_, str>, Vec<(&'static str, usize)>) {
    let mut inserts = Vec::new();
    let mut filled = Vec::new();
    for (name, attr, value) in FILLS {
        let before = inserts.len();
        inserts.extend(
            missing(text, name, attr)
                .into_iter()
                .map(|at| (at, attr, value)),
        );
        if inserts.len() > before {
            filled.push((name, inserts.len() - before));
        }
    }
    if inserts.is_empty() {
        return (Cow::Borrowed(text), filled);
    }
    inserts.sort_unstable();
    let mut out = String::with_capacity(text.len() + 16 * inserts.len());
    let mut copied = 0;
    for (at, attr, value) in inserts {
        out.push_str(&text[copied..at]);
        out.push_str(&format!(" {attr}=\"{value}\""));
        copied = at;
    }
    out.push_str(&text[copied..]);
    (Cow::Owned(out), filled)
}

/// Offsets just past `<name` of each `name` element with no `attr`.
fn missing(text: &str, name: &str, attr: &str) -> Vec<usize> {
    let open = format!("<{name}");
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(off) = text[from..].find(&open) {
        let after = from + off + open.len();
        from = after;
        // `<meshes>` or `<texture_x>` are other elements.
        let whole_name =
            text[after..].starts_with(|c: char| c.is_ascii_whitespace() || c == '/' || c == '>');
        if whole_name && !has_attr(&text[after..tag_end(text, after)], attr) {
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

/// Whether a tag's attribute text names `attr`.
fn has_attr(attrs: &str, attr: &str) -> bool {
    attrs.match_indices(attr).any(|(i, _)| {
        let before_ok = attrs[..i].ends_with(|c: char| c.is_ascii_whitespace());
        let after = attrs[i + attr.len()..].trim_start();
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

    /// #38 item 4: a `<limit>` without `velocity` (valid for Pinocchio
    /// and MuJoCo) gets velocity 0; one with it, and `<limits>`, are left.
    #[test]
    fn a_limit_without_velocity_gets_one() {
        let text =
            r#"<limit lower="-1" upper="1" effort="5"/><limit effort="1" velocity="2"/><limits/>"#;
        let (out, filled) = fill_missing(text);
        assert_eq!(
            out,
            r#"<limit velocity="0" lower="-1" upper="1" effort="5"/><limit effort="1" velocity="2"/><limits/>"#
        );
        assert_eq!(filled, [("limit", 1)]);
        let urdf = r#"<robot name="t"><link name="base"/><link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5"/></joint></robot>"#;
        let model = crate::ArmModel::from_urdf_str(urdf).unwrap();
        assert_eq!(model.dof(), 1);
        assert!(
            model.notes[0].contains("without a velocity"),
            "{:?}",
            model.notes
        );
    }

    /// An `<axis>` without `xyz` on a fixed joint (amrPioneer3DX's
    /// base_top_joint) is ignored, as urdfdom ignores a fixed joint's axis;
    /// on a moving joint it is a zero axis, refused by name.
    #[test]
    fn an_axis_without_xyz_is_ignored_on_a_fixed_joint_and_refused_on_a_moving_one() {
        let urdf = |kind: &str| {
            format!(
                r#"<robot name="t"><link name="base"/><link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link><joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint><joint name="top" type="{kind}"><parent link="a"/><child link="b"/><axis/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint></robot>"#
            )
        };
        let model = crate::ArmModel::from_urdf_str(&urdf("fixed")).unwrap();
        assert_eq!(model.dof(), 1);
        assert!(
            model
                .notes
                .iter()
                .any(|n| n.contains("<axis> element(s) without an xyz")),
            "{:?}",
            model.notes
        );
        let err = crate::ArmModel::from_urdf_str(&urdf("revolute")).unwrap_err();
        assert!(err.to_string().contains("joint 'top'"), "{err}");
    }
}
