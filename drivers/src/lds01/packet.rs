//! The LDS-01 42-byte packet: a checked view over bytes ([`Packet`]), the plain parsed form
//! ([`Repr`]), the checksum, and `emit` into a caller buffer.
//!
//! Layout (little-endian), from `docs/hardware.md`:
//!
//! | bytes  | meaning                                                        |
//! |--------|----------------------------------------------------------------|
//! | 0      | sync `0xFA`                                                    |
//! | 1      | index `0xA0 + k`, k = 0..59 (6° per packet)                    |
//! | 2..4   | motor speed, rpm × 10 (u16)                                    |
//! | 4..40  | 6 readings × 6 bytes: intensity u16, range u16 (mm), reserved u16 |
//! | 40, 41 | checksum, sent twice                                           |
//!
//! The checksum rule is the community one, `0xFF − (Σ bytes 0..=39 mod 256)` in byte 40 with
//! byte 41 equal to byte 40. It is **unconfirmed on real bytes**, so validating a packet's
//! framing ([`Packet::new_checked`]) and its checksum ([`Packet::checksum_ok`]) are separate
//! steps and the decoder's [`ChecksumPolicy`](super::ChecksumPolicy) decides what a failure means.
//!
//! The pattern is smoltcp's `wire` module: byte offsets live in a private `field` module,
//! `new_checked` validates once, and after that no accessor can panic.

use core::fmt;

/// Length of one packet on the wire, in bytes.
pub const PACKET_LEN: usize = 42;
/// The first byte of every packet.
pub const SYNC_BYTE: u8 = 0xFA;
/// Index byte of packet 0; packet k carries `INDEX_BASE + k`.
pub const INDEX_BASE: u8 = 0xA0;
/// Packets in one revolution.
pub const PACKETS_PER_REV: usize = 60;
/// Readings in one packet.
pub const READINGS_PER_PACKET: usize = 6;
/// Readings in one revolution (1° apart).
pub const READINGS_PER_REV: usize = PACKETS_PER_REV * READINGS_PER_PACKET;
/// Index byte of the last packet of a revolution (`0xDB`).
pub const INDEX_LAST: u8 = INDEX_BASE + PACKETS_PER_REV as u8 - 1;

mod field {
    use core::ops::Range;

    pub const SYNC: usize = 0;
    pub const INDEX: usize = 1;
    pub const SPEED: Range<usize> = 2..4;
    pub const READINGS: usize = 4;
    pub const READING_LEN: usize = 6;
    pub const INTENSITY: Range<usize> = 0..2;
    pub const RANGE: Range<usize> = 2..4;
    pub const RESERVED: Range<usize> = 4..6;
    /// Bytes covered by the checksum.
    pub const CHECKED: Range<usize> = 0..40;
    pub const CHECKSUM: usize = 40;
    pub const CHECKSUM_DUP: usize = 41;
}

/// Why a byte slice is not an LDS-01 packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// Fewer than [`PACKET_LEN`] bytes.
    Truncated,
    /// Byte 0 is not [`SYNC_BYTE`].
    BadSync,
    /// Byte 1 is outside `0xA0..=0xDB`.
    BadIndex,
    /// Bytes 40/41 do not carry the checksum of bytes 0..=39.
    BadChecksum,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Error::Truncated => "LDS-01 packet truncated (need 42 bytes)",
            Error::BadSync => "LDS-01 packet does not start with 0xFA",
            Error::BadIndex => "LDS-01 packet index outside 0xA0..=0xDB",
            Error::BadChecksum => "LDS-01 packet checksum mismatch",
        })
    }
}

impl core::error::Error for Error {}

/// Result of packet operations.
pub type Result<T> = core::result::Result<T, Error>;

/// The checksum of the 40 checked bytes: `0xFF − (Σ bytes mod 256)`.
pub fn checksum(checked: &[u8]) -> u8 {
    // Eight bytes at a time: the even and odd bytes of each word are added into four 16-bit
    // lanes, kept mod 256 (only the sum mod 256 matters, and no lane can carry into the next),
    // then the lanes are summed. A byte loop compiles to a 40-add dependency chain.
    const LANES: u64 = 0x00FF_00FF_00FF_00FF;
    let mut words = checked.chunks_exact(8);
    let mut lanes = 0u64;
    for w in &mut words {
        let mut b = [0u8; 8];
        b.copy_from_slice(w);
        let w = u64::from_le_bytes(b);
        lanes = (lanes + (w & LANES) + ((w >> 8) & LANES)) & LANES;
    }
    let lanes = lanes.wrapping_mul(0x0001_0001_0001_0001) >> 48;
    let tail = words
        .remainder()
        .iter()
        .fold(0u8, |a, &b| a.wrapping_add(b));
    0xFF - (lanes as u8).wrapping_add(tail)
}

/// `true` if `byte` is a valid index byte (`0xA0..=0xDB`).
#[inline]
pub const fn is_index_byte(byte: u8) -> bool {
    byte >= INDEX_BASE && byte <= INDEX_LAST
}

/// A read/write view over the bytes of one packet.
///
/// Built with [`Packet::new_checked`], every accessor is infallible: the length, the sync byte
/// and the index range were checked once. The checksum is not part of that check; ask
/// [`Packet::checksum_ok`].
#[derive(Debug, Clone)]
pub struct Packet<T: AsRef<[u8]>> {
    buffer: T,
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Wraps a buffer without checking it. Accessors may panic if it is shorter than
    /// [`PACKET_LEN`]; use this only on buffers about to be filled by [`Repr::emit`].
    pub const fn new_unchecked(buffer: T) -> Packet<T> {
        Packet { buffer }
    }

    /// Wraps a buffer after checking its length, sync byte and index range.
    pub fn new_checked(buffer: T) -> Result<Packet<T>> {
        let packet = Self::new_unchecked(buffer);
        packet.check_len()?;
        let bytes = packet.buffer.as_ref();
        if bytes[field::SYNC] != SYNC_BYTE {
            return Err(Error::BadSync);
        }
        if !is_index_byte(bytes[field::INDEX]) {
            return Err(Error::BadIndex);
        }
        Ok(packet)
    }

    /// Checks that the buffer holds at least a whole packet.
    pub fn check_len(&self) -> Result<()> {
        if self.buffer.as_ref().len() < PACKET_LEN {
            Err(Error::Truncated)
        } else {
            Ok(())
        }
    }

    /// Gives the buffer back.
    pub fn into_inner(self) -> T {
        self.buffer
    }

    /// Packet number within the revolution, 0..=59.
    pub fn index(&self) -> u8 {
        self.buffer.as_ref()[field::INDEX].wrapping_sub(INDEX_BASE)
    }

    /// Motor speed field: rpm × 10.
    pub fn speed_raw(&self) -> u16 {
        self.u16_at(field::SPEED.start)
    }

    /// Intensity of reading `j` (0..6); `j` is taken modulo 6.
    pub fn intensity(&self, j: usize) -> u16 {
        self.u16_at(Self::reading_offset(j) + field::INTENSITY.start)
    }

    /// Range of reading `j` (0..6) in millimetres, 0 = no return; `j` is taken modulo 6.
    pub fn range_mm(&self, j: usize) -> u16 {
        self.u16_at(Self::reading_offset(j) + field::RANGE.start)
    }

    /// The two reserved bytes of reading `j` (0..6); `j` is taken modulo 6.
    pub fn reserved(&self, j: usize) -> u16 {
        self.u16_at(Self::reading_offset(j) + field::RESERVED.start)
    }

    /// The checksum byte (byte 40).
    pub fn checksum(&self) -> u8 {
        self.buffer.as_ref()[field::CHECKSUM]
    }

    /// The repeated checksum byte (byte 41).
    pub fn checksum_dup(&self) -> u8 {
        self.buffer.as_ref()[field::CHECKSUM_DUP]
    }

    /// `true` if bytes 40 and 41 both equal the checksum of bytes 0..=39.
    pub fn checksum_ok(&self) -> bool {
        let bytes = self.buffer.as_ref();
        let c = checksum(&bytes[field::CHECKED]);
        bytes[field::CHECKSUM] == c && bytes[field::CHECKSUM_DUP] == c
    }

    fn reading_offset(j: usize) -> usize {
        field::READINGS + (j % READINGS_PER_PACKET) * field::READING_LEN
    }

    fn u16_at(&self, at: usize) -> u16 {
        let b = self.buffer.as_ref();
        u16::from_le_bytes([b[at], b[at + 1]])
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Packet<T> {
    fn set_u16_at(&mut self, at: usize, value: u16) {
        self.buffer.as_mut()[at..at + 2].copy_from_slice(&value.to_le_bytes());
    }

    /// Writes the sync byte and packet number `k` (taken modulo 60).
    pub fn set_header(&mut self, k: u8) {
        let b = self.buffer.as_mut();
        b[field::SYNC] = SYNC_BYTE;
        b[field::INDEX] = INDEX_BASE + k % PACKETS_PER_REV as u8;
    }

    /// Writes the speed field (rpm × 10).
    pub fn set_speed_raw(&mut self, value: u16) {
        self.set_u16_at(field::SPEED.start, value);
    }

    /// Writes reading `j` (taken modulo 6).
    pub fn set_reading(&mut self, j: usize, reading: RawReading) {
        let at = Self::reading_offset(j);
        self.set_u16_at(at + field::INTENSITY.start, reading.intensity);
        self.set_u16_at(at + field::RANGE.start, reading.range_mm);
        self.set_u16_at(at + field::RESERVED.start, reading.reserved);
    }

    /// Computes the checksum of bytes 0..=39 and writes it to bytes 40 and 41.
    pub fn fill_checksum(&mut self) {
        let b = self.buffer.as_mut();
        let c = checksum(&b[field::CHECKED]);
        b[field::CHECKSUM] = c;
        b[field::CHECKSUM_DUP] = c;
    }
}

/// One reading as it is on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RawReading {
    /// Return strength (unitless, 0..~13,000 on real units; not a "no return" flag).
    pub intensity: u16,
    /// Range in millimetres; 0 = no return.
    pub range_mm: u16,
    /// The two reserved bytes, kept so that `parse` → `emit` is byte-exact.
    pub reserved: u16,
}

/// A parsed packet: plain data, no borrowed bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Repr {
    /// Packet number within the revolution, 0..=59.
    pub index: u8,
    /// Motor speed, rpm × 10.
    pub speed_raw: u16,
    /// The six readings, raw reading numbers `6·index + j`.
    pub readings: [RawReading; READINGS_PER_PACKET],
}

impl Repr {
    /// Parses a checked packet. The checksum is not looked at (see the module docs).
    pub fn parse<T: AsRef<[u8]>>(packet: &Packet<T>) -> Repr {
        let mut readings = [RawReading::default(); READINGS_PER_PACKET];
        for (j, r) in readings.iter_mut().enumerate() {
            *r = RawReading {
                intensity: packet.intensity(j),
                range_mm: packet.range_mm(j),
                reserved: packet.reserved(j),
            };
        }
        Repr {
            index: packet.index(),
            speed_raw: packet.speed_raw(),
            readings,
        }
    }

    /// Bytes that [`Repr::emit`] writes.
    pub const fn buffer_len(&self) -> usize {
        PACKET_LEN
    }

    /// Motor speed in revolutions per minute.
    pub fn rpm(&self) -> f32 {
        f32::from(self.speed_raw) / 10.0
    }

    /// Writes this packet, with a valid checksum, into `packet`.
    ///
    /// # Panics
    /// If `packet` is shorter than [`PACKET_LEN`] (use [`Repr::emit_into`] for a checked call).
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) {
        packet.set_header(self.index);
        packet.set_speed_raw(self.speed_raw);
        for (j, r) in self.readings.iter().enumerate() {
            packet.set_reading(j, *r);
        }
        packet.fill_checksum();
    }

    /// Writes this packet into the first [`PACKET_LEN`] bytes of `buf`.
    pub fn emit_into(&self, buf: &mut [u8]) -> Result<()> {
        let buf = buf.get_mut(..PACKET_LEN).ok_or(Error::Truncated)?;
        self.emit(&mut Packet::new_unchecked(buf));
        Ok(())
    }
}

#[cfg(test)]
mod test {
    use super::*;

    /// A packet built by hand from the layout table: index 5, 301.2 rpm, readings
    /// (intensity, range) = (1000, 500), (0, 0), (13182, 4200), (7, 120), (256, 3500), (1, 1).
    static PACKET_BYTES: [u8; 42] = [
        0xFA, 0xA5, 0xC4, 0x0B, // sync, index 0xA0+5, 3012 = 301.2 rpm
        0xE8, 0x03, 0xF4, 0x01, 0x00, 0x00, // 1000, 500 mm
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // no return
        0x7E, 0x33, 0x68, 0x10, 0x00, 0x00, // 13182, 4200 mm
        0x07, 0x00, 0x78, 0x00, 0x00, 0x00, // 7, 120 mm
        0x00, 0x01, 0xAC, 0x0D, 0x00, 0x00, // 256, 3500 mm
        0x01, 0x00, 0x01, 0x00, 0x00, 0x00, // 1, 1 mm
        0x4D, 0x4D, // checksum: Σ mod 256 = 0xB2 → 0xFF − 0xB2 = 0x4D
    ];

    fn golden_repr() -> Repr {
        let r = |intensity, range_mm| RawReading {
            intensity,
            range_mm,
            reserved: 0,
        };
        Repr {
            index: 5,
            speed_raw: 3012,
            readings: [
                r(1000, 500),
                r(0, 0),
                r(13182, 4200),
                r(7, 120),
                r(256, 3500),
                r(1, 1),
            ],
        }
    }

    #[test]
    fn test_checksum_by_hand() {
        let sum: u32 = PACKET_BYTES[..40].iter().map(|&b| u32::from(b)).sum();
        assert_eq!(sum & 0xFF, 0xB2);
        assert_eq!(checksum(&PACKET_BYTES[..40]), 0x4D);
    }

    #[test]
    fn test_deconstruct() {
        let p = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(p.index(), 5);
        assert_eq!(p.speed_raw(), 3012);
        assert_eq!(p.intensity(2), 13182);
        assert_eq!(p.range_mm(2), 4200);
        assert_eq!(p.range_mm(1), 0);
        assert_eq!(p.checksum(), 0x4D);
        assert!(p.checksum_ok());
    }

    #[test]
    fn test_parse() {
        let p = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        let repr = Repr::parse(&p);
        assert_eq!(repr, golden_repr());
        assert!((repr.rpm() - 301.2).abs() < 1e-4);
    }

    #[test]
    fn test_emit() {
        let mut buf = [0u8; 42];
        golden_repr().emit_into(&mut buf).unwrap();
        assert_eq!(buf, PACKET_BYTES);
    }

    #[test]
    fn test_emit_into_short_buffer_is_an_error() {
        let mut buf = [0u8; 41];
        assert_eq!(golden_repr().emit_into(&mut buf), Err(Error::Truncated));
    }

    #[test]
    fn test_rejects() {
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..41]).unwrap_err(),
            Error::Truncated
        );
        let mut bad = PACKET_BYTES;
        bad[0] = 0xFB;
        assert_eq!(Packet::new_checked(&bad[..]).unwrap_err(), Error::BadSync);
        for index in [0x9F, 0xDC, 0x00, 0xFF] {
            let mut bad = PACKET_BYTES;
            bad[1] = index;
            assert_eq!(Packet::new_checked(&bad[..]).unwrap_err(), Error::BadIndex);
        }
        let mut bad = PACKET_BYTES;
        bad[41] ^= 1;
        assert!(!Packet::new_checked(&bad[..]).unwrap().checksum_ok());
        let mut bad = PACKET_BYTES;
        bad[10] ^= 0x80;
        assert!(!Packet::new_checked(&bad[..]).unwrap().checksum_ok());
    }

    #[test]
    fn test_checksum_matches_byte_sum() {
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        for len in (0..=300).chain([1023, 1024, 1025, 2047, 2048, 4096, 10_000]) {
            let bytes: std::vec::Vec<u8> = (0..len)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x as u8
                })
                .collect();
            let plain = bytes.iter().fold(0u8, |a, &b| a.wrapping_add(b));
            assert_eq!(checksum(&bytes), 0xFF - plain, "length {len}");
            assert_eq!(checksum(&[0xFF; 40]), 0xFF - 0xD8);
        }
    }

    #[test]
    fn test_index_bounds() {
        assert!(is_index_byte(0xA0));
        assert!(is_index_byte(0xDB));
        assert!(!is_index_byte(0xDC));
        assert!(!is_index_byte(0x9F));
        assert_eq!(INDEX_LAST, 0xDB);
    }

    #[test]
    fn test_single_bit_flips_always_detected() {
        // An additive checksum catches every single-bit error: prove it on the golden packet.
        for bit in 0..PACKET_LEN * 8 {
            let mut b = PACKET_BYTES;
            b[bit / 8] ^= 1 << (bit % 8);
            let ok = Packet::new_checked(&b[..]).is_ok_and(|p| p.checksum_ok());
            assert!(!ok, "bit {bit} flip not detected");
        }
    }
}
