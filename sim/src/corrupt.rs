//! A noisy serial line: independent bit flips, inserted and dropped bytes, and garbage bursts
//! between packets, applied to a stream of packets with a record of which packets came through
//! untouched. Seeded and reproducible; the tests and benchmarks measure the decoder with it.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Corruption rates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corruption {
    /// Probability that any one bit is flipped.
    pub bit_flip: f64,
    /// Probability that a random byte is inserted before any one byte.
    pub insert: f64,
    /// Probability that any one byte is dropped.
    pub drop: f64,
    /// Probability that a burst of 1–64 random bytes precedes a packet.
    pub burst: f64,
    /// At most this many bits flipped per packet (`u32::MAX`: independent flips, no cap).
    pub max_flips_per_packet: u32,
}

impl Corruption {
    /// No corruption.
    pub const NONE: Corruption = Corruption {
        bit_flip: 0.0,
        insert: 0.0,
        drop: 0.0,
        burst: 0.0,
        max_flips_per_packet: u32::MAX,
    };

    /// The acceptance mix of the foundation issue: bit flips at 1e-3 per bit plus inserted and
    /// dropped bytes (1e-4 per byte each) and occasional garbage bursts (1 % of packets).
    pub const ISSUE_MIX: Corruption = Corruption {
        bit_flip: 1e-3,
        insert: 1e-4,
        drop: 1e-4,
        burst: 0.01,
        max_flips_per_packet: u32::MAX,
    };
}

/// A corrupted stream and what happened to each packet.
#[derive(Debug, Clone, Default)]
pub struct Corrupted {
    /// The bytes as received.
    pub bytes: Vec<u8>,
    /// Per input packet: `true` if none of its bytes was flipped, dropped or had a byte
    /// inserted before it.
    pub untouched: Vec<bool>,
    /// Bits flipped.
    pub flips: u64,
    /// Bytes inserted (bursts included).
    pub inserted: u64,
    /// Bytes dropped.
    pub dropped: u64,
}

/// Sends `packets` (each one packet's bytes) through the noisy line.
pub fn corrupt<'a>(
    packets: impl IntoIterator<Item = &'a [u8]>,
    c: Corruption,
    seed: u64,
) -> Corrupted {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Corrupted::default();
    for packet in packets {
        if c.burst > 0.0 && rng.random_bool(c.burst) {
            let n = rng.random_range(1..=64);
            out.bytes.extend((0..n).map(|_| rng.random::<u8>()));
            out.inserted += n;
        }
        let mut clean = true;
        let mut flips = 0u32;
        for &byte in packet {
            if c.insert > 0.0 && rng.random_bool(c.insert) {
                out.bytes.push(rng.random());
                out.inserted += 1;
                clean = false;
            }
            if c.drop > 0.0 && rng.random_bool(c.drop) {
                out.dropped += 1;
                clean = false;
                continue;
            }
            let mut b = byte;
            if c.bit_flip > 0.0 {
                for bit in 0..8 {
                    if rng.random_bool(c.bit_flip) && flips < c.max_flips_per_packet {
                        flips += 1;
                        b ^= 1 << bit;
                        out.flips += 1;
                        clean = false;
                    }
                }
            }
            out.bytes.push(b);
        }
        out.untouched.push(clean);
    }
    out
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn none_is_identity() {
        let packets = [[1u8; 42], [2u8; 42]];
        let out = corrupt(packets.iter().map(|p| &p[..]), Corruption::NONE, 1);
        assert_eq!(out.bytes, [[1u8; 42], [2u8; 42]].concat());
        assert_eq!(out.untouched, [true, true]);
    }

    #[test]
    fn rates_are_roughly_right() {
        let packets = vec![[0u8; 42]; 10_000];
        let out = corrupt(packets.iter().map(|p| &p[..]), Corruption::ISSUE_MIX, 2);
        let bits = 10_000.0 * 42.0 * 8.0;
        let rate = out.flips as f64 / bits;
        assert!((0.8e-3..1.2e-3).contains(&rate), "flip rate {rate}");
        let touched = out.untouched.iter().filter(|u| !**u).count();
        // 1 − (1 − 1e-3)^336 · (1 − 1e-4)^84 ≈ 29 %.
        assert!((2_500..3_300).contains(&touched), "{touched} touched");
    }
}
