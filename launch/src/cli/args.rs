//! The arguments of the subcommands.

use std::path::PathBuf;

use clap::Args;

use super::NodeName;
use run_stack::mode::Mode;

#[derive(Debug, Args)]
pub(crate) struct ScenarioArgs {
    /// Scenario file (TOML), or the name of a shipped one (`testbed
    /// scenarios` lists them) [default: the paper's, scenarios/paper.toml].
    #[arg(long, value_name = "FILE|NAME")]
    pub(crate) scenario: Option<PathBuf>,
    /// Run this arm (URDF) instead of the scenario's; with no --scenario,
    /// the default scenario for the arm (see `testbed robot`).
    #[arg(long, value_name = "URDF")]
    pub(crate) robot: Option<PathBuf>,
    /// Run for this many seconds instead of the scenario's duration_s.
    #[arg(long, value_name = "S")]
    pub(crate) duration: Option<f64>,
    /// Run this law instead of the scenario's: T_c, K1 and K2 are the
    /// scenario's, keys the law does not take are reset.
    #[arg(long, value_name = "LAW", value_parser = law_parser())]
    pub(crate) law: Option<controller::LawName>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
    /// Write one row per control step to this CSV file.
    #[arg(long, value_name = "FILE")]
    pub(crate) csv: Option<PathBuf>,
    /// Set one scenario key (repeatable), checked like the file:
    /// `--set plant.engine=rapier --set controller.k1=20`. The value is
    /// TOML (`[1.0, 2.0]`, `true`); a bare word is a string.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = scenario::parse_set)]
    pub(crate) set: Vec<(String, toml::Value)>,
}

#[derive(Debug, Args)]
pub(crate) struct SimArgs {
    #[command(flatten)]
    pub(crate) common: ScenarioArgs,
    /// Write the paper's figures (PNG and SVG: positions, velocities, error
    /// against the envelope, weights and torques) into this folder.
    #[arg(long, value_name = "DIR")]
    pub(crate) plots: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub(crate) struct RunArgs {
    #[command(flatten)]
    pub(crate) common: ScenarioArgs,
    /// Timing mode: realtime or lockstep.
    #[arg(long, value_parser = run_stack::mode::parse, default_value = "realtime")]
    pub(crate) mode: Mode,
    /// Control rate in Hz instead of the scenario's rate_hz.
    #[arg(long, value_name = "HZ")]
    pub(crate) rate: Option<f64>,
    /// Do not start this node; wait for one started by hand (repeatable).
    #[arg(long, value_enum, value_name = "NODE")]
    pub(crate) external: Vec<NodeName>,
    /// Folder for run folders.
    #[arg(long, value_name = "DIR", default_value = "runs")]
    pub(crate) runs_dir: PathBuf,
    /// Name the run's folder (RUNS_DIR/NAME; default: `<epoch seconds>-<pid>`);
    /// refused if it exists.
    #[arg(long, value_name = "NAME", value_parser = parse_run_name)]
    pub(crate) name: Option<String>,
    /// Leave the nodes where the OS puts them: no CPU pinning, and in real
    /// time no SCHED_FIFO and no locked memory.
    #[arg(long)]
    pub(crate) no_realtime_setup: bool,
    /// Run this command as the controller node instead of the testbed's
    /// (for example "python3 my_controller.py"; see python/). The launcher
    /// appends the node arguments and supervises it like any node.
    #[arg(long, value_name = "CMD", conflicts_with = "external")]
    pub(crate) controller_cmd: Option<String>,
    /// Chunk compression of the log: zstd (smallest), lz4 or none (the
    /// logger's cheapest, ten times larger; in lockstep the logger paces
    /// the run).
    #[arg(long, value_name = "KIND", default_value = "zstd", value_parser = logger::LogCompression::parse)]
    pub(crate) log_compression: logger::LogCompression,
    /// Serve the run live to Foxglove (Open connection → Foxglove
    /// WebSocket → ws://ADDR:PORT) from the logger. Without a value:
    /// 127.0.0.1:8765.
    #[arg(
        long,
        value_name = "ADDR:PORT",
        num_args = 0..=1,
        default_missing_value = "127.0.0.1:8765",
        value_parser = parse_live_addr
    )]
    pub(crate) live: Option<std::net::SocketAddr>,
    /// Samples per topic and second of sim time sent live (the log keeps
    /// every one).
    #[arg(long, value_name = "HZ", requires = "live", default_value_t = logger::live::DEFAULT_RATE_HZ, value_parser = parse_live_rate)]
    pub(crate) live_rate: f64,
    /// Most live viewers at once (1 to 64); the next one is refused with
    /// HTTP 503 and a reason. Each costs the logger a bounded queue.
    #[arg(long, value_name = "N", requires = "live", default_value_t = logger::live::DEFAULT_MAX_CLIENTS, value_parser = parse_live_clients)]
    pub(crate) live_clients: usize,
}

/// `ADDR:PORT` of `--live`, a host name (localhost) resolved.
fn parse_live_addr(s: &str) -> Result<std::net::SocketAddr, String> {
    use std::net::ToSocketAddrs;
    s.to_socket_addrs()
        .map_err(|e| format!("{s:?} is not ADDR:PORT ({e})"))?
        .next()
        .ok_or_else(|| format!("{s:?} names no address"))
}

/// `NAME=CMD` of `compare --controller-cmd`.
fn parse_external_law(s: &str) -> Result<(String, String), String> {
    let (name, cmd) = s
        .split_once('=')
        .ok_or_else(|| format!("{s:?} is not NAME=CMD (e.g. pid=\"python3 my.py\")"))?;
    if !run_stack::run::external::is_law_name(name) {
        return Err(format!(
            "{name:?} is not a row name (1 to 40 of a-z, 0-9, '-', '_')"
        ));
    }
    Ok((name.to_string(), cmd.to_string()))
}

/// A run folder's name: one path component of printable characters
/// (`run_stack::run::run_name_problem`).
fn parse_run_name(s: &str) -> Result<String, String> {
    match run_stack::run::run_name_problem(s) {
        None => Ok(s.to_string()),
        Some(why) => {
            let shown: String = s.chars().take(40).collect();
            Err(format!("{shown:?} is not a run folder name: {why}"))
        }
    }
}

fn parse_live_clients(s: &str) -> Result<usize, String> {
    let max = logger::live::MAX_CLIENTS_LIMIT;
    match s.parse::<usize>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!("{s:?} is not a number of clients from 1 to {max}")),
    }
}

fn parse_live_rate(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("{s:?} is not a positive number of Hz")),
    }
}

/// The words of a `--controller-cmd`, split as a POSIX shell would
/// (quotes kept together), with no shell in between.
pub(crate) fn command_words(cmd: &str) -> anyhow::Result<Vec<String>> {
    let words = shell_words::split(cmd)
        .map_err(|e| anyhow::anyhow!("--controller-cmd {cmd:?} cannot be split into words: {e}"))?;
    if words.is_empty() {
        anyhow::bail!("--controller-cmd is empty: give the program to run");
    }
    Ok(words)
}

#[derive(Debug, Args)]
pub(crate) struct BenchArgs {
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
    /// Length of each real-time part and of the timer floor, s.
    #[arg(long, value_name = "S", default_value_t = 60.0)]
    pub(crate) realtime_s: f64,
    /// Repeats of the in-process and lockstep parts (medians are reported).
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub(crate) repeats: usize,
    /// Shorten every scenario to this many seconds (quick check).
    #[arg(long, value_name = "S")]
    pub(crate) duration: Option<f64>,
    /// The large arm to measure besides the paper's (any shipped arm's
    /// default scenario runs at 1 kHz; the UR5 keeps the figures comparable
    /// with earlier benches).
    #[arg(long, value_name = "URDF", default_value = "robots/ur5.urdf")]
    pub(crate) large_arm: PathBuf,
    /// Folder for run folders.
    #[arg(long, value_name = "DIR", default_value = "runs")]
    pub(crate) runs_dir: PathBuf,
    /// Measure without pinning, SCHED_FIFO or locked memory.
    #[arg(long)]
    pub(crate) no_realtime_setup: bool,
    /// Chunk compression of the log: zstd (smallest), lz4 or none (the
    /// logger's cheapest, ten times larger; in lockstep the logger paces
    /// the run).
    #[arg(long, value_name = "KIND", default_value = "zstd", value_parser = logger::LogCompression::parse)]
    pub(crate) log_compression: logger::LogCompression,
    /// Run this law instead of the scenarios' (with --controller-cmd: the
    /// law the testbed's controller runs, whose parameters the command gets).
    #[arg(long, value_name = "LAW", value_parser = law_parser())]
    pub(crate) law: Option<controller::LawName>,
    /// Measure only this controller command against the testbed's own
    /// controller: real-time runs of the paper scenario at its rate, in
    /// --repeats pairs, each beside the timer floor.
    #[arg(long, value_name = "CMD")]
    pub(crate) controller_cmd: Option<String>,
    /// Measure only the paper scenario in lockstep against the Python +
    /// MuJoCo loop a user would write instead (python/peer/mujoco_loop.py),
    /// in --repeats alternating pairs.
    #[arg(long, conflicts_with = "controller_cmd")]
    pub(crate) peer: bool,
    /// Measure only the Gymnasium environment from Python: env.step a
    /// second (one two-link arm), arm-steps a second (64 arms in one
    /// vector call; two-link and iiwa14), beside Gymnasium's MuJoCo
    /// Reacher-v5 in the same run (python/bench/gym_steps.py; build the
    /// module with `bash python/build-module.sh --release`).
    #[arg(long, conflicts_with_all = ["controller_cmd", "peer"])]
    pub(crate) gym: bool,
    /// The Python that runs the loop of --peer or --gym (set up by `bash
    /// python/setup-venv.sh --peer` and `bash python/build-module.sh`).
    #[arg(
        long,
        value_name = "CMD",
        default_value = "target/python-venv/bin/python3"
    )]
    pub(crate) peer_python: String,
}

#[derive(Debug, Args)]
pub(crate) struct ReplayArgs {
    /// The run's MCAP log (`runs/<id>/run.mcap`).
    #[arg(value_name = "FILE.mcap")]
    pub(crate) log: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
    /// Write one row per control step to this CSV file.
    #[arg(long, value_name = "FILE")]
    pub(crate) csv: Option<PathBuf>,
    /// Write the paper's figures (PNG and SVG) and a timing figure here.
    #[arg(long, value_name = "DIR")]
    pub(crate) plots: Option<PathBuf>,
    /// Re-drive the controller from the logged states and references and
    /// report the largest difference from the logged torques.
    #[arg(long)]
    pub(crate) verify: bool,
}

#[derive(Debug, Args)]
pub(crate) struct CompareArgs {
    /// Scenario file (TOML), or the name of a shipped one [default: the paper's].
    #[arg(long, value_name = "FILE|NAME")]
    pub(crate) scenario: Option<PathBuf>,
    /// Run this arm (URDF) instead of the scenario's; with no --scenario,
    /// the default scenario for the arm.
    #[arg(long, value_name = "URDF")]
    pub(crate) robot: Option<PathBuf>,
    /// Run for this many seconds instead of the scenario's duration_s.
    #[arg(long, value_name = "S")]
    pub(crate) duration: Option<f64>,
    /// Set one scenario key (repeatable), checked like the file, e.g.
    /// `--set controller.tc=3`.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = scenario::parse_set)]
    pub(crate) set: Vec<(String, toml::Value)>,
    /// The laws, comma-separated [default: every law but pd-gravity].
    #[arg(long, value_name = "LAW,…", value_delimiter = ',', value_parser = law_parser())]
    pub(crate) laws: Vec<controller::LawName>,
    /// Your own controller as a row of the table (repeatable):
    /// `--controller-cmd pid="python3 python/examples/pid.py"`. Each seed
    /// runs it through the lockstep stack, given the scenario's law's
    /// gains; its run folders go under --runs-dir.
    #[arg(long, value_name = "NAME=CMD", value_parser = parse_external_law)]
    pub(crate) controller_cmd: Vec<(String, String)>,
    /// Folder for the run folders of --controller-cmd rows.
    #[arg(long, value_name = "DIR", default_value = "runs")]
    pub(crate) runs_dir: PathBuf,
    /// Seeds per law: the scenario's seed, seed + 1, … (table: median and worst).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub(crate) seeds: u64,
    /// Worker threads [default: one per CPU].
    #[arg(long, value_name = "N")]
    pub(crate) threads: Option<usize>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
    /// Write one row per law and seed, with every metric, to this CSV file.
    #[arg(long, value_name = "FILE")]
    pub(crate) csv: Option<PathBuf>,
    /// Write the comparison figures (PNG and SVG) here.
    #[arg(long, value_name = "DIR")]
    pub(crate) plots: Option<PathBuf>,
    /// How ctc, cbf-ctc, mpc and ppc turn K1, K2 into their gains: `matched` gives every
    /// law pd's error dynamics near e = 0 (docs/baselines.md §6)
    /// [default: matched with --findings; else the scenario's, as-given
    /// unless it says otherwise].
    #[arg(long, value_name = "RULE", value_parser = ["as-given", "matched"])]
    pub(crate) tuning: Option<String>,
    /// Trade-off mode: run every law with K1 and K2 times each of these
    /// scales and report IAE after T_c against effort (a Pareto front per law).
    #[arg(long, value_name = "S,…", value_delimiter = ',')]
    pub(crate) gain_scales: Vec<f64>,
    /// One law's own key (repeatable), e.g. `--law-set
    /// mpc:controller.mpc_step=0.02`: set on that law's runs only, so a
    /// baseline's own keys need no change of the scenario's law.
    #[arg(long = "law-set", value_name = "LAW:controller.KEY=VALUE", value_parser = parse_law_set)]
    pub(crate) law_set: Vec<experiments::compare::LawSet>,
    /// Print, after the table, which of the paper's claims hold on this
    /// scenario and the numbers they rest on (the JSON always has them).
    /// Without --tuning, the laws then run under matched tuning: a claim
    /// that one law beats another is made on a fair fight.
    #[arg(long)]
    pub(crate) findings: bool,
}

/// `--law-set LAW:controller.KEY=VALUE` ([`experiments::compare::LawSet`]'s
/// reader, which `testbed.compare(law_sets=…)` shares).
fn parse_law_set(arg: &str) -> Result<experiments::compare::LawSet, String> {
    arg.parse()
}

/// `--law` and `--laws`: the names come from the law table, and `--help`
/// lists them.
fn law_parser() -> impl clap::builder::TypedValueParser<Value = controller::LawName> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(controller::LawName::ALL.iter().map(|l| l.as_str()))
        .try_map(|s| s.parse::<controller::LawName>())
}

#[derive(Debug, Args)]
pub(crate) struct TuneArgs {
    /// Print LAW's search space (every key a tuner searches, its range and
    /// scale, from the parameter table) and exit; needs no Python.
    #[arg(long, value_name = "LAW", value_parser = law_parser())]
    pub(crate) print_space: Option<controller::LawName>,
    /// Print what a study file found (the same as `testbed tune report FILE`).
    #[arg(long, value_name = "STUDY", conflicts_with = "print_space")]
    pub(crate) report: Option<PathBuf>,
    /// The Python that has the `testbed` module and Optuna (`bash
    /// python/build-module.sh` makes one; or the wheel's `tune` extra)
    /// [default: $TESTBED_PYTHON, else target/python-venv/bin/python3].
    #[arg(long, value_name = "CMD")]
    pub(crate) python: Option<String>,
    /// Everything else goes to `python -m testbed.tune` (its `run`,
    /// `report`, `best`, `evaluate`; `testbed tune run --help` lists the
    /// options), e.g. `testbed tune run --law nac --scenario
    /// paper_randomised --trials 200`.
    #[arg(
        trailing_var_arg = true,
        allow_hyphen_values = true,
        value_name = "ARGS",
        conflicts_with_all = ["print_space", "report"]
    )]
    pub(crate) args: Vec<String>,
}
