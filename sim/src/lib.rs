//! # umbra sim
//!
//! A simulated robot whose sensors emit the bytes the real parts put on their wires, so that
//! the simulated robot exercises the same decoders as a real one. Every run takes a seed and is
//! reproducible.
//!
//! | module      | owns                                                                |
//! |-------------|---------------------------------------------------------------------|
//! | [`world`]   | a seeded rectangular room with box obstacles; ray casting            |
//! | [`lds01`]   | the LDS-01: per-reading timing, rpm jitter, noise, dropouts, packets |
//! | [`corrupt`] | a noisy serial line: bit flips, inserted and dropped bytes, with truth |
//!
//! The full simulator (room shapes, doors, furniture classes, encoders, compass, datasets)
//! grows here with its issue; this first cut is what the LiDAR driver and `umbra run` need.
#![deny(unsafe_code, missing_docs)]

pub mod corrupt;
pub mod lds01;
pub mod world;
