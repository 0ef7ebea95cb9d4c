//! ROBOTIS LDS-01 (HLS-LFCD2) 2D LiDAR: wire format, streaming decoder, revolution assembler.
//!
//! Layers, bottom up:
//!
//! | module        | owns                                                             |
//! |---------------|------------------------------------------------------------------|
//! | [`packet`]    | the 42-byte packet: checked view, parsed form, checksum, `emit`  |
//! | [`decoder`]   | bytes in any chunking → packets; resync; checksum policy; counters |
//! | [`assembler`] | packets → revolutions; missing/repeated packets; sensor clock    |
//! | this module   | [`Lds01Stream`], the two glued together, as a [`RevolutionStream`]   |
//!
//! The revolution type is every model's ([`crate::lidar::revolution`]); an LDS-01 packet is
//! one of its 6° sectors.
//!
//! Everything here is `no_std` and allocation-free; sizes are in `memory-budget.md`.
//!
//! ```
//! use drivers::lds01::{Lds01Config, Lds01Stream, Repr, RawReading, PACKET_LEN};
//! use drivers::lidar::RevolutionStream;
//!
//! // Emit one revolution the way the simulator does, then decode it.
//! let mut bytes = [0u8; 60 * PACKET_LEN];
//! for (k, chunk) in bytes.chunks_exact_mut(PACKET_LEN).enumerate() {
//!     let reading = RawReading { intensity: 500, range_mm: 1500, reserved: 0 };
//!     let repr = Repr { index: k as u8, speed_raw: 3000, readings: [reading; 6] };
//!     repr.emit_into(chunk).unwrap();
//! }
//! let mut stream = Lds01Stream::new(Lds01Config::default());
//! let mut revolutions = 0;
//! stream.feed(&bytes, None, |rev| {
//!     assert!(rev.is_complete());
//!     assert_eq!(rev.valid_count(), 360);
//!     revolutions += 1;
//! });
//! assert_eq!(revolutions, 1);
//! ```

pub mod assembler;
pub mod decoder;
pub mod packet;
/// The revolution type, shared by every model (it lives in [`crate::lidar::revolution`]).
pub mod revolution {
    pub use crate::lidar::revolution::*;
}

pub use crate::lidar::revolution::{Reading, Revolution, bin_angle_rad, raw_to_bin};
use crate::lidar::{LidarFaults, LidarModel, RevolutionStream};
pub use assembler::{Assembler, AssemblerConfig, AssemblerStats};
pub use decoder::{ChecksumPolicy, Decoded, Decoder, DecoderStats};
pub use packet::{
    PACKET_LEN, PACKETS_PER_REV, Packet, READINGS_PER_PACKET, READINGS_PER_REV, RawReading, Repr,
    SYNC_BYTE,
};

/// Serial link settings of the LDS-01 (`docs/hardware.md`).
pub mod link {
    /// Baud rate, 8N1, no flow control.
    pub const BAUD: u32 = 230_400;
    /// Byte that starts the motor on older firmware; harmless on newer.
    pub const START_MOTOR: u8 = b'b';
    /// Byte that stops the motor.
    pub const STOP_MOTOR: u8 = b'e';
    /// Bytes per revolution.
    pub const BYTES_PER_REV: usize = super::PACKETS_PER_REV * super::PACKET_LEN;
}

/// All LDS-01 settings.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Lds01Config {
    /// What a checksum failure means.
    pub checksum: ChecksumPolicy,
    /// Range window and staleness.
    pub assembler: AssemblerConfig,
}

/// The LDS-01's fault counters: the shared set ([`LidarFaults`]).
pub type Lds01Faults = LidarFaults;

/// Decoder and assembler glued together: feed bytes, get revolutions.
#[derive(Debug, Clone)]
pub struct Lds01Stream {
    decoder: Decoder,
    assembler: Assembler,
}

impl Lds01Stream {
    /// A stream with the given settings.
    pub fn new(cfg: Lds01Config) -> Self {
        Lds01Stream {
            decoder: Decoder::new(cfg.checksum),
            assembler: Assembler::new(cfg.assembler),
        }
    }

    /// The decoder (its counters, its policy).
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// The assembler (its counters, the last revolution).
    pub fn assembler(&self) -> &Assembler {
        &self.assembler
    }
}

impl RevolutionStream for Lds01Stream {
    fn model(&self) -> Option<LidarModel> {
        Some(LidarModel::Lds01)
    }

    fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool {
        while let Some(packet) = self.decoder.next_packet(input) {
            if self.assembler.push_packet(&packet, host_us) {
                return true;
            }
        }
        false
    }

    fn last_revolution(&self) -> Option<&Revolution> {
        self.assembler.last()
    }

    fn poll(&mut self, now_us: u64) -> Option<&Revolution> {
        self.assembler.poll(now_us)
    }

    fn finish(&mut self) -> Option<&Revolution> {
        self.decoder.reset();
        self.assembler.flush()
    }

    fn link_reset(&mut self) {
        self.decoder.reset();
    }

    /// Sensor-clock time of the latest packet slot's end, seconds.
    fn sensor_time_s(&self) -> f64 {
        self.assembler.sensor_time_s()
    }

    fn faults(&self) -> LidarFaults {
        let d = self.decoder.stats();
        let a = self.assembler.stats();
        LidarFaults {
            bytes_skipped: d.bytes_skipped,
            bad_checksum: d.bad_checksum,
            bad_index: d.bad_index,
            missing_packets: a.missing_packets,
            repeated_packets: a.repeated_packets,
            out_of_sequence_bad_packets: a.out_of_sequence_bad_packets,
            incomplete_revolutions: a.incomplete_revolutions,
            stalled_packets: a.stalled_packets,
            ..LidarFaults::default()
        }
    }
}

/// Reads once from any `embedded_io::Read` into `buf` and feeds what came into `stream`.
/// Returns the bytes read (0 = end of stream, after which the partial revolution is flushed).
pub fn read_and_feed<R: embedded_io::Read, S: RevolutionStream>(
    io: &mut R,
    buf: &mut [u8],
    stream: &mut S,
    host_us: Option<u64>,
    mut on_revolution: impl FnMut(&Revolution),
) -> Result<usize, R::Error> {
    let n = io.read(buf)?;
    if n == 0 {
        if let Some(rev) = stream.finish() {
            on_revolution(rev);
        }
    } else {
        stream.feed(&buf[..n.min(buf.len())], host_us, &mut on_revolution);
    }
    Ok(n)
}
