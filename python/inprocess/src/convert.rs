//! Python values in, Python values out: arrays checked for length and
//! finiteness, `set=` overrides, scenarios loaded as `--scenario` loads
//! them, JSON reports as dicts.

use std::path::PathBuf;

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use crate::TestbedError;

/// A testbed error as a Python exception carrying its message.
pub fn err(e: impl std::fmt::Display) -> PyErr {
    TestbedError::new_err(e.to_string())
}

/// Reads a 1-D array of `n` numbers named `what` into `out`: float64 or
/// float32 numpy arrays, or any sequence of numbers.
pub fn read_into(what: &str, x: &Bound<'_, PyAny>, out: &mut [f64]) -> PyResult<()> {
    let n = out.len();
    let wrong_len = |got: usize| {
        PyValueError::new_err(format!(
            "{what}: {got} values; this arm needs {n} (one per controlled joint)"
        ))
    };
    if let Ok(a) = x.cast::<PyArray1<f64>>() {
        let a: PyReadonlyArray1<'_, f64> = a.readonly();
        if a.len() != n {
            return Err(wrong_len(a.len()));
        }
        match a.as_slice() {
            Ok(s) => out.copy_from_slice(s),
            Err(_) => out
                .iter_mut()
                .zip(a.as_array().iter())
                .for_each(|(o, v)| *o = *v),
        }
        return Ok(());
    }
    if let Ok(a) = x.cast::<PyArray1<f32>>() {
        let a = a.readonly();
        if a.len() != n {
            return Err(wrong_len(a.len()));
        }
        out.iter_mut()
            .zip(a.as_array().iter())
            .for_each(|(o, v)| *o = f64::from(*v));
        return Ok(());
    }
    let text = x.is_instance_of::<pyo3::types::PyBytes>() || x.is_instance_of::<PyString>();
    let v: Vec<f64> = (!text).then(|| x.extract().ok()).flatten().ok_or_else(|| {
        let ty = x
            .get_type()
            .name()
            .map_or_else(|_| "?".to_string(), |n| n.to_string());
        let shape = x
            .getattr("shape")
            .ok()
            .map(|s| format!(" of shape {s}"))
            .unwrap_or_default();
        let dtype = x
            .getattr("dtype")
            .ok()
            .map(|s| format!(" and dtype {s}"))
            .unwrap_or_default();
        PyTypeError::new_err(format!(
            "{what}: expected {n} numbers (a 1-D float array), got {ty}{shape}{dtype}"
        ))
    })?;
    if v.len() != n {
        return Err(wrong_len(v.len()));
    }
    out.copy_from_slice(&v);
    Ok(())
}

/// [`read_into`], refusing a value that is not finite (naming its index).
pub fn read_finite(what: &str, x: &Bound<'_, PyAny>, out: &mut [f64]) -> PyResult<()> {
    read_into(what, x, out)?;
    match out.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(PyValueError::new_err(format!(
            "{what}[{i}] = {} is not a finite number",
            out[i]
        ))),
        None => Ok(()),
    }
}

/// A new float64 array holding `v`.
pub fn array<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v)
}

/// `set=`: a dict `{"controller.k1": 20}` (values as Python numbers,
/// strings, booleans or lists), or a list of `"key=value"` strings as
/// `--set` takes them.
pub fn overrides_set(set: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<(String, toml::Value)>> {
    let Some(set) = set else {
        return Ok(Vec::new());
    };
    if let Ok(d) = set.cast::<PyDict>() {
        let mut out = Vec::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!(
                    "set: key {} is not a string",
                    cut(&k.to_string(), QUOTED)
                ))
            })?;
            check_dotted(&key)?;
            let value = to_toml(&key, &v, 0)?;
            // Through `--set`'s own reader: the same key checks.
            let parsed = scenario::parse_set(&format!("{key}={value}")).map_err(|e| {
                PyValueError::new_err(format!("set: {}", cut(&e.to_string(), 2 * QUOTED)))
            })?;
            out.push(parsed);
        }
        return Ok(out);
    }
    let items: Vec<String> = set.extract().map_err(|_| {
        PyTypeError::new_err(
            "set: expected a dict {\"controller.k1\": 20.0} or a list of \"key=value\" strings",
        )
    })?;
    items
        .iter()
        .map(|s| {
            scenario::parse_set(s).map_err(|e| {
                PyValueError::new_err(format!("set: {}", cut(&e.to_string(), 2 * QUOTED)))
            })
        })
        .collect()
}

/// A `set=` key is a dotted name (`controller.k1`), nothing else: it is
/// joined to its value as `--set`'s text, so a key holding `=`, `#` or a
/// newline would write a value of its own (`'controller.k1=20 #'` set k1
/// to 20, #60 item 6).
fn check_dotted(key: &str) -> PyResult<()> {
    let part_ok = |p: &str| {
        !p.is_empty()
            && p.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    };
    if key.split('.').all(part_ok) {
        return Ok(());
    }
    Err(PyValueError::new_err(format!(
        "set: key {:?} is not a dotted name like \"controller.k1\" (letters, digits, _ and - \
         between dots)",
        cut(key, QUOTED)
    )))
}

/// `law_sets=`: `["pd:controller.k1=20"]` or `{"pd": {"controller.k1": 20}}`.
pub fn law_sets(x: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<experiments::compare::LawSet>> {
    let Some(x) = x else {
        return Ok(Vec::new());
    };
    let parse = |s: &str| {
        s.parse::<experiments::compare::LawSet>()
            .map_err(|e| PyValueError::new_err(format!("law_sets: {}", cut(&e, 2 * QUOTED))))
    };
    if let Ok(d) = x.cast::<PyDict>() {
        let mut out = Vec::new();
        for (law, keys) in d.iter() {
            let law: String = law
                .extract()
                .map_err(|_| PyTypeError::new_err("law_sets: a law's name is a string"))?;
            for (key, value) in overrides_set(Some(&keys))? {
                out.push(parse(&format!("{law}:{key}={value}"))?);
            }
        }
        return Ok(out);
    }
    let items: Vec<String> = x.extract().map_err(|_| {
        PyTypeError::new_err(
            "law_sets: expected a dict {\"pd\": {\"controller.k1\": 20.0}} or a list of \
             \"LAW:controller.KEY=VALUE\" strings",
        )
    })?;
    items.iter().map(|s| parse(s)).collect()
}

/// The most characters of a user's value a refusal quotes: a 2 M-entry
/// `set=` made a 10 MB message and 650 MB of memory (#48 item 9). The
/// reader's own messages quote the whole `key=value`, so they are cut at
/// twice this, which keeps what they say of it.
const QUOTED: usize = 80;

/// `text` cut to `chars` characters, with its length when cut.
fn cut(text: &str, chars: usize) -> String {
    match text.char_indices().nth(chars) {
        None => text.to_string(),
        Some((at, _)) => format!("{}… ({} bytes in all)", &text[..at], text.len()),
    }
}

/// How deep a `set=` value may nest (a scenario's deepest is 3).
const MAX_SET_DEPTH: usize = 16;

/// A Python value as a TOML value, for `set=`.
fn to_toml(key: &str, v: &Bound<'_, PyAny>, depth: usize) -> PyResult<toml::Value> {
    if depth > MAX_SET_DEPTH {
        return Err(PyValueError::new_err(format!(
            "set: {}: nested more than {MAX_SET_DEPTH} deep (a list or dict that contains itself?)",
            cut(key, QUOTED)
        )));
    }
    if let Ok(b) = v.extract::<bool>() {
        return Ok(toml::Value::Boolean(b));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    let key_is_seed = key == "seed" || key.ends_with(".seed");
    // Past TOML's i64: a seed up to 2**64 - 1 is written as its digits,
    // which the scenario's seed takes (it was rounded to a float and
    // refused). Any other key keeps the float it was.
    if key_is_seed && let Ok(u) = v.extract::<u64>() {
        return Ok(toml::Value::String(u.to_string()));
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(toml::Value::String(s.to_str()?.to_string()));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let k: String = k.extract()?;
            t.insert(k.clone(), to_toml(&format!("{key}.{k}"), &x, depth + 1)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.cast::<PyList>().is_ok()
        || v.hasattr("tolist")?
        || v.cast::<pyo3::types::PyTuple>().is_ok()
    {
        let items = if v.hasattr("tolist")? {
            v.call_method0("tolist")?
        } else {
            v.clone()
        };
        if let Ok(list) = items.cast::<PyList>() {
            return list
                .iter()
                .map(|x| to_toml(key, &x, depth + 1))
                .collect::<PyResult<Vec<_>>>()
                .map(toml::Value::Array);
        }
        return to_toml(key, &items, depth + 1);
    }
    Err(PyTypeError::new_err(format!(
        "set: {}: a {} is not a scenario value (a number, string, bool, list or dict)",
        cut(key, QUOTED),
        v.get_type().name()?
    )))
}

/// What every function that runs a scenario takes, as `testbed sim` does:
/// `scenario` (a file or a shipped name; None: the paper's, or the
/// default of `robot`), `robot` (a URDF or a shipped robot's name), `set`,
/// `duration`, `law`.
pub struct ScenarioArgs<'a, 'py> {
    pub scenario: Option<PathBuf>,
    pub robot: Option<PathBuf>,
    pub set: Option<&'a Bound<'py, PyAny>>,
    pub duration: Option<f64>,
    pub law: Option<&'a str>,
}

impl ScenarioArgs<'_, '_> {
    /// The plan `testbed sim` with the same arguments would run.
    pub fn load(&self) -> PyResult<scenario::Plan> {
        let law = self
            .law
            .map(|l| {
                l.parse::<controller::LawName>()
                    .map_err(|e| PyValueError::new_err(format!("law: {e}")))
            })
            .transpose()?;
        let robot = self
            .robot
            .as_deref()
            .map(crate::shipped::robot)
            .transpose()
            .map_err(err)?;
        let overrides = scenario::Overrides {
            duration_s: self.duration,
            rate_hz: None,
            robot,
            law,
            set: overrides_set(self.set)?,
        };
        let scenario = self.scenario.as_deref().map(crate::shipped::scenario);
        scenario::load_named(scenario.as_deref(), &overrides).map_err(err)
    }
}

/// Serialises `value` as JSON and returns Python's reading of it.
pub fn json_to_py<'py>(
    py: Python<'py>,
    value: &impl serde::Serialize,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(err)?;
    py.import("json")?.call_method1("loads", (text,))
}
