//! `testbed scenarios`.

/// `testbed scenarios`: name, file and what each shipped scenario shows.
pub(crate) fn scenario_list() -> String {
    let mut out = String::new();
    for s in scenario::SHIPPED {
        out.push_str(&format!("{}\n    {}\n", s.name, s.path().display()));
        let mut line = String::from("   ");
        for word in s.about().split_whitespace() {
            if line.len() + word.len() > 76 {
                out.push_str(&line);
                out.push('\n');
                line = String::from("   ");
            }
            line.push(' ');
            line.push_str(word);
        }
        out.push_str(&line);
        out.push_str("\n\n");
    }
    out.push_str("Run one with `testbed sim --scenario NAME` or `testbed run --scenario NAME`.\n");
    out
}

/// The same list as JSON, for scripts (docs/regenerate.py takes its
/// scenario rows from it): `[{"name", "path", "about"}, …]`.
pub(crate) fn scenario_json() -> anyhow::Result<String> {
    let list: Vec<serde_json::Value> = scenario::SHIPPED
        .iter()
        .map(|s| {
            serde_json::json!({
                "name": s.name,
                "path": s.path().display().to_string(),
                "about": s.about(),
            })
        })
        .collect();
    Ok(serde_json::to_string_pretty(&list)? + "\n")
}
