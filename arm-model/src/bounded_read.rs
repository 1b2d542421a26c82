//! A model file read from disk: a regular file only, its size checked
//! before a byte is read and the read itself bounded (#60 items 2, 3). A
//! 3 GB include aborted the process and `/dev/zero` was read until memory
//! ran out; a FIFO would block on open. Callers name the file; a fault
//! here never holds the file's text.

use std::io::Read;
use std::path::Path;

/// Why a file was not read.
#[derive(Debug)]
pub(crate) enum Fault {
    /// The file system said no (missing, no permission…).
    Io(std::io::Error),
    /// A FIFO, device, socket or folder: what it is.
    NotRegular(&'static str),
    /// Its size in bytes, over the cap (or the size it reached while read).
    TooLarge(u64),
    /// Not UTF-8 text.
    NotUtf8,
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Fault::Io(e) => write!(f, "cannot read it: {e}"),
            Fault::NotRegular(kind) => write!(f, "it is {kind}, not a regular file: not read"),
            Fault::TooLarge(n) => write!(f, "it is {n} bytes or more"),
            Fault::NotUtf8 => write!(f, "it is not UTF-8 text"),
        }
    }
}

/// What a file that is not a regular one is, for the message.
pub(crate) fn kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() { "a folder" } else { "not a file" }
}

/// The text of the regular file at `path`, at most `cap` bytes of it.
/// The type and size are checked before the file is opened (opening a
/// FIFO blocks), again on the open file (it may have been replaced), and
/// the read stops one byte past `cap` (it may grow while read).
pub(crate) fn read(path: &Path, cap: u64) -> Result<String, Fault> {
    let meta = std::fs::metadata(path).map_err(Fault::Io)?;
    check(&meta, cap)?;
    let file = std::fs::File::open(path).map_err(Fault::Io)?;
    let opened = file.metadata().map_err(Fault::Io)?;
    check(&opened, cap)?;
    let mut bytes = Vec::with_capacity(usize::try_from(opened.len()).unwrap_or(0));
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(Fault::Io)?;
    if bytes.len() as u64 > cap {
        return Err(Fault::TooLarge(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|_| Fault::NotUtf8)
}

fn check(meta: &std::fs::Metadata, cap: u64) -> Result<(), Fault> {
    if !meta.is_file() {
        return Err(Fault::NotRegular(kind(meta.file_type())));
    }
    if meta.len() > cap {
        return Err(Fault::TooLarge(meta.len()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn devices_folders_and_large_files_are_refused_unread() {
        let e = read(Path::new("/dev/zero"), 10).unwrap_err().to_string();
        assert_eq!(e, "it is a character device, not a regular file: not read");
        let e = read(&std::env::temp_dir(), 10).unwrap_err().to_string();
        assert_eq!(e, "it is a folder, not a regular file: not read");
        let path = std::env::temp_dir().join(format!("bounded-read-{}", std::process::id()));
        std::fs::write(&path, "0123456789").unwrap();
        assert_eq!(read(&path, 10).unwrap(), "0123456789");
        assert!(matches!(read(&path, 9), Err(Fault::TooLarge(10))));
        std::fs::write(&path, b"\xff\xfe").unwrap();
        assert!(matches!(read(&path, 9), Err(Fault::NotUtf8)));
        std::fs::remove_file(&path).unwrap();
    }

    /// A file longer than its metadata said when it was checked (one that
    /// grew in between) is cut one byte past the cap and refused: procfs
    /// files give size 0 and hold more.
    #[test]
    fn a_file_longer_than_its_size_said_is_read_no_further_than_the_cap() {
        let path = Path::new("/proc/self/status");
        if std::fs::metadata(path).is_ok_and(|m| m.len() == 0) {
            assert!(matches!(read(path, 16), Err(Fault::TooLarge(17))));
            assert!(read(path, 1 << 20).is_ok());
        }
    }
}
