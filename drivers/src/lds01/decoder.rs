//! The streaming LDS-01 decoder: bytes in arbitrary chunks → checked packets.
//!
//! It owns one packet-sized buffer ([`DECODER_BUFFER_LEN`] bytes) and nothing else. Bytes are
//! taken as they come: a chunk may end mid-packet, start with garbage, or hold many packets.
//!
//! ## Framing and resynchronisation
//!
//! 1. **Hunt:** bytes are skipped until a sync byte `0xFA`.
//! 2. **Index:** the next byte must be `0xA0..=0xDB`; if not, the candidate is rejected at
//!    once (counted in [`DecoderStats::bad_index`]).
//! 3. **Collect** 42 bytes, then check the checksum. A pass yields the packet. A failure is
//!    counted in [`DecoderStats::bad_checksum`]; under [`ChecksumPolicy::Verify`] the packet is
//!    dropped, under [`ChecksumPolicy::Count`] it is yielded with `checksum_ok == false`.
//! 4. **Resync** after a rejected candidate drops only its first byte and rescans the bytes
//!    already buffered for the next `0xFA`. No byte that could start a real packet is ever
//!    thrown away, so a good packet that begins inside a bad candidate (garbage, an inserted
//!    or dropped byte) is still found: the decoder is back in step within one packet's length
//!    of the end of the garbage.
//!
//! Every byte fed is accounted for: `bytes_in == bytes_skipped + 42·packets + buffered()`,
//! an invariant the tests check on random streams.

use super::packet::{PACKET_LEN, Packet, Repr, SYNC_BYTE, is_index_byte};
use crate::framing::{Candidate, skip_to};

/// Bytes the decoder buffers: exactly one packet.
pub const DECODER_BUFFER_LEN: usize = PACKET_LEN;

/// What a checksum failure means. The LDS-01 checksum rule is unconfirmed on real hardware
/// (see `docs/hardware.md`), hence a setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChecksumPolicy {
    /// Drop packets whose checksum fails (and count them). The default.
    #[default]
    Verify,
    /// Keep packets whose checksum fails, flag and count them.
    Count,
}

/// Counters for every byte and packet the decoder did not pass on cleanly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Bytes fed in.
    pub bytes_in: u64,
    /// Bytes discarded: not part of any packet yielded.
    pub bytes_skipped: u64,
    /// Packets yielded (under `Count` this includes the bad-checksum ones).
    pub packets: u64,
    /// Candidates whose checksum failed (dropped under `Verify`, kept under `Count`).
    pub bad_checksum: u64,
    /// Candidates whose index byte was outside `0xA0..=0xDB`.
    pub bad_index: u64,
}

/// One decoded packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Decoded {
    /// The parsed packet.
    pub repr: Repr,
    /// `false` only under [`ChecksumPolicy::Count`] for a packet whose checksum failed.
    pub checksum_ok: bool,
}

/// The streaming decoder. Allocation-free; `const`-constructible so it can live in a `static`.
#[derive(Debug, Clone)]
pub struct Decoder {
    cand: Candidate<DECODER_BUFFER_LEN>,
    policy: ChecksumPolicy,
    stats: DecoderStats,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new(ChecksumPolicy::default())
    }
}

impl Decoder {
    /// A decoder with the given checksum policy.
    pub const fn new(policy: ChecksumPolicy) -> Self {
        Decoder {
            cand: Candidate::new(),
            policy,
            stats: DecoderStats {
                bytes_in: 0,
                bytes_skipped: 0,
                packets: 0,
                bad_checksum: 0,
                bad_index: 0,
            },
        }
    }

    /// The checksum policy in force.
    pub fn policy(&self) -> ChecksumPolicy {
        self.policy
    }

    /// Counters since construction.
    pub fn stats(&self) -> &DecoderStats {
        &self.stats
    }

    /// Bytes held in the buffer waiting for the rest of a packet.
    pub fn buffered(&self) -> usize {
        self.cand.len()
    }

    /// Drops any partial packet (counted as skipped), e.g. after the link was reopened.
    pub fn reset(&mut self) {
        self.stats.bytes_skipped += self.cand.clear() as u64;
    }

    /// Iterates over the packets in `input`, continuing any packet begun by earlier chunks.
    /// Bytes of an unfinished packet at the end stay buffered for the next call.
    ///
    /// Dropping the iterator early leaves the unread part of `input` unconsumed (not counted).
    pub fn feed<'d, 'i>(&'d mut self, input: &'i [u8]) -> Feed<'d, 'i> {
        Feed {
            decoder: self,
            input,
        }
    }

    /// Takes bytes from the front of `input` until one packet is complete, and returns it;
    /// `None` once `input` is used up. The building block of [`Decoder::feed`].
    pub fn next_packet(&mut self, input: &mut &[u8]) -> Option<Decoded> {
        loop {
            if self.cand.len() == 0 {
                // Hunt for sync in the input itself: no copying of garbage.
                let skipped = skip_to(input, SYNC_BYTE) as u64;
                self.stats.bytes_in += skipped;
                self.stats.bytes_skipped += skipped;
                if input.is_empty() {
                    return None;
                }
            }
            // Fast path: a whole packet in the input with a good checksum is parsed in place.
            if self.cand.len() == 0
                && let Some(candidate) = input.get(..PACKET_LEN)
                && let Ok(packet) = Packet::new_checked(candidate)
                && packet.checksum_ok()
            {
                let repr = Repr::parse(&packet);
                self.stats.bytes_in += PACKET_LEN as u64;
                self.stats.packets += 1;
                *input = &input[PACKET_LEN..];
                return Some(Decoded {
                    repr,
                    checksum_ok: true,
                });
            }
            // Anything else takes the general path below, which counts and resyncs.
            self.stats.bytes_in += self.cand.fill(input, DECODER_BUFFER_LEN) as u64;

            if self.cand.bytes().get(1).is_some_and(|&b| !is_index_byte(b)) {
                self.stats.bad_index += 1;
                self.resync();
                continue;
            }
            if self.cand.len() < DECODER_BUFFER_LEN {
                return None;
            }
            // Sync and index were checked above and the length is exact: this cannot fail,
            // but stay panic-free and treat a failure as a bad candidate.
            let Ok(packet) = Packet::new_checked(self.cand.bytes()) else {
                self.resync();
                continue;
            };
            let checksum_ok = packet.checksum_ok();
            if !checksum_ok {
                self.stats.bad_checksum += 1;
                if self.policy == ChecksumPolicy::Verify {
                    self.resync();
                    continue;
                }
            }
            let repr = Repr::parse(&packet);
            self.cand.clear();
            self.stats.packets += 1;
            return Some(Decoded { repr, checksum_ok });
        }
    }

    /// Rejects the candidate at the front of the buffer: drops its sync byte and everything
    /// up to the next `0xFA` already buffered.
    fn resync(&mut self) {
        self.stats.bytes_skipped += self.cand.resync(SYNC_BYTE) as u64;
    }
}

/// Iterator over the packets of one chunk; see [`Decoder::feed`].
#[derive(Debug)]
pub struct Feed<'d, 'i> {
    decoder: &'d mut Decoder,
    input: &'i [u8],
}

impl Iterator for Feed<'_, '_> {
    type Item = Decoded;

    fn next(&mut self) -> Option<Decoded> {
        self.decoder.next_packet(&mut self.input)
    }
}

#[cfg(test)]
mod test {
    use super::super::packet::RawReading;
    use super::*;

    fn packet(k: u8, fill: u16) -> [u8; PACKET_LEN] {
        let mut readings = [RawReading::default(); 6];
        for (j, r) in readings.iter_mut().enumerate() {
            *r = RawReading {
                intensity: fill,
                range_mm: fill.wrapping_add(j as u16),
                reserved: 0,
            };
        }
        let mut buf = [0u8; PACKET_LEN];
        Repr {
            index: k,
            speed_raw: 3000,
            readings,
        }
        .emit_into(&mut buf)
        .unwrap();
        buf
    }

    fn collect(d: &mut Decoder, bytes: &[u8]) -> std::vec::Vec<Decoded> {
        d.feed(bytes).collect()
    }

    fn assert_accounting(d: &Decoder) {
        let s = d.stats();
        assert_eq!(
            s.bytes_in,
            s.bytes_skipped + PACKET_LEN as u64 * s.packets + d.buffered() as u64
        );
    }

    #[test]
    fn byte_at_a_time() {
        let mut d = Decoder::default();
        let mut out = std::vec::Vec::new();
        for k in 0..3u8 {
            for b in packet(k, 100) {
                out.extend(d.feed(&[b]));
            }
        }
        assert_eq!(
            out.iter()
                .map(|p| p.repr.index)
                .collect::<std::vec::Vec<_>>(),
            [0, 1, 2]
        );
        assert_eq!(d.stats().bytes_skipped, 0);
        assert_accounting(&d);
    }

    #[test]
    fn garbage_before_and_between() {
        let mut d = Decoder::default();
        let mut s = std::vec::Vec::new();
        s.extend_from_slice(&[0x00, 0xFA, 0x13, 0xFA, 0xFA, 0xA1, 0x55]);
        s.extend_from_slice(&packet(7, 0xFAFA));
        s.extend_from_slice(&[0xFA, 0xA0, 0xFA]);
        s.extend_from_slice(&packet(8, 0xFA));
        let out = collect(&mut d, &s);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].repr.index, 7);
        assert_eq!(out[1].repr.index, 8);
        assert!(out.iter().all(|p| p.checksum_ok));
        assert_accounting(&d);
        assert_eq!(d.stats().bytes_skipped, 10);
    }

    #[test]
    fn good_packet_inside_bad_candidate_is_found() {
        // A truncated packet (dropped tail) followed directly by a good one: the bad
        // candidate swallows the start of the good packet, which must still come out.
        let mut d = Decoder::default();
        let mut s = std::vec::Vec::new();
        s.extend_from_slice(&packet(1, 10)[..30]);
        s.extend_from_slice(&packet(2, 20));
        let out = collect(&mut d, &s);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].repr.index, 2);
        assert_eq!(d.stats().bad_checksum, 1);
        assert_accounting(&d);
    }

    #[test]
    fn checksum_policy() {
        let mut bad = packet(3, 1234);
        bad[20] ^= 0x04;
        let mut v = Decoder::new(ChecksumPolicy::Verify);
        assert!(collect(&mut v, &bad).is_empty());
        assert_eq!(v.stats().bad_checksum, 1);
        assert_accounting(&v);

        let mut c = Decoder::new(ChecksumPolicy::Count);
        let out = collect(&mut c, &bad);
        assert_eq!(out.len(), 1);
        assert!(!out[0].checksum_ok);
        assert_eq!(c.stats().bad_checksum, 1);
        assert_accounting(&c);
    }

    #[test]
    fn bad_index_rejected_early() {
        let mut d = Decoder::default();
        let mut p = packet(0, 5);
        p[1] = 0xDC;
        let out = collect(&mut d, &p);
        assert!(out.is_empty());
        assert_eq!(d.stats().bad_index, 1);
        assert_eq!(d.stats().bad_checksum, 0);
        assert_accounting(&d);
    }

    #[test]
    fn reset_counts_partial() {
        let mut d = Decoder::default();
        assert!(collect(&mut d, &packet(0, 5)[..20]).is_empty());
        assert_eq!(d.buffered(), 20);
        d.reset();
        assert_eq!(d.buffered(), 0);
        assert_eq!(d.stats().bytes_skipped, 20);
        assert_accounting(&d);
    }
}
