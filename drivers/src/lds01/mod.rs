//! ROBOTIS LDS-01 (HLS-LFCD2) 2D LiDAR: wire format, streaming decoder, revolution assembler.
//!
//! Layers, bottom up:
//!
//! | module        | owns                                                             |
//! |---------------|------------------------------------------------------------------|
//! | [`packet`]    | the 42-byte packet: checked view, parsed form, checksum, `emit`  |
//! | [`decoder`]   | bytes in any chunking → packets; resync; checksum policy; counters |
//! | [`revolution`]| 360 readings in REP 103 angles, validity, time stamps            |
//! | [`assembler`] | packets → revolutions; missing/repeated packets; sensor clock    |
//! | this module   | [`Lds01Stream`], the two glued together, and [`Lds01Faults`]     |
//!
//! Everything here is `no_std` and allocation-free; sizes are in `memory-budget.md`.
//!
//! ```
//! use drivers::lds01::{Lds01Config, Lds01Stream, Repr, RawReading, PACKET_LEN};
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
pub mod revolution;

pub use assembler::{Assembler, AssemblerConfig, AssemblerStats};
pub use decoder::{ChecksumPolicy, Decoded, Decoder, DecoderStats};
pub use packet::{
    PACKET_LEN, PACKETS_PER_REV, Packet, READINGS_PER_PACKET, READINGS_PER_REV, RawReading, Repr,
    SYNC_BYTE,
};
pub use revolution::{Reading, Revolution, bin_angle_rad, raw_to_bin};

/// Serial link settings of the LDS-01 (`hardware.md`).
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

/// Every LDS-01 fault counter in one place (cumulative since start).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Lds01Faults {
    /// Bytes that were not part of any packet passed on.
    pub bytes_skipped: u64,
    /// Packets whose checksum failed (dropped under `Verify`, kept under `Count`).
    pub bad_checksum: u64,
    /// Sync bytes followed by an out-of-range index.
    pub bad_index: u64,
    /// Packets missing from revolutions handed out.
    pub missing_packets: u64,
    /// Packets received twice in a row.
    pub repeated_packets: u64,
    /// Bad-checksum packets kept by the `Count` policy but dropped for an out-of-sequence index.
    pub out_of_sequence_bad_packets: u64,
    /// Revolutions handed out with packets missing.
    pub incomplete_revolutions: u64,
}

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

    /// Feeds a chunk of bytes; calls `on_revolution` for each revolution it finishes and
    /// returns how many. `host_us` is the host's monotonic clock for this chunk, if any.
    pub fn feed(
        &mut self,
        bytes: &[u8],
        host_us: Option<u64>,
        mut on_revolution: impl FnMut(&Revolution),
    ) -> usize {
        let mut done = 0;
        let mut input = bytes;
        while self.next_revolution(&mut input, host_us) {
            if let Some(rev) = self.assembler.last() {
                on_revolution(rev);
                done += 1;
            }
        }
        done
    }

    /// Consumes bytes from the front of `input` until a revolution is finished (returns
    /// `true`; read it with [`Lds01Stream::last_revolution`]) or `input` is used up (`false`).
    /// This form lets a caller look at the stream's counters between revolutions.
    pub fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool {
        while let Some(packet) = self.decoder.next_packet(input) {
            if self.assembler.push_packet(&packet, host_us) {
                return true;
            }
        }
        false
    }

    /// The last revolution finished.
    pub fn last_revolution(&self) -> Option<&Revolution> {
        self.assembler.last()
    }

    /// Hands out a partial revolution if no packet arrived for the stale time.
    pub fn poll(&mut self, now_us: u64, on_revolution: impl FnOnce(&Revolution)) -> bool {
        self.assembler.poll(now_us).map(on_revolution).is_some()
    }

    /// End of stream: drops a partial packet and hands out a partial revolution.
    pub fn finish(&mut self, on_revolution: impl FnOnce(&Revolution)) -> bool {
        self.decoder.reset();
        self.assembler.flush().map(on_revolution).is_some()
    }

    /// The link was lost and reopened: a partial packet cannot continue.
    pub fn link_reset(&mut self) {
        self.decoder.reset();
    }

    /// The decoder (its counters, its policy).
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// The assembler (its counters, the last revolution).
    pub fn assembler(&self) -> &Assembler {
        &self.assembler
    }

    /// Sensor-clock time of the latest packet slot's end, seconds.
    pub fn sensor_time_s(&self) -> f64 {
        self.assembler.sensor_time_s()
    }

    /// All fault counters.
    pub fn faults(&self) -> Lds01Faults {
        let d = self.decoder.stats();
        let a = self.assembler.stats();
        Lds01Faults {
            bytes_skipped: d.bytes_skipped,
            bad_checksum: d.bad_checksum,
            bad_index: d.bad_index,
            missing_packets: a.missing_packets,
            repeated_packets: a.repeated_packets,
            out_of_sequence_bad_packets: a.out_of_sequence_bad_packets,
            incomplete_revolutions: a.incomplete_revolutions,
        }
    }
}

/// Reads once from any `embedded_io::Read` into `buf` and feeds what came into `stream`.
/// Returns the bytes read (0 = end of stream, after which the partial revolution is flushed).
pub fn read_and_feed<R: embedded_io::Read>(
    io: &mut R,
    buf: &mut [u8],
    stream: &mut Lds01Stream,
    host_us: Option<u64>,
    mut on_revolution: impl FnMut(&Revolution),
) -> Result<usize, R::Error> {
    let n = io.read(buf)?;
    if n == 0 {
        stream.finish(on_revolution);
    } else {
        stream.feed(&buf[..n.min(buf.len())], host_us, &mut on_revolution);
    }
    Ok(n)
}
