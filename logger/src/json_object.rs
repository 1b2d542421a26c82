//! A logged message's JSON object, read straight from its text.
//!
//! Reading a log is mostly reading JSON: building a `serde_json::Value` for
//! every message (a map of owned keys, one allocation per value) was a third
//! of `replay`'s time. This keeps only what a message's fields need: each
//! key (borrowed from the text when it has no escapes) with its number,
//! null or array of numbers. The meaning is `Value`'s: the last of repeated
//! keys wins, integers are read as `as_u64`/`as_i64` would, `null` is NaN.

use std::borrow::Cow;
use std::fmt;

use serde::Deserializer as _;
use serde::de::{self, DeserializeSeed, IgnoredAny, MapAccess, SeqAccess, Visitor};
use wire::{FieldError, FieldSource, Joints, MAX_DOF, joints};

use crate::decode_error::DecodeError;

/// One value of a field, as far as a message's fields care.
#[derive(Debug, Clone, PartialEq)]
enum Raw {
    U(u64),
    I(i64),
    F(f64),
    Null,
    /// Numbers (NaN for null); `false` when an entry was not a number.
    Array(Vec<f64>, bool),
    /// A string, a boolean or an object: no field takes one.
    Other,
}

/// The top-level object of one message: its keys in text order.
#[derive(Debug)]
pub struct JsonObject<'a>(Vec<(Cow<'a, str>, Raw)>);

impl<'a> JsonObject<'a> {
    /// The object in `text`: an error when the text is not JSON or not an
    /// object.
    pub fn parse(text: &'a [u8]) -> Result<Self, DecodeError> {
        let mut de = serde_json::Deserializer::from_slice(text);
        let fields = (&mut de).deserialize_any(TopLevel).map_err(not_json)?;
        de.end().map_err(not_json)?;
        fields.map(JsonObject).ok_or(DecodeError::NotJsonObject)
    }

    /// Checks that `text` is JSON, of any shape (for messages nothing
    /// decodes further).
    pub fn check(text: &[u8]) -> Result<(), DecodeError> {
        serde_json::from_slice::<IgnoredAny>(text)
            .map(|_| ())
            .map_err(not_json)
    }

    fn get(&self, k: &str) -> Result<&Raw, FieldError> {
        self.0
            .iter()
            .rev()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v)
            .ok_or_else(|| FieldError::Missing(k.into()))
    }
}

impl FieldSource for JsonObject<'_> {
    fn has(&self, k: &str) -> bool {
        self.0.iter().any(|(key, _)| key == k)
    }
    fn u(&self, k: &str) -> Result<u64, FieldError> {
        match self.get(k)? {
            Raw::U(x) => Ok(*x),
            _ => Err(FieldError::not_a(k, "an unsigned integer")),
        }
    }
    fn u32(&self, k: &str) -> Result<u32, FieldError> {
        u32::try_from(self.u(k)?).map_err(|_| FieldError::OutOfRange(k.into()))
    }
    fn i(&self, k: &str) -> Result<i64, FieldError> {
        match self.get(k)? {
            Raw::U(x) => i64::try_from(*x).ok(),
            Raw::I(x) => Some(*x),
            _ => None,
        }
        .ok_or_else(|| FieldError::not_a(k, "an integer"))
    }
    fn f(&self, k: &str) -> Result<f64, FieldError> {
        match self.get(k)? {
            Raw::U(x) => Ok(*x as f64),
            Raw::I(x) => Ok(*x as f64),
            Raw::F(x) => Ok(*x),
            Raw::Null => Ok(f64::NAN),
            _ => Err(FieldError::not_a(k, "a number")),
        }
    }
    fn j(&self, k: &str) -> Result<Joints, FieldError> {
        let Raw::Array(xs, all_numbers) = self.get(k)? else {
            return Err(FieldError::not_a(k, "an array"));
        };
        if xs.len() > MAX_DOF {
            return Err(FieldError::TooLong {
                field: k.into(),
                len: xs.len(),
            });
        }
        if !all_numbers {
            return Err(FieldError::not_a(k, "an array of numbers"));
        }
        Ok(joints(xs))
    }
}

fn not_json(e: serde_json::Error) -> DecodeError {
    DecodeError::NotJson(e.to_string())
}

/// The whole text: `Some(fields)` for an object, `None` for anything else.
struct TopLevel;

type Fields<'a> = Vec<(Cow<'a, str>, Raw)>;

impl<'de> Visitor<'de> for TopLevel {
    type Value = Option<Fields<'de>>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON object")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut fields = Vec::with_capacity(16);
        while let Some(key) = map.next_key::<Key<'de>>()? {
            fields.push((key.0, map.next_value_seed(RawSeed)?));
        }
        Ok(Some(fields))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        IgnoredAny.visit_seq(seq).map(|_| None)
    }

    fn visit_bool<E: de::Error>(self, _: bool) -> Result<Self::Value, E> {
        Ok(None)
    }
    fn visit_i64<E: de::Error>(self, _: i64) -> Result<Self::Value, E> {
        Ok(None)
    }
    fn visit_u64<E: de::Error>(self, _: u64) -> Result<Self::Value, E> {
        Ok(None)
    }
    fn visit_f64<E: de::Error>(self, _: f64) -> Result<Self::Value, E> {
        Ok(None)
    }
    fn visit_str<E: de::Error>(self, _: &str) -> Result<Self::Value, E> {
        Ok(None)
    }
    fn visit_unit<E: de::Error>(self) -> Result<Self::Value, E> {
        Ok(None)
    }
}

/// A key, borrowed from the text unless it holds escapes.
struct Key<'a>(Cow<'a, str>);

impl<'de> de::Deserialize<'de> for Key<'de> {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct KeyVisitor;
        impl<'de> Visitor<'de> for KeyVisitor {
            type Value = Key<'de>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a key")
            }
            fn visit_borrowed_str<E: de::Error>(self, s: &'de str) -> Result<Self::Value, E> {
                Ok(Key(Cow::Borrowed(s)))
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<Self::Value, E> {
                Ok(Key(Cow::Owned(s.to_owned())))
            }
        }
        d.deserialize_str(KeyVisitor)
    }
}

/// A field's value.
struct RawSeed;

impl<'de> DeserializeSeed<'de> for RawSeed {
    type Value = Raw;
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<Raw, D::Error> {
        d.deserialize_any(RawVisitor)
    }
}

struct RawVisitor;

impl<'de> Visitor<'de> for RawVisitor {
    type Value = Raw;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_u64<E: de::Error>(self, x: u64) -> Result<Raw, E> {
        Ok(Raw::U(x))
    }
    fn visit_i64<E: de::Error>(self, x: i64) -> Result<Raw, E> {
        // serde_json hands non-negative integers to visit_u64.
        Ok(Raw::I(x))
    }
    fn visit_f64<E: de::Error>(self, x: f64) -> Result<Raw, E> {
        Ok(Raw::F(x))
    }
    fn visit_unit<E: de::Error>(self) -> Result<Raw, E> {
        Ok(Raw::Null)
    }
    fn visit_bool<E: de::Error>(self, _: bool) -> Result<Raw, E> {
        Ok(Raw::Other)
    }
    fn visit_str<E: de::Error>(self, _: &str) -> Result<Raw, E> {
        Ok(Raw::Other)
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Raw, A::Error> {
        IgnoredAny.visit_map(map).map(|_| Raw::Other)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Raw, A::Error> {
        let mut xs = Vec::with_capacity(seq.size_hint().unwrap_or(MAX_DOF));
        let mut all_numbers = true;
        while let Some(x) = seq.next_element_seed(RawSeed)? {
            xs.push(match x {
                Raw::U(x) => x as f64,
                Raw::I(x) => x as f64,
                Raw::F(x) => x,
                Raw::Null => f64::NAN,
                Raw::Array(..) | Raw::Other => {
                    all_numbers = false;
                    f64::NAN
                }
            });
        }
        Ok(Raw::Array(xs, all_numbers))
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;
    use serde_json::{Value, json};

    /// What `Value` made of the same text (the reader's old way), to hold
    /// this reader to the same meaning.
    fn via_value(v: &Value, k: &str) -> (Option<u64>, Option<i64>, Option<f64>) {
        let x = &v[k];
        let f = if x.is_null() {
            Some(f64::NAN)
        } else {
            x.as_f64()
        };
        (x.as_u64(), x.as_i64(), f)
    }

    #[test]
    fn numbers_read_as_value_reads_them() {
        let text = br#"{"a":3,"b":-4,"c":2.5,"d":null,"e":18446744073709551615,"f":1.0,
            "g":-9223372036854775808,"i":"x","j":true,"k":{"x":[1]}}"#;
        let v: Value = serde_json::from_slice(text).unwrap();
        let o = JsonObject::parse(text).unwrap();
        for k in ["a", "b", "c", "d", "e", "f", "g", "i", "j", "k"] {
            let (u, i, f) = via_value(&v, k);
            assert_eq!(o.u(k).ok(), u, "{k}");
            assert_eq!(o.i(k).ok(), i, "{k}");
            assert_eq!(o.f(k).ok().map(f64::to_bits), f.map(f64::to_bits), "{k}");
        }
    }

    #[test]
    fn arrays_keys_and_errors() {
        let o = JsonObject::parse(br#"{"q":[1,null,-2.5],"q":[0.5],"r":[1,"x"],"s":3}"#).unwrap();
        // The last of repeated keys, as Value keeps it.
        assert_eq!(o.j("q").unwrap()[0], 0.5);
        assert_eq!(
            o.j("r").unwrap_err().to_string(),
            "field 'r' is not an array of numbers"
        );
        assert_eq!(
            o.j("s").unwrap_err().to_string(),
            "field 's' is not an array"
        );
        assert_eq!(o.j("t").unwrap_err().to_string(), "field 't' is missing");
        let long = json!({ "q": vec![0.0; MAX_DOF + 1] }).to_string();
        assert!(
            JsonObject::parse(long.as_bytes())
                .unwrap()
                .j("q")
                .unwrap_err()
                .to_string()
                .contains("entries (at most")
        );
        // Escaped keys are read too.
        let o = JsonObject::parse(br#"{"\u0071":[2]}"#).unwrap();
        assert_eq!(o.j("q").unwrap()[0], 2.0);
    }

    #[test]
    fn not_json_and_not_an_object_are_named() {
        let not_json = |e: DecodeError| matches!(e, DecodeError::NotJson(_));
        assert!(not_json(JsonObject::parse(b"{\"a\":").unwrap_err()));
        assert!(not_json(JsonObject::parse(b"{} x").unwrap_err()));
        assert!(not_json(JsonObject::check(b"[1,").unwrap_err()));
        for text in [&b"[1,{}]"[..], b"3", b"null", b"\"s\"", b"true"] {
            JsonObject::check(text).unwrap();
            assert_eq!(
                JsonObject::parse(text).unwrap_err(),
                DecodeError::NotJsonObject
            );
        }
    }
}
