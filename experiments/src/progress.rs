//! The progress bar compare and sweep show on a terminal.

/// A bar of `len` runs on standard error, if `show` (a terminal).
pub fn bar(show: bool, len: usize) -> Option<indicatif::ProgressBar> {
    if !show || len == 0 {
        return None;
    }
    let bar = indicatif::ProgressBar::new(len as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{spinner} [{bar:40}] {pos}/{len} runs, {elapsed_precise} elapsed, ETA {eta}",
    ) {
        bar.set_style(style);
    }
    Some(bar)
}
