//! One CSV row per control step.

use std::io::Write;

use crate::record::StepRecord;

/// Column names: `t`, then per joint i `q{i} qd{i} qdd{i} tau{i} qref{i}
/// kc{i} z1_{i} z2_{i} wa{i} qm{i} qdm{i} d{i}` (qm, qdm: as measured; d: the
/// disturbance), then `effects` (bits of `plant_rapier::Effects`).
pub fn header(dof: usize) -> String {
    let mut cols = vec!["t".to_string()];
    for i in 0..dof {
        for c in [
            "q", "qd", "qdd", "tau", "qref", "kc", "z1_", "z2_", "wa", "qm", "qdm", "d",
        ] {
            cols.push(format!("{c}{i}"));
        }
    }
    cols.push("effects".into());
    cols.join(",")
}

/// Writes one row. `{:?}` prints the shortest text that parses back to the
/// same f64 (and switches to exponent form for very small or large values).
pub fn write_row(w: &mut impl Write, r: &StepRecord<'_>) -> std::io::Result<()> {
    write!(w, "{:?}", r.t)?;
    for i in 0..r.q.len() {
        write!(
            w,
            ",{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            r.q[i],
            r.qd[i],
            r.qdd[i],
            r.tau[i],
            r.q_d[i],
            r.kc[i],
            r.z1[i],
            r.z2[i],
            r.wa_norm[i],
            r.q_measured[i],
            r.qd_measured[i],
            r.disturbance[i],
        )?;
    }
    writeln!(w, ",{}", r.effects)
}
