//! The LDROBOT wire format (LDS-02 = LD08, LD06, LD19): the 47-byte measurement frame, the
//! 4-byte health frame and the 27-byte information frame, all starting `0x54` and ending in a
//! CRC-8 (`docs/hardware.md` §1a–1b). Checked views that never panic, parsed forms, and `emit` for
//! the simulator and tests.
//!
//! Measurement frame, multi-byte fields little-endian:
//!
//! | offset | size | field                                                |
//! |--------|------|------------------------------------------------------|
//! | 0      | 1    | header `0x54`                                        |
//! | 1      | 1    | `0x2C` (or `0xEC`): type in bits 5–7, 12 points      |
//! | 2      | 2    | speed, degrees per second                            |
//! | 4      | 2    | start angle, 0.01°                                   |
//! | 6      | 36   | 12 × (distance u16 mm, confidence u8)               |
//! | 42     | 2    | end angle, 0.01°                                     |
//! | 44     | 2    | timestamp, ms, wraps at 30000                        |
//! | 46     | 1    | CRC-8 over bytes 0..46                               |
//!
//! The CRC is the MSB-first CRC-8 of polynomial `0x4D`, init 0, no reflection, no final XOR:
//! its check value over `"123456789"` is `0xC3`. The table is generated at compile time from
//! the polynomial rather than pasted from the vendor code.

/// First byte of every LDROBOT frame.
pub const HEADER: u8 = 0x54;
/// Second byte of a measurement frame.
pub const VER_LEN: u8 = 0x2C;
/// Second byte of a measurement frame accepted by the ROBOTIS driver (`0x2C | 0x07 << 5`).
pub const VER_LEN_ALT: u8 = 0xEC;
/// Second byte of a health frame.
pub const HEALTH_INFO: u8 = 0xE0;
/// Second byte of a manufacture-information frame.
pub const INFO_INFO: u8 = 0x0F;
/// Measurement frame length.
pub const FRAME_LEN: usize = 47;
/// Health frame length.
pub const HEALTH_LEN: usize = 4;
/// Manufacture-information frame length.
pub const INFO_LEN: usize = 27;
/// Points per measurement frame.
pub const POINTS: usize = 12;
/// The timestamp field wraps at this many milliseconds.
pub const TIMESTAMP_WRAP_MS: u16 = 30_000;

/// The LDROBOT CRC-8: polynomial 0x4D, init 0, no reflection, no final xor (check 0xC3).
pub const CRC8_LDROBOT: crc::Algorithm<u8> = crc::Algorithm {
    width: 8,
    poly: 0x4D,
    init: 0x00,
    refin: false,
    refout: false,
    xorout: 0x00,
    check: 0xC3,
    residue: 0x00,
};

/// Its 256-entry table, built at compile time by the `crc` crate.
const CRC8: crc::Crc<u8> = crc::Crc::<u8>::new(&CRC8_LDROBOT);

/// CRC-8 of `bytes` (init 0).
pub fn crc8(bytes: &[u8]) -> u8 {
    CRC8.checksum(bytes)
}

/// The frame length that follows header byte 2 `info`, or `None` for an unknown type.
pub const fn frame_len(info: u8) -> Option<usize> {
    match info {
        VER_LEN | VER_LEN_ALT => Some(FRAME_LEN),
        HEALTH_INFO => Some(HEALTH_LEN),
        INFO_INFO => Some(INFO_LEN),
        _ => None,
    }
}

/// `true` if `bytes` (a whole frame of any type) ends in its correct CRC.
pub fn crc_ok(bytes: &[u8]) -> bool {
    match bytes.split_last() {
        Some((&crc, body)) if !body.is_empty() => crc8(body) == crc,
        _ => false,
    }
}

/// Why a buffer is not a measurement frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// Shorter than a frame.
    Truncated,
    /// Not `0x54 0x2C` / `0x54 0xEC`.
    BadHeader,
    /// The CRC does not match.
    BadCrc,
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Error::Truncated => "LDROBOT frame truncated",
            Error::BadHeader => "not an LDROBOT measurement frame header",
            Error::BadCrc => "LDROBOT frame CRC mismatch",
        })
    }
}

impl core::error::Error for Error {}

/// One measured point as sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawPoint {
    /// Distance, mm (0 = no return).
    pub distance_mm: u16,
    /// Confidence / intensity (bit 0: the vendor's "sunshine" flag).
    pub confidence: u8,
}

/// A parsed measurement frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameRepr {
    /// Rotation speed, degrees per second.
    pub speed_dps: u16,
    /// Raw (clockwise) angle of the first point, 0.01°.
    pub start_angle_cdeg: u16,
    /// The 12 points.
    pub points: [RawPoint; POINTS],
    /// Raw angle of the last point, 0.01°.
    pub end_angle_cdeg: u16,
    /// Sensor timestamp, ms, wrapping at 30000.
    pub timestamp_ms: u16,
}

fn le16(b: &[u8], at: usize) -> u16 {
    match (b.get(at), b.get(at + 1)) {
        (Some(&lo), Some(&hi)) => u16::from_le_bytes([lo, hi]),
        _ => 0,
    }
}

impl FrameRepr {
    /// Parses a measurement frame, checking length, header and CRC.
    pub fn parse(bytes: &[u8]) -> Result<FrameRepr, Error> {
        let b = bytes.get(..FRAME_LEN).ok_or(Error::Truncated)?;
        if b[0] != HEADER || !matches!(b[1], VER_LEN | VER_LEN_ALT) {
            return Err(Error::BadHeader);
        }
        if !crc_ok(b) {
            return Err(Error::BadCrc);
        }
        Ok(Self::parse_unchecked(b))
    }

    /// Parses the fields of a frame-length buffer without checking header or CRC (the
    /// decoder has checked them). Short buffers read as zeros; never panics.
    pub fn parse_unchecked(b: &[u8]) -> FrameRepr {
        let mut points = [RawPoint::default(); POINTS];
        for (i, p) in points.iter_mut().enumerate() {
            let at = 6 + 3 * i;
            *p = RawPoint {
                distance_mm: le16(b, at),
                confidence: b.get(at + 2).copied().unwrap_or(0),
            };
        }
        FrameRepr {
            speed_dps: le16(b, 2),
            start_angle_cdeg: le16(b, 4),
            points,
            end_angle_cdeg: le16(b, 42),
            timestamp_ms: le16(b, 44),
        }
    }

    /// Writes the frame, CRC included, into `out[..47]`; `Err(Truncated)` if `out` is short.
    pub fn emit_into(&self, out: &mut [u8]) -> Result<(), Error> {
        let b = out.get_mut(..FRAME_LEN).ok_or(Error::Truncated)?;
        b[0] = HEADER;
        b[1] = VER_LEN;
        b[2..4].copy_from_slice(&self.speed_dps.to_le_bytes());
        b[4..6].copy_from_slice(&self.start_angle_cdeg.to_le_bytes());
        for (i, p) in self.points.iter().enumerate() {
            let at = 6 + 3 * i;
            b[at..at + 2].copy_from_slice(&p.distance_mm.to_le_bytes());
            b[at + 2] = p.confidence;
        }
        b[42..44].copy_from_slice(&self.end_angle_cdeg.to_le_bytes());
        b[44..46].copy_from_slice(&self.timestamp_ms.to_le_bytes());
        b[46] = crc8(&b[..46]);
        Ok(())
    }

    /// Raw (clockwise) angle of point `i` in degrees, by the vendors' rule: the span
    /// `(end + 36000 − start) mod 36000` centidegrees, divided by 11 **in integers** (as the C
    /// code does), then `start + i·step`, wrapped into [0, 360).
    pub fn point_angle_deg(&self, i: usize) -> f32 {
        let step = (self.span_cdeg() / (POINTS as u32 - 1)) as f32 / 100.0;
        let a = f32::from(self.start_angle_cdeg) / 100.0 + i as f32 * step;
        let a = a % 360.0;
        if a < 0.0 { a + 360.0 } else { a }
    }

    /// First to last point, clockwise, 0.01°: `(end + 36000 − start) mod 36000`.
    pub fn span_cdeg(&self) -> u32 {
        let start = u32::from(self.start_angle_cdeg);
        let end = u32::from(self.end_angle_cdeg);
        (end + 36_000 - start % 36_000) % 36_000
    }

    /// The sample rate the frame implies, Hz: speed ÷ angular step between points (2300 for
    /// an LD08, 4500 for an LD06/LD19). `None` for a zero speed or span.
    pub fn sample_rate_hz(&self) -> Option<f32> {
        let step_deg = self.span_cdeg() as f32 / 100.0 / (POINTS - 1) as f32;
        (step_deg > 0.0 && self.speed_dps > 0).then(|| f32::from(self.speed_dps) / step_deg)
    }

    /// The packet span in whole degrees, by the vendors' plausibility rule:
    /// `(end/100 − start/100 + 360) mod 360` with integer division.
    pub fn span_whole_deg(&self) -> u32 {
        let s = u32::from(self.start_angle_cdeg) / 100;
        let e = u32::from(self.end_angle_cdeg) / 100;
        (e + 360 - s % 360) % 360
    }
}

/// A health frame's error code (`0x54 0xE0 code crc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Health {
    /// 0 = healthy; bit 0 = blocked (stalled motor), bit 1 = occluded.
    pub error_code: u8,
}

impl Health {
    /// Parses a 4-byte health frame, checking header and CRC.
    pub fn parse(bytes: &[u8]) -> Option<Health> {
        let b = bytes.get(..HEALTH_LEN)?;
        (b[0] == HEADER && b[1] == HEALTH_INFO && crc_ok(b)).then_some(Health { error_code: b[2] })
    }

    /// Writes the 4-byte frame into `out`; `false` if `out` is short.
    pub fn emit_into(&self, out: &mut [u8]) -> bool {
        let Some(b) = out.get_mut(..HEALTH_LEN) else {
            return false;
        };
        b[0] = HEADER;
        b[1] = HEALTH_INFO;
        b[2] = self.error_code;
        b[3] = crc8(&b[..3]);
        true
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn crc_check_value() {
        // docs/hardware.md §1a: CRC-8 poly 0x4D, init 0, no reflection, no xorout → 0xC3.
        assert_eq!(crc8(b"123456789"), 0xC3);
        // Spot-check against the vendor table's first entries (one byte from init 0 is the
        // table entry itself).
        let first: [u8; 8] = core::array::from_fn(|i| crc8(&[i as u8]));
        assert_eq!(first, [0x00, 0x4d, 0x9a, 0xd7, 0x79, 0x34, 0xe3, 0xae]);
    }

    /// A golden frame: bytes written out by hand from the field table, CRC computed
    /// independently (bit by bit, not through the table).
    #[test]
    fn golden_frame() {
        let mut b = [0u8; FRAME_LEN];
        b[0] = 0x54;
        b[1] = 0x2C;
        b[2..4].copy_from_slice(&[0x68, 0x08]); // 2152 °/s
        b[4..6].copy_from_slice(&[0x10, 0x27]); // 100.00°
        for i in 0..12 {
            let d: u16 = 1000 + 10 * i;
            b[6 + 3 * i as usize..8 + 3 * i as usize].copy_from_slice(&d.to_le_bytes());
            b[8 + 3 * i as usize] = 200;
        }
        b[42..44].copy_from_slice(&[0xB4, 0x2A]); // 109.32°
        b[44..46].copy_from_slice(&[0x2C, 0x01]); // 300 ms
        let mut crc = 0u8;
        for &x in &b[..46] {
            crc ^= x;
            for _ in 0..8 {
                crc = if crc & 0x80 != 0 {
                    (crc << 1) ^ 0x4D
                } else {
                    crc << 1
                };
            }
        }
        b[46] = crc;
        let f = FrameRepr::parse(&b).unwrap();
        assert_eq!(f.speed_dps, 2152);
        assert_eq!(f.start_angle_cdeg, 10_000);
        assert_eq!(f.end_angle_cdeg, 10_932);
        assert_eq!(f.timestamp_ms, 300);
        assert_eq!(f.points[11].distance_mm, 1110);
        // 932 / 11 = 84 (integer) → 0.84° a step.
        assert!((f.point_angle_deg(1) - 100.84).abs() < 1e-3);
        assert!((f.point_angle_deg(11) - 109.24).abs() < 1e-3);
        let mut out = [0u8; FRAME_LEN];
        f.emit_into(&mut out).unwrap();
        assert_eq!(out, b);
        b[20] ^= 1;
        assert_eq!(FrameRepr::parse(&b), Err(Error::BadCrc));
        assert_eq!(FrameRepr::parse(&b[..46]), Err(Error::Truncated));
    }

    #[test]
    fn angles_wrap_through_zero() {
        let f = FrameRepr {
            start_angle_cdeg: 35_900,
            end_angle_cdeg: 50,
            ..FrameRepr::default()
        };
        // diff = 150 → step 13 (integer 150/11) → 0.13°.
        assert!((f.point_angle_deg(0) - 359.0).abs() < 1e-3);
        assert!((f.point_angle_deg(11) - (359.0 + 1.43 - 360.0)).abs() < 1e-3);
        assert_eq!(f.span_whole_deg(), 1);
    }

    #[test]
    fn health_round_trip() {
        let mut b = [0u8; HEALTH_LEN];
        assert!(Health { error_code: 1 }.emit_into(&mut b));
        assert_eq!(Health::parse(&b), Some(Health { error_code: 1 }));
        b[2] = 2;
        assert_eq!(Health::parse(&b), None);
    }
}
