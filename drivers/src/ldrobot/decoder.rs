//! The streaming LDROBOT decoder: bytes in arbitrary chunks → checked frames of the three
//! types (measurement, health, information).
//!
//! It owns one frame-sized buffer ([`DECODER_BUFFER_LEN`] bytes) and nothing else.
//!
//! ## Framing and resynchronisation
//!
//! 1. **Hunt** for the header `0x54`.
//! 2. **Type:** the next byte says the length (`0x2C`/`0xEC` measurement, `0xE0` health,
//!    `0x0F` information); any other byte rejects the candidate at once.
//! 3. **Collect** the frame and check its CRC-8. A failure is counted and the candidate
//!    rejected: `0x54` also occurs inside distance data, so nothing is trusted before the CRC.
//! 4. **Resync** drops only the rejected candidate's header byte and rescans the bytes already
//!    buffered, as the ROBOTIS driver does ("lidar data may contain head"). The vendor SDK's
//!    state machine instead skips the whole 47 bytes and can lose a good frame that began
//!    inside a bad one; this decoder cannot.
//!
//! Every byte fed is accounted for: `bytes_in == bytes_skipped + bytes of frames yielded +
//! buffered()`, checked by the tests on random streams.

use super::frame::{self, FRAME_LEN, FrameRepr, HEADER, Health};
use crate::framing::{Candidate, skip_to};

/// Bytes the decoder buffers: the longest frame.
pub const DECODER_BUFFER_LEN: usize = FRAME_LEN;

/// One decoded frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Decoded {
    /// A measurement frame.
    Measurement(FrameRepr),
    /// A health report.
    Health(Health),
    /// A manufacture-information frame (content not used).
    Info,
}

/// Counters for every byte and frame the decoder did not pass on cleanly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Bytes fed in.
    pub bytes_in: u64,
    /// Bytes discarded: not part of any frame yielded.
    pub bytes_skipped: u64,
    /// Measurement frames yielded.
    pub frames: u64,
    /// Health and information frames yielded.
    pub other_frames: u64,
    /// Candidates whose CRC failed.
    pub bad_crc: u64,
    /// Headers followed by an unknown type byte.
    pub bad_type: u64,
}

/// The decoder; see the module docs.
#[derive(Debug, Clone, Default)]
pub struct Decoder {
    cand: Candidate<DECODER_BUFFER_LEN>,
    stats: DecoderStats,
}

impl Decoder {
    /// A new decoder.
    pub fn new() -> Self {
        Decoder::default()
    }

    /// Counters.
    pub fn stats(&self) -> &DecoderStats {
        &self.stats
    }

    /// Bytes held in the buffer (a partial frame).
    pub fn buffered(&self) -> usize {
        self.cand.len()
    }

    /// Drops a partial frame (link reset, end of stream), counting its bytes as skipped.
    pub fn reset(&mut self) {
        self.stats.bytes_skipped += self.cand.clear() as u64;
    }

    /// Takes bytes from the front of `input` until one frame is complete and returns it;
    /// `None` once `input` is used up.
    pub fn next_frame(&mut self, input: &mut &[u8]) -> Option<Decoded> {
        loop {
            if self.cand.len() == 0 {
                let skipped = skip_to(input, HEADER) as u64;
                self.stats.bytes_in += skipped;
                self.stats.bytes_skipped += skipped;
                if input.is_empty() {
                    return None;
                }
                // Fast path: a whole good measurement frame in the input, parsed in place.
                if let Some(candidate) = input.get(..FRAME_LEN)
                    && frame::frame_len(candidate[1]) == Some(FRAME_LEN)
                    && frame::crc_ok(candidate)
                {
                    let repr = FrameRepr::parse_unchecked(candidate);
                    self.stats.bytes_in += FRAME_LEN as u64;
                    self.stats.frames += 1;
                    *input = &input[FRAME_LEN..];
                    return Some(Decoded::Measurement(repr));
                }
            }
            // The type byte fixes the length; until it is here, want 2 bytes.
            let want = if let Some(&info) = self.cand.bytes().get(1) {
                match frame::frame_len(info) {
                    Some(n) => n,
                    None => {
                        self.stats.bad_type += 1;
                        self.resync();
                        continue;
                    }
                }
            } else {
                2
            };
            // After a resync the buffer may already hold more than a short (health) frame.
            self.stats.bytes_in += self.cand.fill(input, want) as u64;
            if self.cand.len() < want {
                return None; // input used up
            }
            if want == 2 {
                continue;
            }
            // Bytes buffered past this candidate (only after a resync) stay for the next one.
            let body = &self.cand.bytes()[..want];
            if !frame::crc_ok(body) {
                self.stats.bad_crc += 1;
                self.resync();
                continue;
            }
            let out = match want {
                FRAME_LEN => {
                    self.stats.frames += 1;
                    Decoded::Measurement(FrameRepr::parse_unchecked(body))
                }
                frame::HEALTH_LEN => {
                    self.stats.other_frames += 1;
                    match Health::parse(body) {
                        Some(h) => Decoded::Health(h),
                        None => Decoded::Info, // unreachable: header and CRC checked
                    }
                }
                _ => {
                    self.stats.other_frames += 1;
                    Decoded::Info
                }
            };
            self.cand.consume(want);
            return Some(out);
        }
    }

    /// Rejects the candidate at the front of the buffer: drops its header byte and everything
    /// up to the next `0x54` already buffered.
    fn resync(&mut self) {
        self.stats.bytes_skipped += self.cand.resync(HEADER) as u64;
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::ldrobot::frame::RawPoint;

    fn frame_bytes(start: u16) -> [u8; FRAME_LEN] {
        let f = FrameRepr {
            speed_dps: 2160,
            start_angle_cdeg: start,
            points: [RawPoint {
                distance_mm: 0x5454,
                confidence: 0x54,
            }; 12],
            end_angle_cdeg: start + 1000,
            timestamp_ms: 0x5454,
        };
        let mut b = [0u8; FRAME_LEN];
        f.emit_into(&mut b).unwrap();
        b
    }

    fn decode_all(d: &mut Decoder, bytes: &[u8], chunk: usize) -> usize {
        let mut n = 0;
        for c in bytes.chunks(chunk.max(1)) {
            let mut input = c;
            while let Some(f) = d.next_frame(&mut input) {
                if matches!(f, Decoded::Measurement(_)) {
                    n += 1;
                }
            }
        }
        n
    }

    #[test]
    fn every_chunking_decodes_every_frame() {
        let mut bytes = [0u8; 5 * FRAME_LEN];
        for (k, c) in bytes.chunks_exact_mut(FRAME_LEN).enumerate() {
            c.copy_from_slice(&frame_bytes(1000 * k as u16));
        }
        for chunk in [1, 2, 3, 46, 47, 48, 1000] {
            let mut d = Decoder::new();
            assert_eq!(decode_all(&mut d, &bytes, chunk), 5, "chunk {chunk}");
            assert_eq!(d.stats().bytes_skipped, 0);
        }
    }

    #[test]
    fn a_good_frame_inside_a_bad_one_is_found() {
        // Header bytes of 0x54 inside the payload, a corrupted frame cut short by a good one.
        let good = frame_bytes(500);
        let mut bytes = [0u8; 20 + FRAME_LEN + FRAME_LEN];
        bytes[..20].copy_from_slice(&good[..20]); // truncated candidate
        bytes[20..20 + FRAME_LEN].copy_from_slice(&good);
        bytes[20 + FRAME_LEN..].copy_from_slice(&frame_bytes(1500));
        for chunk in [1, 7, 47, 200] {
            let mut d = Decoder::new();
            assert_eq!(decode_all(&mut d, &bytes, chunk), 2, "chunk {chunk}");
            let s = d.stats();
            assert_eq!(
                s.bytes_in,
                s.bytes_skipped + 2 * FRAME_LEN as u64 + d.buffered() as u64
            );
            assert_eq!(s.bytes_skipped, 20);
        }
    }

    #[test]
    fn health_frames_are_recognised() {
        let mut b = [0u8; 4 + FRAME_LEN];
        Health { error_code: 1 }.emit_into(&mut b[..4]);
        b[4..].copy_from_slice(&frame_bytes(0));
        let mut d = Decoder::new();
        let mut input = &b[..];
        assert_eq!(
            d.next_frame(&mut input),
            Some(Decoded::Health(Health { error_code: 1 }))
        );
        assert!(matches!(
            d.next_frame(&mut input),
            Some(Decoded::Measurement(_))
        ));
    }
}
