//! # umbra drivers
//!
//! Wire protocols and devices for the umbra perception runtime. The protocol layers are
//! `no_std` and allocation-free: they build for bare-metal targets (CI builds them for
//! `thumbv7em-none-eabihf` and links a binary with no allocator). The `std` feature adds the
//! host-side transports.
//!
//! | module      | owns                                                          | needs  |
//! |-------------|---------------------------------------------------------------|--------|
//! | [`lidar`]   | the revolution every model yields, the `RevolutionStream` trait, auto-detection | core |
//! | [`lds01`]   | LDS-01 packets, streaming decoder, revolution assembler        | core   |
//! | [`ldrobot`] | LDS-02 (LD08), LD06, LD19: 47-byte CRC-8 frames → revolutions  | core   |
//! | [`rplidar`] | RPLIDAR A1/A2: SCAN descriptor, 5-byte nodes, motor sequences  | core   |
//! | `compass`   | LSM303AGR magnetometer over embedded-hal 1.0 I²C (`lsm303agr`), bounded waits | `compass` |
//! | [`dynamixel`] | DYNAMIXEL Protocol 2.0 (OpenCR): CRC-16, stuffing, instruction emit, status decoder | core |
//! | `serial`    | serial ports via `serialport`, as `embedded-io`; reopen with back-off | `std`  |
//! | `probe`     | which LiDAR is on a port: baud rates tried, bytes recognised, diagnosis | `std` |
//! | `opencr`    | OpenCR wheel encoders over DYNAMIXEL 2.0, timeouts, counted errors | `std`  |
//!
//! ## Guarantees
//!
//! * No byte from a device is trusted: every parser validates before it reads, no accessor of
//!   a checked view can panic, and every dropped byte, packet or reading is counted.
//! * No heap in the protocol layers; every buffer is a named constant listed in
//!   `memory-budget.md` at the repository root.
//!
//! ## Features
//!
//! * `std` (default): the `serial` module.
//! * `defmt`: `defmt::Format` on every public data and error type.
//!
//! MSRV: the workspace's `rust-version`.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(unsafe_code, missing_docs)]

#[cfg(feature = "compass")]
pub mod compass;
pub mod dynamixel;
mod framing;
pub mod ldrobot;
pub mod lds01;
pub mod lidar;
#[cfg(feature = "std")]
pub mod opencr;
#[cfg(feature = "std")]
pub mod probe;
pub mod rplidar;
#[cfg(feature = "std")]
pub mod serial;
