//! A testbed message back from its CDR, read by a schema: the one its log
//! stores ([`decode_by`]) or the one this build writes ([`decode`]). Each
//! field is read as the schema says and handed to the message by name
//! ([`wire::MessageFields::decode`]).

use wire::{FieldError, FieldSource, Header, Joints, MAX_DOF, joints};

use crate::LogMessage;
use crate::cdr::CdrReader;
use crate::decode_error::DecodeError;
use crate::msg_schema::{MsgSchema, SchemaKind};
use crate::ros2::msg_schema;

/// One field read from CDR.
enum Val {
    U(u64),
    I(i64),
    F(f64),
    J(Box<Joints>),
}

/// A message's fields read from its CDR, in the order its schema gives,
/// for [`wire::MessageFields::decode`].
struct CdrFields<'s>(Vec<(&'s str, Val)>);

impl CdrFields<'_> {
    fn get(&self, k: &str) -> Result<&Val, FieldError> {
        self.0
            .iter()
            .find(|(n, _)| *n == k)
            .map(|(_, v)| v)
            .ok_or_else(|| FieldError::Missing(k.into()))
    }
}

impl FieldSource for CdrFields<'_> {
    fn u(&self, k: &str) -> Result<u64, FieldError> {
        match self.get(k)? {
            Val::U(x) => Ok(*x),
            _ => Err(FieldError::not_a(k, "an unsigned integer")),
        }
    }
    fn u32(&self, k: &str) -> Result<u32, FieldError> {
        u32::try_from(self.u(k)?).map_err(|_| FieldError::OutOfRange(k.into()))
    }
    fn i(&self, k: &str) -> Result<i64, FieldError> {
        match self.get(k)? {
            Val::I(x) => Ok(*x),
            _ => Err(FieldError::not_a(k, "an integer")),
        }
    }
    fn f(&self, k: &str) -> Result<f64, FieldError> {
        match self.get(k)? {
            Val::F(x) => Ok(*x),
            _ => Err(FieldError::not_a(k, "a number")),
        }
    }
    fn j(&self, k: &str) -> Result<Joints, FieldError> {
        match self.get(k)? {
            Val::J(x) => Ok(**x),
            _ => Err(FieldError::not_a(k, "an array")),
        }
    }
    fn has(&self, k: &str) -> bool {
        self.get(k).is_ok()
    }
}

/// The message back from its CDR, written with this build's own schema
/// for `M` (a log is read by the schema it stores: [`decode_by`]).
pub fn decode<M: LogMessage>(data: &[u8]) -> Result<M, DecodeError> {
    let schema = msg_schema::<M>()?;
    decode_by(&schema, data)
}

/// The message back from CDR written with `schema`: each field is read as
/// the schema says and handed to `M` by name, so a field `M` has and the
/// schema lacks takes its declared default for older logs (or is missing),
/// and a field the schema has and `M` lacks is read past.
pub fn decode_by<M: LogMessage>(schema: &MsgSchema, data: &[u8]) -> Result<M, DecodeError> {
    let mut r = CdrReader::new(data)?;
    let (mut stamp, mut seq, mut wall_ns) = (None, None, None);
    let mut fields = Vec::with_capacity(schema.fields.len());
    let mut xs = Vec::with_capacity(MAX_DOF);
    for f in &schema.fields {
        let name = f.name.as_str();
        let v = match f.kind {
            SchemaKind::Header => {
                stamp = Some(r.time(name)?);
                r.string(name)?;
                continue;
            }
            SchemaKind::U32 => Val::U(r.u32(name)?.into()),
            SchemaKind::U64 => Val::U(r.u64(name)?),
            SchemaKind::I64 => Val::I(r.i64(name)?),
            SchemaKind::F64 => Val::F(r.f64(name)?),
            SchemaKind::F64s => {
                r.f64s(name, &mut xs)?;
                if xs.len() > MAX_DOF {
                    return Err(DecodeError::TooManyEntries {
                        field: name.to_string(),
                        entries: xs.len(),
                        max: MAX_DOF,
                    });
                }
                Val::J(Box::new(joints(&xs)))
            }
        };
        match (name, v) {
            ("seq", Val::U(x)) => seq = Some(x),
            ("wall_ns", Val::U(x)) => wall_ns = Some(x),
            (name, v) => fields.push((name, v)),
        }
    }
    if !r.at_end() {
        return Err(DecodeError::LongerThanSchema {
            schema: schema.name.to_string(),
        });
    }
    let need = |v: Option<u64>, field: &'static str| {
        v.ok_or_else(|| DecodeError::SchemaLacks {
            schema: schema.name.to_string(),
            field,
        })
    };
    let header = Header {
        seq: need(seq, "uint64 seq")?,
        t_ns: need(stamp, "std_msgs/Header header")?,
        wall_ns: need(wall_ns, "uint64 wall_ns")?,
    };
    M::decode(header, &CdrFields(fields)).map_err(DecodeError::from)
}
