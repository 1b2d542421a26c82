//! The records of an MCAP file that the testbed reads, in order, chunks
//! unpacked: `mcap`'s own `ChunkFlattener` without its gaps, found by
//! fuzzing. It sets no limit on a record's length, so a damaged length
//! inside a compressed chunk (which the outer scan cannot see) made it
//! allocate whatever the length said (8 × 10¹⁸ bytes); and its parser
//! reserves a string's claimed length (up to 4 GB) before reading it. Here
//! every record is limited, only the records the reader uses are parsed,
//! and their length fields are checked against the record first.

use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};

/// Why the records stop: a record whose framing does not hold, or what
/// the `mcap` reader found (a checksum among them).
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// A length field claims more than the record holds.
    #[error("claims {claims} bytes for its {what} but {left} remain")]
    Overrun {
        /// Bytes claimed.
        claims: u64,
        /// Which field.
        what: &'static str,
        /// Bytes left in the record.
        left: usize,
    },
    /// The record ends inside a length field.
    #[error("ends inside its {0}")]
    Short(&'static str),
    /// A record the reader uses whose fields do not fit it.
    #[error("a record (opcode {opcode:#04x}) {cause}")]
    Record {
        /// The record's opcode.
        opcode: u8,
        /// What does not fit.
        cause: Box<RecordError>,
    },
    /// The `mcap` reader's own error.
    #[error(transparent)]
    Mcap(#[from] mcap::McapError),
}

impl RecordError {
    /// A checksum does not match (a chunk's, the data section's, an
    /// attachment's or the summary's).
    pub fn is_checksum(&self) -> bool {
        use mcap::McapError as E;
        matches!(
            self,
            Self::Mcap(
                E::BadChunkCrc { .. }
                    | E::BadDataCrc { .. }
                    | E::BadAttachmentCrc { .. }
                    | E::BadSummaryCrc { .. }
            )
        )
    }
}

/// No record of a testbed log is longer (the URDF attachment is at most
/// 16 MB, chunks about 1 MB).
pub const MAX_RECORD_BYTES: usize = 64 << 20;

/// Iterates over the records of `buf` (a whole MCAP file, end magic optional).
pub struct Records<'a> {
    buf: &'a [u8],
    reader: LinearReader,
}

impl<'a> Records<'a> {
    /// The records of `buf`.
    pub fn new(buf: &'a [u8]) -> Self {
        Self::with_data_crc(buf, true)
    }

    /// The records of `buf`, one top-level record of a file after the
    /// magic: the data section's checksum covers the whole file, so it is
    /// not checked here (each chunk's is).
    pub fn part(buf: &'a [u8]) -> Self {
        Self::with_data_crc(buf, false)
    }

    fn with_data_crc(buf: &'a [u8], data_crc: bool) -> Self {
        Self {
            buf,
            reader: LinearReader::new_with_options(
                LinearReaderOptions::default()
                    .with_skip_end_magic(true)
                    // A chunk is checked before any of its records is used:
                    // a flipped byte once changed a summary without a word.
                    .with_prevalidate_chunk_crcs(true)
                    .with_validate_data_section_crc(data_crc)
                    .with_record_length_limit(MAX_RECORD_BYTES),
            ),
        }
    }
}

impl<'a> Iterator for Records<'a> {
    type Item = Result<Record<'a>, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        while let Some(event) = self.reader.next_event() {
            match event {
                Ok(LinearReadEvent::ReadRequest(need)) => {
                    let len = need.min(self.buf.len());
                    self.reader.insert(len).copy_from_slice(&self.buf[..len]);
                    self.reader.notify_read(len);
                    self.buf = &self.buf[len..];
                }
                Ok(LinearReadEvent::Record { data, opcode }) => {
                    if !USED.contains(&opcode) {
                        continue;
                    }
                    if let Err(why) = fields_fit(opcode, data) {
                        let cause = Box::new(why);
                        return Some(Err(RecordError::Record { opcode, cause }));
                    }
                    let parsed = mcap::parse_record(opcode, data);
                    return Some(parsed.map(Record::into_owned).map_err(RecordError::from));
                }
                Err(e) => return Some(Err(e.into())),
            }
        }
        None
    }
}

/// Footer, schema, channel, message, attachment, metadata: what the reader
/// uses.
const USED: [u8; 6] = [0x02, 0x03, 0x04, 0x05, 0x09, 0x0c];

/// Walks a record's fields, checking each length against what is left.
struct Fields<'b>(&'b [u8]);

impl Fields<'_> {
    fn skip(&mut self, n: u64, what: &'static str) -> Result<(), RecordError> {
        if n > self.0.len() as u64 {
            return Err(RecordError::Overrun {
                claims: n,
                what,
                left: self.0.len(),
            });
        }
        self.0 = &self.0[n as usize..];
        Ok(())
    }

    fn int(&mut self, bytes: usize, what: &'static str) -> Result<u64, RecordError> {
        if self.0.len() < bytes {
            return Err(RecordError::Short(what));
        }
        let mut b = [0u8; 8];
        b[..bytes].copy_from_slice(&self.0[..bytes]);
        self.0 = &self.0[bytes..];
        Ok(u64::from_le_bytes(b))
    }

    /// A u32-prefixed string or map, or a u64-prefixed byte array.
    fn prefixed(&mut self, prefix: usize, what: &'static str) -> Result<(), RecordError> {
        let n = self.int(prefix, what)?;
        self.skip(n, what)
    }
}

/// Whether every length field of a used record fits inside it.
fn fields_fit(opcode: u8, data: &[u8]) -> Result<(), RecordError> {
    let mut f = Fields(data);
    match opcode {
        // Schema: id, name, encoding, data.
        0x03 => {
            f.skip(2, "id")?;
            f.prefixed(4, "name")?;
            f.prefixed(4, "encoding")?;
            f.prefixed(4, "data")
        }
        // Channel: id, schema id, topic, message encoding, metadata map.
        0x04 => {
            f.skip(4, "ids")?;
            f.prefixed(4, "topic")?;
            f.prefixed(4, "message encoding")?;
            let map = f.int(4, "metadata")?;
            map_fits(&f.0[..(map as usize).min(f.0.len())], map)
        }
        // Attachment: log time, create time, name, media type, data.
        0x09 => {
            f.skip(16, "times")?;
            f.prefixed(4, "name")?;
            f.prefixed(4, "media type")?;
            f.prefixed(8, "data")
        }
        // Metadata: name, map.
        0x0c => {
            f.prefixed(4, "name")?;
            let map = f.int(4, "map")?;
            map_fits(&f.0[..(map as usize).min(f.0.len())], map)
        }
        _ => Ok(()),
    }
}

/// A map of `len` bytes of u32-prefixed key and value strings.
fn map_fits(body: &[u8], len: u64) -> Result<(), RecordError> {
    if len > body.len() as u64 {
        return Err(RecordError::Overrun {
            claims: len,
            what: "map",
            left: body.len(),
        });
    }
    let mut f = Fields(body);
    while !f.0.is_empty() {
        f.prefixed(4, "map key")?;
        f.prefixed(4, "map value")?;
    }
    Ok(())
}
