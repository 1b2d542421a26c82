//! How the processes of a run keep time: [`wire::Mode`], read from the
//! command line.

pub use wire::Mode;

/// `--mode realtime|lockstep` for clap (`value_parser = mode::parse`).
pub fn parse(s: &str) -> Result<Mode, wire::UnknownMode> {
    s.parse()
}
