//! The scenario's `seed` in TOML: any u64. TOML's integers are 64-bit
//! signed, so a seed above `i64::MAX` is written (and may be given, in a
//! file, `--set` or Python's `set=`) as a decimal string; every other seed
//! stays a plain integer, so a scenario written before keeps its text.

use serde::de::{self, Visitor};
use serde::{Deserializer, Serializer};

/// Writes `seed` as an integer when TOML can hold it, else as a string.
pub(crate) fn serialize<S: Serializer>(seed: &u64, s: S) -> Result<S::Ok, S::Error> {
    match i64::try_from(*seed) {
        Ok(i) => s.serialize_i64(i),
        Err(_) => s.serialize_str(&seed.to_string()),
    }
}

/// Reads an integer in 0..=u64::MAX, or such an integer as a decimal string.
pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    d.deserialize_any(SeedVisitor)
}

const EXPECTED: &str = "an integer from 0 to 18446744073709551615 (above 9223372036854775807 \
                        as a string, \"18446744073709551615\": TOML's integers are signed)";

struct SeedVisitor;

impl Visitor<'_> for SeedVisitor {
    type Value = u64;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(EXPECTED)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<u64, E> {
        Ok(v)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<u64, E> {
        u64::try_from(v).map_err(|_| E::custom(format!("seed {v}: expected {EXPECTED}")))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<u64, E> {
        let t = v.trim();
        if !t.is_empty()
            && t.bytes().all(|b| b.is_ascii_digit())
            && let Ok(seed) = t.parse::<u64>()
        {
            return Ok(seed);
        }
        let shown: String = v.chars().take(40).collect();
        Err(E::custom(format!("seed {shown:?}: expected {EXPECTED}")))
    }
}
