//! Which file an MJCF `<include>` may read (#60 item 1): a regular file
//! inside the main file's folder tree, after symlinks and `..` are
//! resolved, whose root element is `<mujoco>` or `<mujocoinclude>`.
//! `<include file="/etc/passwd"/>` or `file="../outside/secret.xml"` was
//! read and pasted into the model, whose text is logged; a refused file's
//! text is never shown, only the include and the path.

use std::path::{Path, PathBuf};

/// The canonical path of `written` (an include's file joined to the
/// canonical folder `root`) if an include may read it; else the path as
/// shown and why not. Nothing is opened here: the type is told from the
/// file system's metadata, so a FIFO does not block and a device is not
/// read.
pub(crate) fn resolve(root: &Path, written: &Path) -> Result<PathBuf, (String, String)> {
    let path = written
        .canonicalize()
        .map_err(|e| (shown(written, written), format!("cannot find it: {e}")))?;
    let refuse = |reason: String| (shown(written, &path), reason);
    let meta = std::fs::metadata(&path).map_err(|e| refuse(format!("cannot read it: {e}")))?;
    if !meta.is_file() {
        return Err(refuse(format!(
            "it is {}, not a regular file: not read",
            crate::bounded_read::kind(meta.file_type())
        )));
    }
    if !path.starts_with(root) {
        return Err(refuse(format!(
            "it lies outside the model's folder {} (an include reads only files in the main \
             file's folder and the folders below it, after symlinks and '..' are resolved)",
            root.display()
        )));
    }
    Ok(path)
}

/// The path as messages show it: as written, and where it leads when a
/// symlink or `..` takes it elsewhere.
pub(crate) fn shown(written: &Path, path: &Path) -> String {
    if written == path {
        written.display().to_string()
    } else {
        format!("{} → {}", written.display(), path.display())
    }
}

/// What lies inside the root element of an included file: `<mujoco>`, or
/// `<mujocoinclude>` as older models (Adroit, Meta-World) write it. None
/// when the root is anything else: that file is not MJCF and is refused,
/// so that no other file's text reaches the model (or its messages).
pub(crate) fn children(text: &str) -> Option<&str> {
    let root = prolog_end(text);
    let body = text[root..].strip_prefix('<')?;
    let name_len = body
        .find(|c: char| c.is_whitespace() || c == '>' || c == '/')
        .unwrap_or(body.len());
    let name = &body[..name_len];
    if name != "mujoco" && name != "mujocoinclude" {
        return None;
    }
    let open_end = text[root..].find('>').map(|e| root + e + 1)?;
    if text[..open_end].ends_with("/>") {
        return Some("");
    }
    // An unclosed root is not XML: the parser would refuse the model, but
    // the file is refused here, before its text is pasted anywhere.
    let close = text.rfind(&format!("</{name}>"))?;
    text.get(open_end..close)
}

/// Where the root element starts: past the XML declaration, comments and
/// blank space.
fn prolog_end(text: &str) -> usize {
    let mut at = 0;
    loop {
        let rest = &text[at..];
        let trimmed = rest.trim_start_matches(|c: char| c.is_whitespace() || c == '\u{feff}');
        at += rest.len() - trimmed.len();
        let close = if trimmed.starts_with("<?") {
            "?>"
        } else if trimmed.starts_with("<!--") {
            "-->"
        } else {
            return at;
        };
        match trimmed.find(close) {
            Some(e) => at += e + close.len(),
            None => return at,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_included_root_gives_its_children() {
        assert_eq!(
            children("<?xml?><mujoco model='x'><a/></mujoco>"),
            Some("<a/>")
        );
        assert_eq!(children("<mujoco/>"), Some(""));
        assert_eq!(
            children("<!-- <mujoco> --><mujocoinclude>\n<body/>\n</mujocoinclude>\n"),
            Some("\n<body/>\n")
        );
    }

    #[test]
    fn a_file_that_is_not_mjcf_gives_nothing() {
        for text in [
            "root:x:0:0:root:/root:/bin/bash\n",
            "<robot name='r'/>",
            "<!DOCTYPE mujoco [<!ENTITY a 'b'>]><mujoco/>",
            "<mujoco><worldbody>",
            "<mujocox/>",
            "",
        ] {
            assert_eq!(children(text), None, "{text}");
        }
    }
}
