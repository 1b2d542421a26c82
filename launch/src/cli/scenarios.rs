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
