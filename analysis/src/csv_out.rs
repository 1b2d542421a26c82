//! One CSV row per control step.

use std::io::Write;

use crate::record::StepRecord;

/// A per-joint column: its name stem and where its value comes from.
type Column = (&'static str, fn(&StepRecord<'_>, usize) -> f64);

/// The per-joint columns, in order: the one list the header and the rows
/// are both made from. qm, qdm: as measured; d: the disturbance.
const JOINT_COLUMNS: [Column; 12] = [
    ("q", |r, i| r.q[i]),
    ("qd", |r, i| r.qd[i]),
    ("qdd", |r, i| r.qdd[i]),
    ("tau", |r, i| r.tau[i]),
    ("qref", |r, i| r.q_d[i]),
    ("kc", |r, i| r.kc[i]),
    ("z1_", |r, i| r.z1[i]),
    ("z2_", |r, i| r.z2[i]),
    ("wa", |r, i| r.wa_norm[i]),
    ("qm", |r, i| r.q_measured[i]),
    ("qdm", |r, i| r.qd_measured[i]),
    ("d", |r, i| r.disturbance[i]),
];

/// Column names: `t`, then per joint i `q{i} qd{i} qdd{i} tau{i} qref{i}
/// kc{i} z1_{i} z2_{i} wa{i} qm{i} qdm{i} d{i}`, then `effects` (bits of
/// `wire::Effects`).
pub fn header(dof: usize) -> String {
    header_with_own(dof, &[])
}

/// [`header`], then an external controller's own diagnostics as `own.NAME`
/// columns ([`wire::OwnLayout::columns`]).
pub fn header_with_own(dof: usize, own: &[String]) -> String {
    let mut cols = vec!["t".to_string()];
    for i in 0..dof {
        cols.extend(JOINT_COLUMNS.iter().map(|(stem, _)| format!("{stem}{i}")));
    }
    cols.push("effects".into());
    cols.extend(own.iter().map(|c| format!("own.{c}")));
    cols.join(",")
}

/// Writes one row. `{:?}` prints the shortest text that parses back to the
/// same f64 (and switches to exponent form for very small or large values).
pub fn write_row(w: &mut impl Write, r: &StepRecord<'_>) -> std::io::Result<()> {
    write!(w, "{:?}", r.t)?;
    for i in 0..r.q.len() {
        for (_, value) in &JOINT_COLUMNS {
            write!(w, ",{:?}", value(r, i))?;
        }
    }
    write!(w, ",{}", r.effects)?;
    for v in r.own {
        write!(w, ",{v:?}")?;
    }
    writeln!(w)
}
