//! # umbra sim
//!
//! A TurtleBot3 in seeded random rooms whose sensors put out what the real parts put on their
//! wires, so that the simulated robot exercises the same decoders as a real one; with the
//! ground truth of every reading for training and scoring. Every run takes a seed and is
//! reproducible: same seed, byte-identical output.
//!
//! | module        | owns                                                                 |
//! |---------------|----------------------------------------------------------------------|
//! | [`world`]     | rooms (rectangle, L, two rooms + corridor), doors, furniture, clutter; its spatial index and ray caster (`world::grid`) |
//! | [`robot`]     | differential drive (Burger constants), slip, encoders, motion scripts |
//! | [`compass`]   | magnetometer: earth field, hard iron, noise, local disturbances       |
//! | [`lds01`]     | LDS-01 reading model and the packet byte source                       |
//! | [`people`]    | people walking through a scenario: paths, stance-and-swing gait, giving way |
//! | [`scenario`]  | world + robot + sensors stepped one revolution (frame) at a time      |
//! | [`split`]     | which split a dataset's scenario lands in; each scenario's seed      |
//! | [`labels`]    | Method B boxes from footprints, per-reading labels                    |
//! | `dataset`     | dataset writers: YOLO layout, Method A labels, replay recordings (feature `tools`) |
//! | [`noise`]     | the bounded, unit-σ noise every sensor model draws from               |
//! | `picture`     | a PNG of a scene for people to look at (feature `tools`)              |
//! | [`wear`]      | a real unit's wear: returns fading with range, mixed pixels at depth edges |
//! | [`power`]     | a unit that returns by the light it receives (reflectivity · cos / range²) |
//! | [`wire`]      | every LiDAR model's bytes from the same simulated revolutions          |
//! | [`corrupt`]   | a noisy serial line: bit flips, inserted and dropped bytes, with truth |
//! | `pty`         | devices on pseudo-terminals for hardware-in-the-loop tests (feature `pty`) |
#![deny(unsafe_code, missing_docs)]

pub mod compass;
pub mod corrupt;
#[cfg(feature = "tools")]
pub mod dataset;
pub mod labels;
pub mod lds01;
pub mod noise;
pub mod people;
#[cfg(feature = "tools")]
pub mod picture;
pub mod power;
#[cfg(feature = "pty")]
pub mod pty;
pub mod robot;
pub mod scenario;
pub mod split;
pub mod wear;
pub mod wire;
pub mod world;
