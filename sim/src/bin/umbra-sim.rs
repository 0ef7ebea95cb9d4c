//! `umbra-sim`: writes simulator output to files.
//!
//! `umbra-sim capture --out FILE [--revolutions N] [--seed S] [--room-seed R] [--corrupt]`
//! writes raw LDS-01 bytes exactly as a serial port would deliver them, which `umbra replay`
//! reads back.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use sim::corrupt::{Corruption, corrupt};
use sim::lds01::{Lds01Sim, Lds01SimConfig};
use sim::world::World;

#[derive(Parser)]
#[command(
    name = "umbra-sim",
    version,
    about = "umbra's simulator: sensor bytes and datasets"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write a raw LDS-01 capture of a simulated robot in a random room.
    Capture {
        /// Output file.
        #[arg(long)]
        out: PathBuf,
        /// Revolutions to write (5 per second of sensor time).
        #[arg(long, default_value_t = 50)]
        revolutions: usize,
        /// Seed of the sensor noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Seed of the room.
        #[arg(long, default_value_t = 1)]
        room_seed: u64,
        /// Send the bytes through a noisy line (1e-3 bit flips, inserted/dropped bytes, bursts).
        #[arg(long)]
        corrupt: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Capture {
            out,
            revolutions,
            seed,
            room_seed,
            corrupt: noisy,
        } => {
            let mut sim = Lds01Sim::new(
                World::random_room(room_seed),
                Lds01SimConfig::default(),
                seed,
            );
            let mut bytes = Vec::new();
            sim.emit_revolutions(revolutions, &mut bytes);
            if noisy {
                bytes = corrupt(bytes.chunks(42), Corruption::ISSUE_MIX, seed).bytes;
            }
            if let Err(e) = std::fs::write(&out, &bytes) {
                eprintln!("umbra-sim: cannot write {}: {e}", out.display());
                return ExitCode::from(1);
            }
            println!(
                "wrote {} bytes ({revolutions} revolutions) to {}",
                bytes.len(),
                out.display()
            );
            ExitCode::SUCCESS
        }
    }
}
