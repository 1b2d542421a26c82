//! Reading files that come from outside: only regular files, and only up
//! to a size, checked before a byte is read (a device, a FIFO or a huge
//! file is refused rather than read or waited on).

use std::io::Read;
use std::path::Path;

/// Largest scenario or sweep file read, bytes.
pub const MAX_TEXT_FILE_BYTES: u64 = 16 << 20;
/// Largest URDF read, bytes (real arms without inline meshes are well
/// under 1 MB).
pub const MAX_URDF_BYTES: u64 = 16 << 20;

/// Opens `path` for reading if it is a regular file (a device, FIFO or
/// folder is refused before it is opened: opening a FIFO would block).
pub fn open_regular_file(path: &Path) -> std::io::Result<std::fs::File> {
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, FIFO or folder is not read)",
        ));
    }
    std::fs::File::open(path)
}

/// The bytes of the regular file at `path`, at most `max_bytes` of them
/// (`None`: no limit).
pub fn read_regular_file(path: &Path, max_bytes: Option<u64>) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, FIFO or folder is not read)",
        ));
    }
    let too_big = |len: u64, max: u64| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{len} bytes is larger than the {max} bytes read"),
        )
    };
    if let Some(max) = max_bytes
        && meta.len() > max
    {
        return Err(too_big(meta.len(), max));
    }
    let mut buf = Vec::with_capacity(meta.len() as usize);
    let file = std::fs::File::open(path)?;
    match max_bytes {
        // The file may grow after the check: read one byte past the limit.
        Some(max) => file.take(max + 1).read_to_end(&mut buf)?,
        None => (&file).read_to_end(&mut buf)?,
    };
    if let Some(max) = max_bytes
        && buf.len() as u64 > max
    {
        return Err(too_big(buf.len() as u64, max));
    }
    Ok(buf)
}

/// [`read_regular_file`] as UTF-8 text, without a leading byte-order mark
/// (editors on Windows write one; left in, it became part of the first
/// key or column name, `'\u{feff}t'`).
pub fn read_text_file(path: &Path, max_bytes: u64) -> std::io::Result<String> {
    let mut bytes = read_regular_file(path, Some(max_bytes))?;
    if bytes.starts_with(UTF8_BOM) {
        bytes.drain(..UTF8_BOM.len());
    }
    String::from_utf8(bytes).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// The UTF-8 byte-order mark.
const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn devices_folders_and_big_files_are_refused() {
        assert!(read_regular_file(Path::new("/dev/zero"), None).is_err());
        assert!(read_regular_file(Path::new("/tmp"), None).is_err());
        let dir = std::env::temp_dir().join(format!("wire-files-{}", std::process::id()));
        std::fs::write(&dir, b"0123456789").unwrap();
        assert_eq!(read_text_file(&dir, 10).unwrap(), "0123456789");
        let e = read_text_file(&dir, 9).unwrap_err().to_string();
        assert!(
            e.contains("10 bytes is larger than the 9 bytes read"),
            "{e}"
        );
        std::fs::remove_file(&dir).unwrap();
    }

    /// #48 item 16: a UTF-8 byte-order mark is not text of the file.
    #[test]
    fn a_byte_order_mark_is_stripped() {
        let path = std::env::temp_dir().join(format!("wire-bom-{}", std::process::id()));
        std::fs::write(&path, b"\xEF\xBB\xBFt,joint1\n").unwrap();
        assert_eq!(read_text_file(&path, 100).unwrap(), "t,joint1\n");
        // Only at the start: one later is the file's own character.
        std::fs::write(&path, "a\u{feff}".as_bytes()).unwrap();
        assert_eq!(read_text_file(&path, 100).unwrap(), "a\u{feff}");
        std::fs::remove_file(&path).unwrap();
    }
}
