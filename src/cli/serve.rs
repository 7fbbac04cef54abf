//! `plantwide serve FILE [--scenario S] [--port 8080] [--bind 127.0.0.1] [--allow-host NAME ...]
//! [--set PATH=VALUE ...] [--speed K] [--paused]`: the browser simulator. Loads and converges the plant as `run` does,
//! starts a live run of the scenario (or of none: the plant left to itself) from that steady
//! state, and hands it to the server (`src/serve/`).

use std::net::IpAddr;
use std::path::PathBuf;

use plantwide::flowsheet::scenario::{Limits, ScenarioSpec, parse_scenario, resolve_with};
use plantwide::solve::dynamic::Live;
use plantwide::units::QuantityValue;

use super::CliError;
use super::run::fingerprint;
use super::steady::{converge, load_with_overrides};
use crate::serve::{Options, serve};

/// Options of `plantwide serve`.
#[derive(Debug, clap::Args)]
pub struct ServeArgs {
    /// Flowsheet file (JSON).
    pub file: PathBuf,
    /// Scenario file: its events happen at their times, its sampling, analyzers and integrator
    /// settings apply (default: none; the run goes on until commands move it).
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Port (0: any free one, printed at start).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Address to listen on; any other than 127.0.0.1 or ::1 asks every API request for the token
    /// printed at start (on those two, commands only: the page carries it).
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: IpAddr,
    /// A host name the server answers to besides its address (e.g. the machine's name when bound
    /// beyond loopback); requests naming any other host are refused (DNS rebinding).
    #[arg(long = "allow-host", value_name = "NAME")]
    pub allow_hosts: Vec<String>,
    /// Override an input or a unit parameter, e.g. `--set feed_source.F=1.01kmol/min`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// Clock speed at start (simulated seconds per second).
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    /// Start with the clock stopped.
    #[arg(long)]
    pub paused: bool,
    /// API requests admitted per second (twice as many in a burst); more are answered 429.
    #[arg(long, default_value_t = 200.0)]
    pub rate: f64,
    /// Stop the server after this many seconds (tests).
    #[arg(long, hide = true)]
    pub exit_after: Option<f64>,
}

/// The scenario of a server started without one: nothing happens until commands arrive. Its
/// duration only bounds what a file would ask for (recorded rows, samples).
fn empty_scenario() -> ScenarioSpec {
    ScenarioSpec {
        format_version: 1,
        name: "live".into(),
        description: String::new(),
        duration: QuantityValue::Text("1000 h".into()),
        integrator: Default::default(),
        events: Vec::new(),
        when: Vec::new(),
        sampling: Default::default(),
        analyzers: Default::default(),
        record: Default::default(),
        snapshots: Vec::new(),
    }
}

pub fn run(args: &ServeArgs) -> Result<(), CliError> {
    let user = |e: &dyn std::fmt::Display| CliError::user(e.to_string());
    let text = plantwide::flowsheet::read_text(&args.file).map_err(|e| user(&e))?;
    let (mut plant, u) = load_with_overrides(&args.file, &args.set)?;
    plant.set_input_values(&u);
    let spec = match &args.scenario {
        Some(p) => {
            let name = p.display().to_string();
            parse_scenario(&plantwide::flowsheet::read_text(p).map_err(|e| user(&e))?, &name).map_err(|e| user(&e))?
        }
        None => empty_scenario(),
    };
    let limits = Limits::get();
    let scen_name = args.scenario.as_ref().map_or("(no scenario)".to_string(), |p| p.display().to_string());
    let sc = resolve_with(&spec, &plant, &scen_name, limits).map_err(|e| user(&e))?;
    let x0 = converge(&plant, &u)?.x;
    let live = Live::new(&plant, &x0, &spec, &sc, &fingerprint(&text, &args.set))
        .map_err(|e| CliError::numerical(e.to_string()))?;
    if !(args.rate.is_finite() && args.rate > 0.0) {
        return Err(CliError::user(format!("--rate {}: give a positive number of requests per second", args.rate)));
    }
    let opts = Options {
        bind: args.bind,
        port: args.port,
        speed: args.speed,
        paused: args.paused,
        rate: args.rate,
        allow_hosts: args.allow_hosts.clone(),
        exit_after: args.exit_after,
    };
    serve(live, &opts).map_err(|e| user(&e))
}
