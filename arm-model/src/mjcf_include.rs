//! An MJCF file's `<include>`s inlined, so that its text alone is the
//! model: the scenario keeps the text, the plant node and `replay` read it
//! again from there (a log's attachment needs no other file). As in
//! MuJoCo, an included file's root `<mujoco>` element is replaced by its
//! children, and every path is relative to the main file's folder.
//!
//! An include reads a file and pastes it into text that is logged, so
//! what it may read is bounded (#60): only MJCF files inside the main
//! file's folder tree (`mjcf_include_file`), and at most
//! [`MAX_INCLUDED_FILES`] inclusions and [`MAX_URDF_BYTES`] read and
//! written, so that an include DAG (a file included four times on each of
//! 15 levels) is refused at once instead of expanding for minutes.

use std::path::{Path, PathBuf};

use crate::{MAX_URDF_BYTES, ModelError};

/// Includes nest no deeper than this (real models nest two or three).
const MAX_DEPTH: usize = 16;

/// The most inclusions one model may make, each counted (a file included
/// twice counts twice): real models include tens of files.
pub const MAX_INCLUDED_FILES: usize = 1000;

/// `text` with every `<include file>` replaced by that file's contents.
pub(crate) fn inline(text: &str, dir: &Path) -> Result<String, ModelError> {
    refuse_doctype(text)?;
    let mut x = Expansion {
        dir,
        root: None,
        out: String::with_capacity(text.len()),
        files: 0,
        read: 0,
        open: Vec::new(),
        last: None,
    };
    x.inline(text)?;
    Ok(x.out)
}

/// A DTD's entities expand inside the parser, past every check here: an
/// entity bomb grows to gigabytes, an external entity names a host file
/// (XXE). MuJoCo's models have none and its parser reads none.
pub(crate) fn refuse_doctype(text: &str) -> Result<(), ModelError> {
    match next_tag(text, "!DOCTYPE") {
        Some(_) => Err(ModelError::MjcfParse(
            "a <!DOCTYPE> is not read: MuJoCo's models have none, and its entities could \
             expand to gigabytes or name host files"
                .into(),
        )),
        None => Ok(()),
    }
}

/// One model's includes as they are inlined: what they have used of the
/// caps, and the includes open (outermost first) to tell a cycle.
struct Expansion<'a> {
    /// The main file's folder, as given.
    dir: &'a Path,
    /// That folder canonicalised, once an include needs it (text without
    /// includes reads even where the folder cannot be resolved).
    root: Option<PathBuf>,
    out: String,
    files: usize,
    /// Bytes read from included files.
    read: u64,
    /// The canonical paths of the includes being inlined.
    open: Vec<PathBuf>,
    /// The last include read, named when the expanded text passes its cap.
    last: Option<(String, String)>,
}

impl Expansion<'_> {
    fn inline(&mut self, text: &str) -> Result<(), ModelError> {
        let mut rest = text;
        while let Some(i) = next_include(rest) {
            self.push(&rest[..i])?;
            let tag_end = rest[i..]
                .find('>')
                .map(|e| i + e + 1)
                .ok_or_else(|| refuse("<include>", "the tag is not closed"))?;
            let tag = &rest[i..tag_end];
            let file = attribute(tag, "file").ok_or_else(|| refuse(tag, "it names no file"))?;
            let (path, shown, inner) = self.read(tag, file)?;
            let body = super::mjcf_include_file::children(&inner)
                .ok_or_else(|| not_included(tag, &shown, NOT_MJCF.into()))?;
            self.open.push(path);
            self.inline(body)?;
            self.open.pop();
            rest = &rest[tag_end..];
            // `<include …></include>` written in full.
            if !tag.ends_with("/>") {
                rest = rest.trim_start().strip_prefix("</include>").unwrap_or(rest);
            }
        }
        self.push(rest)
    }

    /// The expanded text grows by `piece`, within the cap on a model.
    fn push(&mut self, piece: &str) -> Result<(), ModelError> {
        let bytes = self.out.len() + piece.len();
        if bytes > MAX_URDF_BYTES {
            return Err(match &self.last {
                Some((tag, path)) => not_included(
                    tag,
                    path,
                    format!(
                        "the model with its includes inlined would pass the cap of \
                         {MAX_URDF_BYTES} bytes on a model's text (includes that multiply: a \
                         file included several times on each of many levels)"
                    ),
                ),
                None => ModelError::TooLarge {
                    bytes,
                    cap: MAX_URDF_BYTES,
                },
            });
        }
        self.out.push_str(piece);
        Ok(())
    }

    /// The included file's canonical path, the path as messages show it,
    /// and its text, every cap checked before it is read.
    fn read(&mut self, tag: &str, file: &str) -> Result<(PathBuf, String, String), ModelError> {
        let root = self.root()?;
        let written = root.join(file);
        let shown = written.display().to_string();
        if self.open.len() >= MAX_DEPTH {
            let reason = format!("includes nest more than {MAX_DEPTH} deep");
            return Err(not_included(tag, &shown, reason));
        }
        self.files += 1;
        if self.files > MAX_INCLUDED_FILES {
            return Err(not_included(
                tag,
                &shown,
                format!(
                    "the model makes more than {MAX_INCLUDED_FILES} inclusions (each counted: a \
                     file included twice counts twice), includes that multiply"
                ),
            ));
        }
        let path = super::mjcf_include_file::resolve(&root, &written)
            .map_err(|(shown, reason)| not_included(tag, &shown, reason))?;
        let shown = super::mjcf_include_file::shown(&written, &path);
        self.refuse_cycle(tag, &shown, &path)?;
        let left = MAX_URDF_BYTES as u64 - self.read;
        let text = crate::bounded_read::read(&path, left)
            .map_err(|fault| not_included(tag, &shown, self.why_unread(fault, left)))?;
        self.read += text.len() as u64;
        self.last = Some((cut(tag), shown.clone()));
        Ok((path, shown, text))
    }

    fn root(&mut self) -> Result<PathBuf, ModelError> {
        if let Some(root) = &self.root {
            return Ok(root.clone());
        }
        // `a.xml`'s folder is "", the working directory.
        let dir = match self.dir.as_os_str().is_empty() {
            true => Path::new("."),
            false => self.dir,
        };
        let root = dir.canonicalize().map_err(|e| {
            ModelError::MjcfParse(format!(
                "the model's folder {} cannot be resolved for its includes: {e}",
                dir.display()
            ))
        })?;
        self.root = Some(root.clone());
        Ok(root)
    }

    fn refuse_cycle(&self, tag: &str, shown: &str, path: &Path) -> Result<(), ModelError> {
        let Some(at) = self.open.iter().position(|p| p == path) else {
            return Ok(());
        };
        let chain: Vec<String> = (self.open[at..].iter())
            .map(|p| file_name(p))
            .chain([file_name(path)])
            .collect();
        Err(not_included(
            tag,
            shown,
            format!("the file includes itself ({})", chain.join(" → ")),
        ))
    }

    fn why_unread(&self, fault: crate::bounded_read::Fault, left: u64) -> String {
        use crate::bounded_read::Fault;
        match fault {
            Fault::TooLarge(n) if left < MAX_URDF_BYTES as u64 && n <= MAX_URDF_BYTES as u64 => {
                format!(
                    "the included files would add up to more than the cap of {MAX_URDF_BYTES} \
                     bytes read for one model ({} read before this one)",
                    self.read
                )
            }
            Fault::TooLarge(n) => format!(
                "it is {n} bytes or more, over the cap of {MAX_URDF_BYTES} bytes on a model file"
            ),
            other => other.to_string(),
        }
    }
}

/// What an included file that is not MJCF is told; its text is never shown.
const NOT_MJCF: &str = "it is not an MJCF file (XML whose root element is <mujoco> or \
                        <mujocoinclude>), and its text is not shown";

fn not_included(tag: &str, path: &str, reason: String) -> ModelError {
    ModelError::MjcfInclude {
        include: cut(tag),
        path: path.to_string(),
        reason,
    }
}

/// A tag as messages show it: at most 200 characters.
fn cut(tag: &str) -> String {
    match tag.char_indices().nth(200) {
        Some((i, _)) => format!("{}…", &tag[..i]),
        None => tag.to_string(),
    }
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// Text given alone (a log's attachment, a string) names no other file:
/// an `<include>` there is refused, so that reading a model never reads
/// files its reader did not name.
pub(crate) fn refuse_includes(text: &str) -> Result<(), ModelError> {
    let Some(i) = next_include(text) else {
        return Ok(());
    };
    let tag = text[i..].find('>').map_or(&text[i..], |e| &text[i..=i + e]);
    Err(refuse(
        tag,
        "an include in a model given as text: read the file itself, whose includes are inlined relative to its folder",
    ))
}

fn refuse(element: &str, reason: &str) -> ModelError {
    ModelError::MjcfParse(format!("{element}: {reason}"))
}

/// Where the next `<include` tag starts, outside comments (a commented
/// include, as in Meta-World's usage notes, includes nothing).
fn next_include(text: &str) -> Option<usize> {
    next_tag(text, "include")
}

/// Where the next `<name` tag starts, outside comments.
pub(crate) fn next_tag(text: &str, name: &str) -> Option<usize> {
    let open = format!("<{name}");
    let mut from = 0;
    loop {
        let i = from + text[from..].find(&open)?;
        match text[from..i].find("<!--") {
            Some(c) => from = from + c + text[from + c..].find("-->")? + 3,
            None => {
                let next = text[i + open.len()..].chars().next();
                if next.is_some_and(|c| c.is_whitespace() || c == '/' || c == '>') {
                    return Some(i);
                }
                from = i + 1;
            }
        }
    }
}

/// Every `<name …>` tag outside comments, whole.
pub(crate) fn tags<'a>(text: &'a str, name: &'a str) -> impl Iterator<Item = &'a str> + 'a {
    let mut rest = text;
    std::iter::from_fn(move || {
        let i = next_tag(rest, name)?;
        let end = rest[i..].find('>').map_or(rest.len(), |e| i + e + 1);
        let tag = &rest[i..end];
        rest = &rest[end..];
        Some(tag)
    })
}

/// The value of `name="…"` (or single-quoted) in a tag.
pub(crate) fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let mut from = 0;
    while let Some(i) = tag[from..].find(name) {
        let at = from + i;
        let before = tag[..at].chars().next_back();
        let after = tag[at + name.len()..].trim_start();
        if before.is_some_and(char::is_whitespace)
            && let Some(value) = after.strip_prefix('=')
        {
            let value = value.trim_start();
            let quote = value.chars().next()?;
            if quote == '"' || quote == '\'' {
                let body = &value[1..];
                return body.find(quote).map(|end| &body[..end]);
            }
        }
        from = at + name.len();
    }
    None
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn an_attribute_is_found_by_its_whole_name() {
        assert_eq!(
            attribute(r#"<include xfile="a" file='b.xml'/>"#, "file"),
            Some("b.xml")
        );
        assert_eq!(attribute("<include/>", "file"), None);
    }

    #[test]
    fn a_commented_include_includes_nothing() {
        let text = r#"<mujoco><!-- <include file="gone.xml"/> --><include file="x.xml"/></mujoco>"#;
        assert_eq!(next_include(text), text.find(r#"<include file="x"#));
        assert_eq!(next_include("<!-- <include file='a'/> -->"), None);
        assert_eq!(next_include("<!-- <include file='a'/>"), None);
    }

    #[test]
    fn a_file_that_includes_itself_is_refused() {
        let dir = std::env::temp_dir().join(format!("mjcf-include-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("loop.xml"),
            r#"<mujoco><include file="loop.xml"/></mujoco>"#,
        )
        .unwrap();
        let e = inline(r#"<mujoco><include file="loop.xml"/></mujoco>"#, &dir).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("the file includes itself (loop.xml → loop.xml)"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Text without includes never resolves its folder: a model read from
    /// a string (folder ".") reads where the working folder is gone.
    #[test]
    fn text_without_includes_needs_no_folder() {
        let text = "<mujoco><worldbody/></mujoco>";
        assert_eq!(
            inline(text, Path::new("/nonexistent/folder")).unwrap(),
            text
        );
        assert!(
            inline(
                "<mujoco><include file='a.xml'/></mujoco>",
                Path::new("/nonexistent/folder")
            )
            .is_err()
        );
    }

    #[test]
    fn a_doctype_is_refused_before_any_include_is_read() {
        let text = r#"<!DOCTYPE mujoco [<!ENTITY e "x">]><mujoco><include file="/etc/hostname"/></mujoco>"#;
        let e = inline(text, Path::new(".")).unwrap_err().to_string();
        assert!(
            e.starts_with("not a valid MJCF: a <!DOCTYPE> is not read"),
            "{e}"
        );
    }
}
