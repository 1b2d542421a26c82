//! An external controller (`run --controller-cmd CMD`) as a law of its own:
//! before the run the launcher asks it what it is (`CMD --describe` prints
//! `{"name": …, "params": {key: default, …}}`), checks the scenario's
//! `[external]` table against those parameters, and hands it the merged
//! values (`own_params` in its config). The log and the summary then name
//! the law that ran, not the scenario's.

use std::io::Read;
use std::os::unix::process::CommandExt;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Map, Value};

use super::RunError;

/// How long a command may take to describe itself (Python with numpy
/// starts in about a second).
const DESCRIBE_WAIT: Duration = Duration::from_secs(30);
/// Most bytes of a description read.
const MAX_DESCRIPTION: u64 = 64 * 1024;

/// What an external controller says it is.
#[derive(Debug, Clone, PartialEq)]
pub struct Declared {
    /// Its law's name.
    pub name: String,
    /// Its own parameters: the declared defaults with the scenario's
    /// `[external]` values over them.
    pub params: Map<String, Value>,
    /// Its own diagnostics (published on their own topic, logged on their
    /// own channel), in the order of their names.
    pub diagnostics: wire::OwnLayout,
}

impl Declared {
    /// The parameters as `key=value` pairs, for the log.
    pub fn params_text(&self) -> String {
        self.params
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(",")
    }
}

fn refused(command: &[String], reason: String) -> RunError {
    RunError::External {
        command: shell_words::join(command),
        reason,
    }
}

/// The declaration of `command` with `table`'s values checked and merged;
/// None for a command that does not describe itself (it then takes no
/// `[external]` table).
pub fn declared(
    command: &[String],
    table: &toml::Table,
    dof: usize,
) -> Result<Option<Declared>, RunError> {
    let Some(text) = describe(command)? else {
        if let Some(key) = table.keys().next() {
            return Err(refused(
                command,
                format!(
                    "the scenario sets [external] {key}, but the command declares no parameters \
                     (`--describe` did not answer; see docs/python.md)"
                ),
            ));
        }
        return Ok(None);
    };
    let mut d = parse(&text, dof).map_err(|reason| refused(command, reason))?;
    for (key, value) in table {
        let Some(default) = d.params.get(key) else {
            let known: Vec<&str> = d.params.keys().map(String::as_str).collect();
            return Err(refused(
                command,
                format!(
                    "[external] {key}: '{}' declares no such parameter (it has: {})",
                    d.name,
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            ));
        };
        let given = serde_json::to_value(value).map_err(|e| refused(command, e.to_string()))?;
        if !same_kind(default, &given) {
            return Err(refused(
                command,
                format!(
                    "[external] {key} = {given}: '{}' declares it like {default}",
                    d.name
                ),
            ));
        }
        d.params.insert(key.clone(), given);
    }
    Ok(Some(d))
}

/// Numbers match numbers (an integer where a float is declared too).
fn same_kind(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(_), Value::Number(_))
        | (Value::Bool(_), Value::Bool(_))
        | (Value::String(_), Value::String(_)) => true,
        (Value::Array(x), Value::Array(y)) => x
            .first()
            .zip(y.first())
            .is_none_or(|(p, q)| same_kind(p, q)),
        _ => false,
    }
}

/// Whether `name` may name a law: 1 to 40 of a-z, 0-9, `-`, `_` (it
/// labels rows, files and log records).
pub fn is_law_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 40
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-' || c == '_')
}

/// Reads a description: a name of lowercase letters, digits, `-` and `_`,
/// parameters that are numbers, booleans, strings or lists, and
/// diagnostics that are `"scalar"` or `"joints"` (checked for `dof` joints).
fn parse(text: &str, dof: usize) -> Result<Declared, String> {
    let v: Value = serde_json::from_str(text.trim())
        .map_err(|e| format!("`--describe` printed no JSON object: {e}"))?;
    let name = v["name"].as_str().unwrap_or_default().to_string();
    if !is_law_name(&name) {
        return Err(format!(
            "`--describe` gave the name {:?}: 1 to 40 of a-z, 0-9, '-', '_'",
            v["name"]
        ));
    }
    // The summary, the log and compare's table name the law that ran by
    // this name: a built-in law's would pass the controller off as it.
    if name.parse::<controller::LawName>().is_ok() {
        return Err(format!(
            "`--describe` gave the name {name:?}, a built-in law's: name your law otherwise \
             (a run would be taken for the built-in {name})"
        ));
    }
    let params = match &v["params"] {
        Value::Null => Map::new(),
        Value::Object(m) => m.clone(),
        other => {
            return Err(format!(
                "`--describe` gave params {other}: an object is needed"
            ));
        }
    };
    if let Some((k, _)) = params.iter().find(|(_, p)| p.is_null() || p.is_object()) {
        return Err(format!(
            "`--describe` parameter {k}: a number, boolean, string or list"
        ));
    }
    Ok(Declared {
        name,
        params,
        diagnostics: diagnostics(&v["diagnostics"], dof)?,
    })
}

/// `{"name": "scalar" | "joints", …}` as a layout (names in order).
fn diagnostics(v: &Value, dof: usize) -> Result<wire::OwnLayout, String> {
    let entries = match v {
        Value::Null => Vec::new(),
        Value::Object(m) => m
            .iter()
            .map(|(name, shape)| {
                let shape = shape.as_str().ok_or(format!(
                    "`--describe` diagnostic {name}: {shape} is not \"scalar\" or \"joints\""
                ))?;
                let shape = wire::OwnShape::parse(shape)
                    .map_err(|e| format!("`--describe` diagnostic {name}: {e}"))?;
                Ok((name.clone(), shape))
            })
            .collect::<Result<Vec<_>, String>>()?,
        other => {
            return Err(format!(
                "`--describe` gave diagnostics {other}: an object is needed"
            ));
        }
    };
    wire::OwnLayout::new(entries, dof).map_err(|e| format!("`--describe`: {e}"))
}

/// `CMD --describe`'s standard output, None if it exits non-zero.
fn describe(command: &[String]) -> Result<Option<String>, RunError> {
    let Some((program, words)) = command.split_first() else {
        return Ok(None);
    };
    // Named like a run's nodes, so that a helper it leaves ends too.
    let tag = format!(
        "describe-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    );
    // Its process tree, adopted here, ends with it (a helper that cleared
    // its environment carries no tag).
    let mut tree = super::strays::RunTree::default();
    let mut child = Command::new(program)
        .args(words)
        .arg("--describe")
        .env(super::strays::RUN_ENV, &tag)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .process_group(0)
        .spawn()
        .map_err(|e| refused(command, format!("cannot start it: {e}")))?;
    // Whatever it started goes with it (a helper would hold the pipe open).
    let group = nix::unistd::Pid::from_raw(child.id() as i32);
    let nodes = [group.as_raw()];
    let end_group = |tree: &mut super::strays::RunTree| {
        tree.note(&nodes, true);
        let _ = nix::sys::signal::killpg(group, nix::sys::signal::Signal::SIGKILL);
        tree.end(&nodes);
        super::strays::end_strays(&tag);
    };
    let mut out = String::new();
    let stdout = child.stdout.take();
    // Set once more than MAX_DESCRIPTION bytes came: the command is then
    // ended at once (its next write would block on the unread pipe).
    let over = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let over_seen = std::sync::Arc::clone(&over);
    let reader = std::thread::spawn(move || {
        let mut text = Vec::new();
        if let Some(s) = stdout {
            let _ = s.take(MAX_DESCRIPTION + 1).read_to_end(&mut text);
        }
        if text.len() as u64 > MAX_DESCRIPTION {
            over_seen.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        String::from_utf8_lossy(&text).into_owned()
    });
    let too_long = || {
        refused(
            command,
            format!(
                "`--describe` printed more than {} KiB ({MAX_DESCRIPTION} bytes), the most a \
                 description may be",
                MAX_DESCRIPTION / 1024
            ),
        )
    };
    let start = Instant::now();
    let status = loop {
        if over.load(std::sync::atomic::Ordering::Relaxed) {
            end_group(&mut tree);
            let _ = child.wait();
            return Err(too_long());
        }
        if let Some(status) = child
            .try_wait()
            .map_err(|e| refused(command, e.to_string()))?
        {
            break status;
        }
        tree.note(&nodes, false);
        if start.elapsed() > DESCRIBE_WAIT {
            end_group(&mut tree);
            let _ = child.wait();
            return Err(refused(
                command,
                format!(
                    "`--describe` did not answer in {} s",
                    DESCRIBE_WAIT.as_secs()
                ),
            ));
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    end_group(&mut tree);
    // The pipe closes with the group; a reader still blocked is left behind.
    let waited = Instant::now();
    while !reader.is_finished() && waited.elapsed() < Duration::from_secs(1) {
        std::thread::sleep(Duration::from_millis(5));
    }
    if reader.is_finished()
        && let Ok(text) = reader.join()
    {
        out = text;
    }
    if over.load(std::sync::atomic::Ordering::Relaxed) {
        return Err(too_long());
    }
    Ok(status.success().then_some(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descriptions_are_checked() {
        let d = parse(
            r#"{"name": "pid", "params": {"ki": 0.5, "mode": "x"},
                "diagnostics": {"windup": "scalar", "integral": "joints"}}"#,
            2,
        )
        .unwrap();
        assert_eq!(d.name, "pid");
        assert_eq!(d.diagnostics.text(), "integral:joints,windup:scalar");
        assert_eq!(d.params_text(), "ki=0.5,mode=\"x\"");
        assert!(
            parse(r#"{"name": "Bad Name"}"#, 2)
                .unwrap_err()
                .contains("1 to 40")
        );
        assert!(parse("nope", 2).unwrap_err().contains("no JSON"));
        // #48 item 13 (D15): a controller never passes itself off as a built-in law.
        for builtin in ["pd", "nac", "cbf-ctc"] {
            let e = parse(&format!(r#"{{"name": "{builtin}"}}"#), 2).unwrap_err();
            assert!(e.contains("a built-in law's"), "{e}");
        }
        assert!(parse(r#"{"name": "a", "params": {"k": null}}"#, 2).is_err());
        let e = parse(r#"{"name": "a", "diagnostics": {"x": 3}}"#, 2).unwrap_err();
        assert!(e.contains("diagnostic x"), "{e}");
        let e = parse(
            r#"{"name": "a", "diagnostics": {"a": "joints", "b": "joints"}}"#,
            20,
        );
        assert!(e.unwrap_err().contains("at most 32"));
        assert!(same_kind(&Value::from(1), &Value::from(0.5)));
        assert!(!same_kind(&Value::from(true), &Value::from(0.5)));
    }

    /// #48 item 16: a description over the 64 KiB read is refused naming
    /// the limit (it was cut there and said "EOF while parsing"), also one
    /// that never ends (`yes`), which is ended at the limit; one under it
    /// is read whole.
    #[test]
    fn a_description_over_the_limit_is_named() {
        let sh = |script: String| vec!["sh".to_string(), "-c".to_string(), script, "sh".into()];
        let padded = |n: usize| {
            sh(format!(
                "head -c {n} /dev/zero | tr '\\0' ' '; echo '{{\"name\": \"big\"}}'"
            ))
        };
        let d = declared(&padded(60_000), &toml::Table::new(), 2)
            .unwrap()
            .unwrap();
        assert_eq!(d.name, "big");
        // `yes` alone would refuse the appended `--describe`.
        for command in [padded(70_000), sh("yes".into())] {
            let e = declared(&command, &toml::Table::new(), 2)
                .unwrap_err()
                .to_string();
            assert!(e.contains("more than 64 KiB (65536 bytes)"), "{e}");
        }
    }
}
