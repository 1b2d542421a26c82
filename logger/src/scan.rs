//! A bounds check of an MCAP file's record structure before the `mcap`
//! crate reads it: a length field that runs past the end of the file (a
//! log cut short, or a flipped byte) would make that reader panic or ask
//! for gigabytes. The scan finds where the file stops being sound, so the
//! reader is given only the part before it.

/// A chunk this large uncompressed is not one testbed wrote (its chunks
/// are a few MB at most): a damaged size field.
pub const MAX_CHUNK_BYTES: u64 = 256 << 20;

pub(crate) const OP_FOOTER: u8 = 0x02;
pub(crate) const OP_CHUNK: u8 = 0x06;

/// How far the records of `buf` (a whole MCAP file) are sound: the byte
/// offset where reading must stop, and why when that is before the end.
pub fn sound_prefix(buf: &[u8]) -> (usize, Option<String>) {
    let mut at = mcap::MAGIC.len();
    while at < buf.len() {
        let rest = buf.len() - at;
        if rest < 9 {
            return (
                at,
                Some(format!("the file ends inside a record header at byte {at}")),
            );
        }
        let op = buf[at];
        let len = u64::from_le_bytes(le8(&buf[at + 1..at + 9]));
        if len > (rest - 9) as u64 {
            return (
                at,
                Some(format!(
                    "the record at byte {at} (opcode {op:#04x}) claims {len} bytes but {} remain: \
                     the file is cut short or damaged",
                    rest - 9
                )),
            );
        }
        let body = &buf[at + 9..at + 9 + len as usize];
        if op == OP_CHUNK
            && let Some(why) = check_chunk(body)
        {
            return (
                at,
                Some(format!("the chunk at byte {at} is damaged: {why}")),
            );
        }
        at += 9 + len as usize;
        if op == OP_FOOTER {
            break;
        }
    }
    (buf.len(), None)
}

/// The body of the first top-level record of opcode `op` in `buf` (a
/// soundly framed MCAP file, as [`sound_prefix`] cuts it).
pub(crate) fn find_record(buf: &[u8], op: u8) -> Option<&[u8]> {
    locate(buf, op).map(|(start, end)| &buf[start..end])
}

/// Where the first top-level record of opcode `op` in `buf` has its body:
/// (start, end) offsets.
pub(crate) fn locate(buf: &[u8], op: u8) -> Option<(usize, usize)> {
    let mut at = mcap::MAGIC.len();
    while at + 9 <= buf.len() {
        let len = usize::try_from(u64::from_le_bytes(le8(&buf[at + 1..at + 9]))).ok()?;
        let end = (at + 9).checked_add(len)?;
        buf.get(at + 9..end)?;
        if buf[at] == op {
            return Some((at + 9, end));
        }
        at = end;
    }
    None
}

/// A chunk's sizes agree with its body and are plausible.
pub(crate) fn check_chunk(body: &[u8]) -> Option<String> {
    // start, end, uncompressed size (u64 each), crc (u32), compression (u32 length + text).
    if body.len() < 32 {
        return Some("shorter than its fixed fields".into());
    }
    let uncompressed = u64::from_le_bytes(le8(&body[16..24]));
    if uncompressed > MAX_CHUNK_BYTES {
        return Some(format!(
            "it claims {uncompressed} bytes uncompressed (at most {MAX_CHUNK_BYTES})"
        ));
    }
    let name_len = u32::from_le_bytes([body[28], body[29], body[30], body[31]]) as usize;
    let after_name = 32usize.checked_add(name_len)?;
    if after_name + 8 > body.len() {
        return Some(format!(
            "its compression name of {name_len} bytes runs past it"
        ));
    }
    let records = u64::from_le_bytes(le8(&body[after_name..after_name + 8]));
    if records > (body.len() - after_name - 8) as u64 {
        return Some(format!(
            "its records claim {records} bytes, more than it holds"
        ));
    }
    None
}

fn le8(b: &[u8]) -> [u8; 8] {
    let mut out = [0u8; 8];
    out.copy_from_slice(&b[..8]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(op: u8, body: &[u8]) -> Vec<u8> {
        let mut r = vec![op];
        r.extend_from_slice(&(body.len() as u64).to_le_bytes());
        r.extend_from_slice(body);
        r
    }

    #[test]
    fn lengths_past_the_end_and_huge_chunks_stop_the_read() {
        let mut f = mcap::MAGIC.to_vec();
        f.extend(record(0x01, b"header"));
        let whole = f.len();
        assert_eq!(sound_prefix(&f), (whole, None));
        // A header claiming u64::MAX bytes.
        let mut bad = mcap::MAGIC.to_vec();
        bad.push(0x01);
        bad.extend_from_slice(&u64::MAX.to_le_bytes());
        let (end, why) = sound_prefix(&bad);
        assert_eq!(end, 8);
        assert!(why.unwrap().contains("claims 18446744073709551615 bytes"));
        // A chunk asking for 4.28 GB uncompressed.
        let mut body = vec![0u8; 16];
        body.extend_from_slice(&4_280_000_000u64.to_le_bytes());
        body.extend_from_slice(&[0; 4]);
        body.extend_from_slice(&0u32.to_le_bytes());
        body.extend_from_slice(&0u64.to_le_bytes());
        f.extend(record(OP_CHUNK, &body));
        let (end, why) = sound_prefix(&f);
        assert_eq!(end, whole);
        assert!(why.unwrap().contains("4280000000 bytes uncompressed"));
    }
}
