//! # umbra firmware
//!
//! The `umbra` binary's parts, as a library so that the end-to-end tests can drive them.
//!
//! | module       | owns                                                        |
//! |--------------|-------------------------------------------------------------|
//! | [`calibrate`] | `umbra calibrate-compass`: hard-iron fit, coverage check, config write |
//! | [`cli`]      | the command line of `interfaces.md` §1                      |
//! | [`config`]   | the TOML configuration, defaults and validation             |
//! | [`source`]   | LiDAR byte sources: serial port, capture file, simulated robot |
//! | [`runner`]   | the frame loop: ingest → output, limits, pacing             |
//! | [`odom`]     | odometry/compass input (`--odom` JSON Lines, the simulated robot) → pose |
//! | [`output`]   | the JSON output line (§3) and per-revolution statistics     |
//! | [`deadline`] | stage histograms, budgets, the overrun policy, the deadline table |
//! | [`power`]    | watts from an INA219, the Pi 5 PMIC or a CPU-time model; the budget |
//! | [`snapshot`] | `--snapshot PATH.svg`: the map, robot, walls, doors and objects as a picture |
//! | `viz`        | `--record` MCAP and `--live` Foxglove WebSocket (feature `viz`) |
//! | [`report`]   | `umbra report OUT.jsonl`: the deadline and power table of a run |
#![deny(unsafe_code, missing_docs)]

pub mod calibrate;
pub mod carmen;
pub mod cli;
pub mod config;
pub mod deadline;
pub mod frames;
pub mod launch;
pub mod link_watch;
pub mod odom;
pub mod output;
pub mod power;
pub mod reader;
pub mod realtime;
pub mod record_format;
#[cfg(feature = "viz")]
pub mod recording;
pub mod report;
pub mod runner;
pub mod sink;
pub mod snapshot;
pub mod source;
#[cfg(feature = "viz")]
pub mod viz;
