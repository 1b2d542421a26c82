//! The reference page of `[controller]`, made from the parameters'
//! declaration (`parameters!` in `params.rs`): each key's default, what it
//! must be, which laws take it and what it is. The page is
//! docs/generated/controller-parameters.md; a test keeps it current.

use std::fmt::Write;

use crate::{ControllerParams, LawName};

/// The page as Markdown.
pub fn reference_markdown() -> String {
    let mut out = String::from(
        "<!-- Generated from controller/src/params.rs (parameters!): do not edit.\n     \
         Rewrite it with: TESTBED_WRITE_DOCS=1 cargo test -p controller --lib params_reference -->\n\n\
         # `[controller]` parameters\n\n\
         Every key of a scenario's `[controller]` table, from the one place each \
         is declared. An unset key takes its default; a key set away from its \
         default that the chosen law does not take is an error naming it.\n\n\
         | key | default | must be | laws | what it is |\n|---|---|---|---|---|\n",
    );
    for p in ControllerParams::REFERENCE {
        let default =
            ControllerParams::default_of(p.key).map_or_else(String::new, |v| toml_like(&v));
        let _ = writeln!(
            out,
            "| `{}` | {} | {} | {} | {} |",
            p.key,
            default,
            p.need,
            laws_taking(p.key),
            prose(p.doc)
        );
    }
    out
}

/// A default as a scenario writes it.
fn toml_like(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::Number(n) => format!("`{n}`"),
        other => format!("`{other}`"),
    }
}

/// The laws that take `key`: every one, or their names.
fn laws_taking(key: &str) -> String {
    let takes: Vec<&str> = LawName::ALL
        .iter()
        .filter(|l| l.takes(key))
        .map(|l| l.as_str())
        .collect();
    if takes.len() == LawName::ALL.len() {
        "all".into()
    } else {
        takes
            .iter()
            .map(|l| format!("`{l}`"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A doc comment as one line of a table cell: rustdoc links as code.
fn prose(doc: &str) -> String {
    let text = doc.split_whitespace().collect::<Vec<_>>().join(" ");
    text.replace("[`", "`")
        .replace("`]", "`")
        .replace('|', "\\|")
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        clippy::expect_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// The shipped page equals what the declaration gives (write it with
    /// `TESTBED_WRITE_DOCS=1`).
    #[test]
    fn the_reference_page_is_current() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../docs/generated/controller-parameters.md"
        );
        let page = reference_markdown();
        if std::env::var_os("TESTBED_WRITE_DOCS").is_some() {
            std::fs::write(path, &page).unwrap();
        }
        let shipped = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            shipped == page,
            "{path} is stale: TESTBED_WRITE_DOCS=1 cargo test -p controller --lib params_reference"
        );
    }

    #[test]
    fn every_key_is_on_the_page_with_its_default_and_need() {
        let page = reference_markdown();
        for key in ControllerParams::KEYS {
            assert!(page.contains(&format!("| `{key}` |")), "{key}");
        }
        assert!(page.contains("| `k1` | `15.0` | a number in (0, 1e6], or one per controlled joint, each in (0, 1e6] | all |"), "{page}");
        assert!(
            page.contains("| `neurons` | `10` | an integer from 1 to 1000"),
            "{page}"
        );
    }

    /// The needs the page states are the limits the checks use.
    #[test]
    fn stated_limits_are_the_constants() {
        let page = reference_markdown();
        assert!(page.contains(&format!("from 1 to {}", crate::MAX_NEURONS)));
        assert!(page.contains(&format!("from 1 to {}", crate::MAX_MPC_HORIZON)));
    }
}
