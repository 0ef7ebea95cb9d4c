//! `umbra`: the command line of `docs/interfaces.md` §1; the commands live in the library
//! (`firmware::launch`, `firmware::calibrate`, `firmware::report`).
#![deny(unsafe_code)]

use std::process::ExitCode;

use clap::Parser;
use firmware::cli::{Cli, Command};
use firmware::launch::{self, EXIT_USAGE, Failure};

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("info"))
        .format_timestamp(None)
        .init();
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, msg)) => {
            eprintln!("umbra: {msg}");
            ExitCode::from(code)
        }
    }
}

fn dispatch(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Run(args) => launch::run(args),
        Command::Replay(args) => launch::replay(args),
        Command::CalibrateCompass(args) => firmware::calibrate::command(&args),
        Command::Report(args) => {
            let cfg = match &args.config {
                Some(path) => Some(
                    firmware::config::Config::load(path)
                        .map_err(|e| (EXIT_USAGE, e.to_string()))?,
                ),
                None => None,
            };
            let table = firmware::report::from_jsonl(&args.jsonl, cfg.as_ref())
                .map_err(|m| (EXIT_USAGE, m))?;
            print!("{table}");
            Ok(())
        }
    }
}
