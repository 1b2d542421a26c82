//! Each wire type's memory layout as data: field names, field types and
//! byte offsets, read off the Rust definitions by [`crate::data_message!`].
//! Bindings for other languages (the Python package's ctypes structures)
//! are generated from this, so they cannot drift from the Rust types.

use crate::{Header, Joints, MAX_DOF};

/// A field's type, as another language must lay it out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldType {
    /// `u32`.
    U32,
    /// `u64`.
    U64,
    /// `i64`.
    I64,
    /// `f64`.
    F64,
    /// `[f64; MAX_DOF]`.
    Joints,
    /// The common [`Header`].
    Header,
}

/// A type a wire field may have.
pub trait WireField {
    /// How it is laid out.
    const TYPE: FieldType;
}

impl WireField for u32 {
    const TYPE: FieldType = FieldType::U32;
}
impl WireField for u64 {
    const TYPE: FieldType = FieldType::U64;
}
impl WireField for i64 {
    const TYPE: FieldType = FieldType::I64;
}
impl WireField for f64 {
    const TYPE: FieldType = FieldType::F64;
}
impl WireField for Joints {
    const TYPE: FieldType = FieldType::Joints;
}
impl WireField for Header {
    const TYPE: FieldType = FieldType::Header;
}

/// One field: name, type and byte offset in its struct.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldLayout {
    /// The Rust field name.
    pub name: &'static str,
    /// Its type.
    pub ty: FieldType,
    /// Its offset in bytes.
    pub offset: usize,
}

impl FieldLayout {
    /// The field `name` of type `T` at `offset`.
    pub fn of<T: WireField>(name: &'static str, offset: usize) -> Self {
        Self {
            name,
            ty: T::TYPE,
            offset,
        }
    }
}

/// A `#[repr(C)]` wire type whose layout can be listed.
pub trait WireLayout: Sized {
    /// The iceoryx2 type name (versioned): a peer in another language must
    /// announce exactly this.
    const TYPE_NAME: &'static str;
    /// Every field, padding included, in memory order.
    fn fields() -> Vec<FieldLayout>;
}

/// The layout of one type, for a generator.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeLayout {
    /// The Rust type name (`JointState`).
    pub name: &'static str,
    /// The iceoryx2 type name (`""` for [`Header`], which is never sent alone).
    pub type_name: &'static str,
    /// `size_of`.
    pub size: usize,
    /// `align_of`.
    pub align: usize,
    /// Every field in memory order.
    pub fields: Vec<FieldLayout>,
}

impl TypeLayout {
    fn of<T: WireLayout>(name: &'static str) -> Self {
        Self {
            name,
            type_name: T::TYPE_NAME,
            size: std::mem::size_of::<T>(),
            align: std::mem::align_of::<T>(),
            fields: T::fields(),
        }
    }
}

/// [`Header`] and every message, in dependency order (the header first).
pub fn all_layouts() -> Vec<TypeLayout> {
    vec![TypeLayout {
        name: "Header",
        type_name: "",
        size: std::mem::size_of::<Header>(),
        align: std::mem::align_of::<Header>(),
        fields: vec![
            FieldLayout::of::<u64>("seq", std::mem::offset_of!(Header, seq)),
            FieldLayout::of::<u64>("t_ns", std::mem::offset_of!(Header, t_ns)),
            FieldLayout::of::<u64>("wall_ns", std::mem::offset_of!(Header, wall_ns)),
        ],
    }]
    .into_iter()
    .chain(message_layouts())
    .collect()
}

/// Every message's layout: the logged ones, then the bus's own, from the
/// wire's two lists of them.
fn message_layouts() -> Vec<TypeLayout> {
    macro_rules! logged {
        ($($ty:ident => $topic:ident, $channel:literal, $schema:literal;)*) => {
            vec![$(TypeLayout::of::<crate::$ty>(stringify!($ty)),)*]
        };
    }
    macro_rules! unlogged {
        ($($ty:ident => $topic:ident, $schema:literal;)*) => {
            vec![$(TypeLayout::of::<crate::$ty>(stringify!($ty)),)*]
        };
    }
    let mut all = crate::logged_messages!(logged);
    all.extend(crate::unlogged_messages!(unlogged));
    all
}

/// Size in bytes of a field type.
pub fn field_size(ty: FieldType) -> usize {
    match ty {
        FieldType::U32 => 4,
        FieldType::U64 | FieldType::I64 | FieldType::F64 => 8,
        FieldType::Joints => 8 * MAX_DOF,
        FieldType::Header => std::mem::size_of::<Header>(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_tile_each_struct_without_holes() {
        for t in all_layouts() {
            let mut end = 0;
            for f in &t.fields {
                assert_eq!(f.offset, end, "{}.{} leaves a hole", t.name, f.name);
                end += field_size(f.ty);
            }
            assert_eq!(end, t.size, "{} has trailing padding", t.name);
        }
    }

    #[test]
    fn type_names_are_the_ones_iceoryx2_sees() {
        let names: Vec<&str> = all_layouts().iter().map(|t| t.type_name).collect();
        assert!(names.contains(&<crate::JointState as WireLayout>::TYPE_NAME));
        assert!(names.contains(&<crate::Control as WireLayout>::TYPE_NAME));
        assert!(
            names
                .iter()
                .all(|n| n.is_empty() || n.starts_with("testbed."))
        );
        // The derive and the layout read the same literal.
        // SAFETY: type_name only returns a static string.
        #[allow(
            unsafe_code,
            reason = "iceoryx2's type_name is unsafe to call; it is what the test checks"
        )]
        let derived = unsafe { <crate::Command as iceoryx2::prelude::ZeroCopySend>::type_name() };
        assert_eq!(derived, <crate::Command as WireLayout>::TYPE_NAME);
    }
}
