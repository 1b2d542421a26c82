//! Each data message lists its fields once, where it is defined
//! ([`data_message!`]); the log's JSON codec, its schema and any other
//! per-field view are made from that list by visiting it
//! ([`MessageFields::visit`]) or filling it ([`MessageFields::decode`]).

use crate::{Header, Joints};

/// One field's value, as a reader of the message sees it. Per-joint arrays
/// are trimmed to the message's `dof`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FieldRef<'a> {
    /// Unsigned 32-bit integer.
    U32(u32),
    /// Unsigned integer.
    U(u64),
    /// Signed integer.
    I(i64),
    /// Real number.
    F(f64),
    /// Per-joint reals.
    J(&'a [f64]),
    /// Reals that are not per joint (an external controller's own
    /// diagnostics), trimmed to the message's `count`.
    V(&'a [f64]),
}

/// Why a field could not be taken from a [`FieldSource`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    /// The source lacks the field.
    #[error("field '{0}' is missing")]
    Missing(String),
    /// The field holds another kind of value.
    #[error("field '{field}' is not {want}")]
    NotA {
        /// The field.
        field: String,
        /// What it must be ("an unsigned integer", "an array", …).
        want: &'static str,
    },
    /// The value does not fit the field's type.
    #[error("field '{0}' is out of range")]
    OutOfRange(String),
    /// A per-joint array longer than [`crate::MAX_DOF`].
    #[error("field '{field}' has {len} entries (at most {})", crate::MAX_DOF)]
    TooLong {
        /// The field.
        field: String,
        /// Its entries.
        len: usize,
    },
}

impl FieldError {
    /// `field` is not `want`.
    pub fn not_a(field: &str, want: &'static str) -> Self {
        Self::NotA {
            field: field.to_string(),
            want,
        }
    }
}

/// Where [`MessageFields::decode`] takes each field from (a parsed JSON
/// object, say); an error says which field is missing or wrong.
pub trait FieldSource {
    /// An unsigned integer.
    fn u(&self, name: &str) -> Result<u64, FieldError>;
    /// A u32.
    fn u32(&self, name: &str) -> Result<u32, FieldError>;
    /// A signed integer.
    fn i(&self, name: &str) -> Result<i64, FieldError>;
    /// A real.
    fn f(&self, name: &str) -> Result<f64, FieldError>;
    /// A per-joint array.
    fn j(&self, name: &str) -> Result<Joints, FieldError>;
    /// Whether the source has the field at all: a field added in a later
    /// version of its message takes its documented default when an older
    /// log lacks it.
    fn has(&self, name: &str) -> bool;
}

/// A message whose fields can be listed and filled by name.
pub trait MessageFields: Sized + Copy + Default {
    /// The message's header.
    fn header(&self) -> Header;
    /// Calls `f` with every field but the header and padding, in order.
    fn visit(&self, f: &mut dyn FnMut(&'static str, FieldRef<'_>));
    /// [`MessageFields::visit`] with `f` known at compile time, so that a
    /// hot encoder (the log's CDR) is inlined field by field.
    fn each_field<F: FnMut(&'static str, FieldRef<'_>)>(&self, f: F);
    /// The message from `header` and each field of `source`.
    fn decode(header: Header, source: &dyn FieldSource) -> Result<Self, FieldError>;
}

/// Defines a wire message (`#[repr(C)]`, `Copy`, zero-copy) and its field
/// list in one place: the log's codec ([`MessageFields`]) and its memory
/// layout for other languages ([`crate::WireLayout`]) come from it. Doc
/// comments come first, then `#[type_name("…")]`. Each field names its kind: `U32`, `U64`, `I64`,
/// `F64`, `J` (per-joint, trimmed to `dof`), `V` (reals trimmed to `count`) or `Pad` (layout only). A field
/// added after logs of its message were written ends in `| default`: the
/// value a log without it decodes to (every other field is required).
#[macro_export]
macro_rules! data_message {
    (
        $(#[doc = $doc:literal])*
        #[type_name($type_name:literal)]
        pub struct $name:ident {
            $(#[$hmeta:meta])* header: Header,
            $( $(#[$fmeta:meta])* $field:ident : $ty:ty => $kind:ident $(| $default:expr)? ),* $(,)?
        }
    ) => {
        #[repr(C)]
        #[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
        $(#[doc = $doc])*
        #[type_name($type_name)]
        pub struct $name {
            $(#[$hmeta])*
            pub header: $crate::Header,
            $( $(#[$fmeta])* pub $field: $ty, )*
        }

        impl $crate::WireLayout for $name {
            const TYPE_NAME: &'static str = $type_name;
            fn fields() -> Vec<$crate::FieldLayout> {
                vec![
                    $crate::FieldLayout::of::<$crate::Header>(
                        "header",
                        ::core::mem::offset_of!($name, header),
                    ),
                    $( $crate::FieldLayout::of::<$ty>(
                        stringify!($field),
                        ::core::mem::offset_of!($name, $field),
                    ), )*
                ]
            }
        }

        impl $crate::MessageFields for $name {
            fn header(&self) -> $crate::Header {
                self.header
            }
            fn visit(&self, f: &mut dyn FnMut(&'static str, $crate::FieldRef<'_>)) {
                $( $crate::field_visit!($kind, self, $field, f); )*
            }
            #[inline]
            fn each_field<F: FnMut(&'static str, $crate::FieldRef<'_>)>(&self, mut f: F) {
                $( $crate::field_visit!($kind, self, $field, f); )*
            }
            fn decode(
                header: $crate::Header,
                source: &dyn $crate::FieldSource,
            ) -> Result<Self, $crate::FieldError> {
                let mut m = Self { header, ..Self::default() };
                $( $crate::field_decode!($kind, m, $field, source $(, $default)?); )*
                Ok(m)
            }
        }
    };
}

/// One field of [`data_message!`] handed to a visitor.
#[doc(hidden)]
#[macro_export]
macro_rules! field_visit {
    (U32, $s:ident, $f:ident, $out:ident) => {
        $out(stringify!($f), $crate::FieldRef::U32($s.$f))
    };
    (U64, $s:ident, $f:ident, $out:ident) => {
        $out(stringify!($f), $crate::FieldRef::U($s.$f))
    };
    (I64, $s:ident, $f:ident, $out:ident) => {
        $out(stringify!($f), $crate::FieldRef::I($s.$f))
    };
    (F64, $s:ident, $f:ident, $out:ident) => {
        $out(stringify!($f), $crate::FieldRef::F($s.$f))
    };
    (J, $s:ident, $f:ident, $out:ident) => {
        $out(
            stringify!($f),
            $crate::FieldRef::J(&$s.$f[..($s.dof as usize).min($crate::MAX_DOF)]),
        )
    };
    (V, $s:ident, $f:ident, $out:ident) => {
        $out(
            stringify!($f),
            $crate::FieldRef::V(&$s.$f[..($s.count as usize).min($crate::MAX_DOF)]),
        )
    };
    (Pad, $s:ident, $f:ident, $out:ident) => {};
}

/// One field of [`data_message!`] taken from a source.
#[doc(hidden)]
#[macro_export]
macro_rules! field_decode {
    (U32, $m:ident, $f:ident, $s:ident) => {
        $m.$f = $s.u32(stringify!($f))?
    };
    (U64, $m:ident, $f:ident, $s:ident) => {
        $m.$f = $s.u(stringify!($f))?
    };
    (I64, $m:ident, $f:ident, $s:ident) => {
        $m.$f = $s.i(stringify!($f))?
    };
    (F64, $m:ident, $f:ident, $s:ident) => {
        $m.$f = $s.f(stringify!($f))?
    };
    (J, $m:ident, $f:ident, $s:ident) => {
        $m.$f = $s.j(stringify!($f))?
    };
    (V, $m:ident, $f:ident, $s:ident) => {
        $m.$f = $s.j(stringify!($f))?
    };
    (Pad, $m:ident, $f:ident, $s:ident) => {};
    ($kind:ident, $m:ident, $f:ident, $s:ident, $default:expr) => {
        if $s.has(stringify!($f)) {
            $crate::field_decode!($kind, $m, $f, $s)
        } else {
            $m.$f = $default
        }
    };
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;
    use crate::{ControllerDiagnostics, JointState, MAX_DOF, Timing};

    /// Reads fields back from what a visit produced.
    struct Echo(Vec<(&'static str, Vec<f64>)>);

    impl FieldSource for Echo {
        fn u(&self, name: &str) -> Result<u64, FieldError> {
            Ok(self.f(name)? as u64)
        }
        fn u32(&self, name: &str) -> Result<u32, FieldError> {
            Ok(self.f(name)? as u32)
        }
        fn i(&self, name: &str) -> Result<i64, FieldError> {
            Ok(self.f(name)? as i64)
        }
        fn f(&self, name: &str) -> Result<f64, FieldError> {
            self.0
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| v[0])
                .ok_or(FieldError::Missing(name.into()))
        }
        fn j(&self, name: &str) -> Result<Joints, FieldError> {
            let v = &self
                .0
                .iter()
                .find(|(n, _)| *n == name)
                .ok_or(FieldError::Missing(name.into()))?
                .1;
            Ok(crate::joints(v))
        }
        fn has(&self, name: &str) -> bool {
            self.0.iter().any(|(n, _)| *n == name)
        }
    }

    fn echo<M: MessageFields>(m: &M) -> Echo {
        let mut out = Vec::new();
        m.visit(&mut |name, f| {
            let v = match f {
                FieldRef::U32(x) => vec![x as f64],
                FieldRef::U(x) => vec![x as f64],
                FieldRef::I(x) => vec![x as f64],
                FieldRef::F(x) => vec![x],
                FieldRef::J(xs) | FieldRef::V(xs) => xs.to_vec(),
            };
            out.push((name, v));
        });
        Echo(out)
    }

    #[test]
    fn every_field_but_padding_is_listed_once_and_decodes_back() {
        let mut s = JointState {
            dof: 3,
            flags: 1,
            effects: 5,
            deadline_misses: 9,
            ..JointState::default()
        };
        s.q[2] = 0.5;
        s.disturbance[0] = -1.25;
        let e = echo(&s);
        let names: Vec<&str> = e.0.iter().map(|(n, _)| *n).collect();
        // Every field the layout has but the header and the padding.
        let declared = <JointState as crate::WireLayout>::fields()
            .iter()
            .filter(|f| f.name != "header" && f.name != "reserved")
            .count();
        assert_eq!(names.len(), declared, "{names:?}");
        assert!(!names.contains(&"reserved") && !names.contains(&"header"));
        assert_eq!(e.0[2].1.len(), 3, "per-joint fields are trimmed to dof");
        assert_eq!(JointState::decode(s.header, &e).unwrap(), s);
        let d = ControllerDiagnostics {
            dof: MAX_DOF as u32,
            gamma: 0.25,
            ..ControllerDiagnostics::default()
        };
        assert_eq!(
            ControllerDiagnostics::decode(d.header, &echo(&d)).unwrap(),
            d
        );
        let t = Timing {
            round_trip_ns: -1,
            ..Timing::default()
        };
        assert_eq!(Timing::decode(t.header, &echo(&t)).unwrap(), t);
    }
}
