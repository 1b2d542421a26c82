//! A sweep's run keys are pinned: the key is a hash of the run's resolved
//! scenario as written out, so a new scenario field that is written at its
//! default, or a changed default, re-keys every finished sweep (its runs
//! would all be run again). This test fails when that happens; the fix is
//! to skip the new field when it is at its default
//! (`#[serde(skip_serializing_if = …)]`), or, when the runs really differ,
//! to update the key here and say so in the change.

#![allow(clippy::unwrap_used, reason = "test code")]

use std::path::Path;

#[test]
fn a_shipped_sweeps_first_run_keeps_its_key() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sweeps/paper_gains.toml");
    let sweep = scenario::sweep_file::load(&path).unwrap();
    let first = &sweep.runs[0];
    assert_eq!(
        (first.index, first.key.as_str()),
        (0, "dccadadf2677ef59"),
        "the first run of sweeps/paper_gains.toml changed its key (see this file's header)"
    );
}
