//! # umbra firmware
//!
//! The `umbra` binary's parts, as a library so that the end-to-end tests can drive them.
//!
//! | module          | owns                                                                 |
//! |-----------------|----------------------------------------------------------------------|
//! | [`cli`]         | the command line of `docs/interfaces.md` §1                          |
//! | [`config`]      | the TOML configuration: defaults, validation, what each stage gets   |
//! | [`launch`]      | `umbra run` / `umbra replay`: source, pose input, Method B, sinks, report |
//! | [`calibrate`]   | `umbra calibrate-compass`: readings, hard-iron fit, coverage, config write |
//! | [`source`]      | LiDAR byte sources: serial port, capture, recording, CARMEN log, simulated robot |
//! | [`reader`]      | reader threads: the LiDAR port's pooled chunks, the OpenCR/compass device thread, clock mapping |
//! | [`carmen`]      | CARMEN logs as a revolution stream with their odometry               |
//! | [`odom`]        | odometry/compass samples (`--odom`, devices, simulator, recordings) → pose |
//! | [`runner`]      | the frame loop: ingest → pose → Method A → Method B → fusion → outputs |
//! | [`scene_line`]  | the human-readable line: pose, objects by class with ids, doors, frame time |
//! | [`sink`]        | where frames go: the `FrameSink` trait, JSON lines, statistics lines |
//! | [`output`]      | the JSON output line (§3) and the per-revolution statistics line     |
//! | [`deadline`]    | stage histograms, budgets, the overrun policy, the deadline table    |
//! | [`power`]       | watts from an INA219, the Pi 5 PMIC or a CPU-time model; the budget  |
//! | [`link_watch`]  | the log's word on a silent LiDAR or a stalled motor                  |
//! | [`realtime`]    | SCHED_FIFO and locked memory for the frame loop, on request          |
//! | [`snapshot`]    | `--snapshot PATH.svg`: the map, robot, walls, doors and objects as a picture |
//! | [`record_format`] | the replay channels of a recording, shared by writer and reader    |
//! | `viz`           | `--record` MCAP and `--live` Foxglove WebSocket (feature `viz`)      |
//! | `recording`     | replay of umbra's own MCAP recordings (feature `viz`)                |
//! | `term_view`     | `--view`: a live map in the terminal, ratatui (feature `view`)       |
//! | [`report`]      | `umbra report OUT.jsonl`: the deadline and power table of a run      |
//!
//! Features: `method-b` (tract and the compiled-in YOLO model), `viz` (MCAP and the live
//! Foxglove view), `sim` (the built-in simulated robot), `view` (the terminal map); all four on
//! by default.
#![deny(unsafe_code, missing_docs)]

pub mod calibrate;
pub mod carmen;
pub mod cli;
pub mod config;
pub mod deadline;
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
pub mod scene_line;
pub mod sink;
pub mod snapshot;
pub mod source;
#[cfg(feature = "view")]
pub mod term_view;
#[cfg(feature = "viz")]
pub mod viz;
