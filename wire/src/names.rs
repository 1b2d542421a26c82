//! What a user's name (a run's `--name`, an obstacle's or object's name)
//! may hold: it ends up in folder names, logs, terminals and the 3D view,
//! where a control character or a bidirectional override changes what is
//! shown (a name that reads as another).

/// The first character of `name` that a name may not hold, if any: a
/// control character (newline, tab, escape, …) or a bidirectional
/// formatting character (U+061C, U+200E–U+200F, U+202A–U+202E,
/// U+2066–U+2069), which reorder the text shown after them.
pub fn forbidden_name_char(name: &str) -> Option<char> {
    name.chars().find(|&c| c.is_control() || is_bidi_format(c))
}

/// A character that changes the direction of the text around it.
fn is_bidi_format(c: char) -> bool {
    matches!(c, '\u{061C}' | '\u{200E}' | '\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}')
}

/// How a forbidden character is named in an error: its code point.
pub fn describe_char(c: char) -> String {
    format!("U+{:04X}", c as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controls_and_bidi_overrides_are_found() {
        assert_eq!(forbidden_name_char("arm ü 1"), None);
        assert_eq!(forbidden_name_char("a\nb"), Some('\n'));
        assert_eq!(forbidden_name_char("a\u{1b}[31m"), Some('\u{1b}'));
        assert_eq!(forbidden_name_char("run\u{202E}fdp.exe"), Some('\u{202E}'));
        assert_eq!(forbidden_name_char("x\u{2067}"), Some('\u{2067}'));
        assert_eq!(describe_char('\u{202E}'), "U+202E");
    }
}
