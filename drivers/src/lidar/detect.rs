//! Which LiDAR speaks in a byte stream: every family's decoder runs over the same bytes and
//! the one that explains them wins (`--lidar-model auto`, `docs/hardware.md` §1d.1–2).
//!
//! * **LDS-01:** `0xFA` + index `0xA0..=0xDB` + a good checksum.
//! * **LDROBOT:** `0x54 0x2C` + a good CRC-8. The model follows from the frame itself: the
//!   angular step between points and the speed field give the sample rate (speed ÷ step),
//!   2300 Hz for the LDS-02 (LD08), 4500 Hz for the LD06/LD19 (which send the same bytes;
//!   reported as LD06).
//! * **RPLIDAR:** the SCAN descriptor, and nodes that pass the bit test **and** continue the
//!   previous node's sweep (a clockwise step under 5°): random bytes pass the bit test one
//!   time in eight, but almost never form such a chain. A1 and A2 are told apart by the baud
//!   rate only (reported as A1 from a capture).
//!
//! [`Detector`] is fed chunks (a port prober feeds it as bytes arrive) and gives a
//! [`Verdict`]: the model with its frame count and error rate, or a specific diagnosis:
//! no bytes at all, bytes but no valid frame, frames but a high error rate. Fixed memory,
//! `no_std`.

use super::LidarModel;
use crate::ldrobot::{self, frame::FRAME_LEN as LD_FRAME_LEN};
use crate::lds01::{self, PACKET_LEN as LDS01_PACKET_LEN};
use crate::rplidar::{self, NODE_LEN};

/// Share of the bytes a family must explain to be called found.
pub const MIN_EXPLAINED: f32 = 0.5;
/// Valid units (packets, frames, chained nodes) needed before a verdict is "found".
pub const MIN_UNITS: u64 = 10;
/// Error rate (bad / (good + bad) candidates) above which the verdict is "high error rate".
pub const MAX_ERROR_RATE: f32 = 0.2;
/// Largest clockwise step between chained RPLIDAR nodes, degrees.
pub const RPLIDAR_MAX_STEP_DEG: f32 = 5.0;

/// What the bytes say.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Verdict {
    /// Nothing arrived.
    NoBytes,
    /// Bytes, but no valid frame of any family.
    NoFrames {
        /// Bytes seen.
        bytes: u64,
    },
    /// A family's frames, but with too many errors to trust (wrong baud, bad cable, noise).
    HighErrorRate {
        /// The best guess.
        model: LidarModel,
        /// Valid units.
        units: u64,
        /// Error rate, 0..1.
        error_rate: f32,
    },
    /// Found.
    Found {
        /// The model.
        model: LidarModel,
        /// Valid units.
        units: u64,
        /// Error rate, 0..1.
        error_rate: f32,
    },
}

/// Per-family tallies.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tally {
    /// Valid units.
    pub units: u64,
    /// Rejected candidates.
    pub errors: u64,
    /// Bytes the valid units cover.
    pub bytes: u64,
}

impl Tally {
    fn error_rate(&self) -> f32 {
        let n = self.units + self.errors;
        if n == 0 {
            0.0
        } else {
            self.errors as f32 / n as f32
        }
    }
}

/// The detector; see the module docs.
#[derive(Debug, Clone, Default)]
pub struct Detector {
    bytes: u64,
    lds01: lds01::Decoder,
    ldrobot: ldrobot::Decoder,
    rplidar: rplidar::Decoder,
    rp_last_deg: Option<f32>,
    rp_chained: u64,
    rp_descriptor: bool,
    /// Sample-rate estimates of LDROBOT frames: (near 2300, near 4500).
    ld_rate_votes: (u32, u32),
}

impl Detector {
    /// A new detector.
    pub fn new() -> Self {
        Detector::default()
    }

    /// Bytes seen.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Feeds bytes.
    pub fn feed(&mut self, bytes: &[u8]) {
        self.bytes += bytes.len() as u64;
        let mut input = bytes;
        while self.lds01.next_packet(&mut input).is_some() {}
        let mut input = bytes;
        while let Some(item) = self.ldrobot.next_frame(&mut input) {
            if let ldrobot::Decoded::Measurement(f) = item
                && let Some(rate) = f.sample_rate_hz()
            {
                if rate < 3400.0 {
                    self.ld_rate_votes.0 += 1;
                } else {
                    self.ld_rate_votes.1 += 1;
                }
            }
        }
        let mut input = bytes;
        while let Some(item) = self.rplidar.next_item(&mut input) {
            match item {
                rplidar::Decoded::Node(n) => {
                    let a = n.angle_deg();
                    if let Some(last) = self.rp_last_deg {
                        let step = (a - last + 360.0) % 360.0;
                        if step > 0.0 && step < RPLIDAR_MAX_STEP_DEG {
                            self.rp_chained += 1;
                        }
                    }
                    self.rp_last_deg = Some(a);
                }
                rplidar::Decoded::Descriptor(d) => {
                    self.rp_descriptor |= d == rplidar::SCAN_DESCRIPTOR;
                }
                _ => {}
            }
        }
    }

    /// Tallies of the three families: LDS-01, LDROBOT, RPLIDAR.
    pub fn tallies(&self) -> [(LidarModel, Tally); 3] {
        let l = self.lds01.stats();
        let d = self.ldrobot.stats();
        let r = self.rplidar.stats();
        let ld_model = if self.ld_rate_votes.0 > self.ld_rate_votes.1 {
            LidarModel::Lds02
        } else {
            LidarModel::Ld06
        };
        [
            (
                LidarModel::Lds01,
                Tally {
                    units: l.packets,
                    errors: l.bad_checksum + l.bad_index,
                    bytes: l.packets * LDS01_PACKET_LEN as u64,
                },
            ),
            (
                ld_model,
                Tally {
                    units: d.frames,
                    errors: d.bad_crc + d.bad_type,
                    bytes: d.frames * LD_FRAME_LEN as u64,
                },
            ),
            (
                LidarModel::RplidarA1,
                Tally {
                    units: self.rp_chained,
                    errors: r.nodes - self.rp_chained.min(r.nodes),
                    bytes: self.rp_chained * NODE_LEN as u64,
                },
            ),
        ]
    }

    /// `true` if a SCAN descriptor was seen.
    pub fn saw_rplidar_descriptor(&self) -> bool {
        self.rp_descriptor
    }

    /// The verdict so far.
    pub fn verdict(&self) -> Verdict {
        if self.bytes == 0 {
            return Verdict::NoBytes;
        }
        let tallies = self.tallies();
        let best = tallies
            .iter()
            .max_by(|a, b| a.1.bytes.cmp(&b.1.bytes))
            .copied();
        let Some((model, t)) = best.filter(|(_, t)| t.units > 0) else {
            return Verdict::NoFrames { bytes: self.bytes };
        };
        let explained = t.bytes as f32 / self.bytes as f32;
        let error_rate = t.error_rate();
        if t.units >= MIN_UNITS && explained >= MIN_EXPLAINED && error_rate <= MAX_ERROR_RATE {
            Verdict::Found {
                model,
                units: t.units,
                error_rate,
            }
        } else if t.units >= MIN_UNITS / 2 && (explained >= 0.05 || self.rp_descriptor) {
            Verdict::HighErrorRate {
                model,
                units: t.units,
                error_rate: error_rate.max(1.0 - explained),
            }
        } else {
            Verdict::NoFrames { bytes: self.bytes }
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn lcg(seed: &mut u64) -> u8 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 33) as u8
    }

    #[test]
    fn no_bytes_and_noise_are_diagnosed() {
        let d = Detector::new();
        assert_eq!(d.verdict(), Verdict::NoBytes);
        let mut d = Detector::new();
        let mut seed = 7;
        let mut noise = [0u8; 20_000];
        noise.iter_mut().for_each(|b| *b = lcg(&mut seed));
        d.feed(&noise);
        assert!(
            matches!(d.verdict(), Verdict::NoFrames { bytes: 20_000 }),
            "{:?} {:?}",
            d.verdict(),
            d.tallies()
        );
    }
}
