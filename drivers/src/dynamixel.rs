//! DYNAMIXEL Protocol 2.0 (ROBOTIS), as spoken by the OpenCR board that reports a TurtleBot3's
//! wheel encoders: instruction packets out, status packets in.
//!
//! ```text
//! FF FF FD 00 | ID | LEN_L LEN_H | INST | PARAM … | CRC_L CRC_H
//! ```
//!
//! * `LEN` counts the bytes after itself: instruction, parameters (after stuffing) and CRC.
//! * **Byte stuffing:** from the instruction on, every `FF FF FD` that would appear gets an extra
//!   `FD` after it, so that the header never appears inside a packet; the receiver removes it.
//! * **CRC-16** as ROBOTIS specifies it: polynomial 0x8005, initial value 0, MSB first, no final
//!   XOR (CRC-16/UMTS, check value 0xFEE8 over `"123456789"`), over every byte from the header to
//!   the last parameter, stuffing included, sent little-endian.
//! * A status packet's instruction is `0x55`, followed by an error byte and the data.
//!
//! [`StatusDecoder`] is a streaming decoder in the style of the LDS-01 one: any chunking, resync
//! after garbage without losing a packet that starts inside a bad candidate, every dropped byte
//! counted, fixed capacity ([`MAX_PACKET_LEN`]).

use core::fmt;

/// The packet header.
pub const HEADER: [u8; 4] = [0xFF, 0xFF, 0xFD, 0x00];
/// Instruction: read from the control table (address u16, length u16).
pub const INST_READ: u8 = 0x02;
/// Instruction: ping.
pub const INST_PING: u8 = 0x01;
/// Instruction byte of a status packet.
pub const INST_STATUS: u8 = 0x55;
/// Longest packet (stuffed, header to CRC) the decoder holds: a status with up to 48 data bytes.
pub const MAX_PACKET_LEN: usize = 64;
/// Most data bytes a decoded status carries.
pub const MAX_STATUS_DATA: usize = MAX_PACKET_LEN - 11;

/// ROBOTIS's CRC-16 is CRC-16/UMTS (a.k.a. BUYPASS: polynomial 0x8005, init 0, no
/// reflection, no final xor; check 0xFEE8), table-driven by the `crc` crate.
const CRC16: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_UMTS);

/// CRC-16 of `bytes` as ROBOTIS specifies it (continuing from `crc`; start with 0).
pub fn crc16(crc: u16, bytes: &[u8]) -> u16 {
    let mut d = CRC16.digest_with_initial(crc);
    d.update(bytes);
    d.finalize()
}

/// Codec errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// The output buffer is too small for the packet.
    BufferTooSmall,
    /// The packet would exceed [`MAX_PACKET_LEN`].
    TooLong,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Error::BufferTooSmall => "DYNAMIXEL packet does not fit the buffer",
            Error::TooLong => "DYNAMIXEL packet longer than MAX_PACKET_LEN",
        })
    }
}

impl core::error::Error for Error {}

/// Writes a packet (instruction `inst`, parameters `params`, stuffed, with CRC) for device `id`
/// into `out`; returns its length.
pub fn emit(id: u8, inst: u8, params: &[u8], out: &mut [u8]) -> Result<usize, Error> {
    fn put(out: &mut [u8], n: &mut usize, b: u8) -> Result<(), Error> {
        if *n >= MAX_PACKET_LEN {
            return Err(Error::TooLong);
        }
        *out.get_mut(*n).ok_or(Error::BufferTooSmall)? = b;
        *n += 1;
        Ok(())
    }
    let mut n = 0;
    for b in HEADER.into_iter().chain([id, 0, 0]) {
        put(out, &mut n, b)?; // the two length bytes are filled in below
    }
    let body_start = n;
    for &b in core::iter::once(&inst).chain(params) {
        put(out, &mut n, b)?;
        // Stuffing: FF FF FD inside the body gets an extra FD.
        if n - body_start >= 3 && out[n - 3..n] == [0xFF, 0xFF, 0xFD] {
            put(out, &mut n, 0xFD)?;
        }
    }
    let len = (n - body_start + 2) as u16;
    out[5..7].copy_from_slice(&len.to_le_bytes());
    let crc = crc16(0, &out[..n]);
    for b in crc.to_le_bytes() {
        put(out, &mut n, b)?;
    }
    Ok(n)
}

/// The READ instruction for `len` bytes at control-table `address` of device `id`.
pub fn read_request(id: u8, address: u16, len: u16, out: &mut [u8]) -> Result<usize, Error> {
    let a = address.to_le_bytes();
    let l = len.to_le_bytes();
    emit(id, INST_READ, &[a[0], a[1], l[0], l[1]], out)
}

/// A decoded status packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status {
    /// Device id.
    pub id: u8,
    /// Error byte (bit 7: hardware alert; low 7 bits: result, 0 = none).
    pub error: u8,
    data: [u8; MAX_STATUS_DATA],
    len: u8,
}

impl Status {
    /// The data bytes (stuffing removed).
    pub fn data(&self) -> &[u8] {
        &self.data[..usize::from(self.len).min(MAX_STATUS_DATA)]
    }

    /// The little-endian i32 at byte `at` of the data, if there.
    pub fn i32_at(&self, at: usize) -> Option<i32> {
        let d = self.data().get(at..at + 4)?;
        Some(i32::from_le_bytes([d[0], d[1], d[2], d[3]]))
    }
}

/// A decoded packet of any kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Packet {
    /// Device id.
    pub id: u8,
    /// Instruction (0x55 for a status).
    pub inst: u8,
    params: [u8; MAX_PACKET_LEN],
    len: u8,
    /// Bytes it took on the wire.
    pub wire_len: u8,
}

impl Packet {
    /// Parameters, stuffing removed (for a status: the error byte, then the data).
    pub fn params(&self) -> &[u8] {
        &self.params[..usize::from(self.len).min(MAX_PACKET_LEN)]
    }

    /// The (address, length) of a READ instruction.
    pub fn read_args(&self) -> Option<(u16, u16)> {
        let p = self.params();
        (self.inst == INST_READ && p.len() == 4).then(|| {
            (
                u16::from_le_bytes([p[0], p[1]]),
                u16::from_le_bytes([p[2], p[3]]),
            )
        })
    }
}

/// Counters of the status decoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Bytes fed.
    pub bytes_in: u64,
    /// Bytes not part of any status handed out.
    pub bytes_skipped: u64,
    /// Packets handed out (by `next_status`: status packets only).
    pub packets: u64,
    /// Candidates with a bad CRC.
    pub bad_crc: u64,
    /// Candidates with a length field out of range.
    pub bad_length: u64,
    /// Valid packets that were not status packets (e.g. our own instruction echoed).
    pub not_status: u64,
}

/// Streaming status decoder; see the module docs.
#[derive(Debug, Clone)]
pub struct StatusDecoder {
    buf: [u8; MAX_PACKET_LEN],
    len: usize,
    stats: DecoderStats,
}

impl Default for StatusDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl StatusDecoder {
    /// A decoder.
    pub const fn new() -> Self {
        StatusDecoder {
            buf: [0; MAX_PACKET_LEN],
            len: 0,
            stats: DecoderStats {
                bytes_in: 0,
                bytes_skipped: 0,
                packets: 0,
                bad_crc: 0,
                bad_length: 0,
                not_status: 0,
            },
        }
    }

    /// Counters.
    pub fn stats(&self) -> &DecoderStats {
        &self.stats
    }

    /// Bytes buffered.
    pub fn buffered(&self) -> usize {
        self.len
    }

    /// Drops a partial packet (counted as skipped).
    pub fn reset(&mut self) {
        self.stats.bytes_skipped += self.len as u64;
        self.len = 0;
    }

    /// Takes bytes from the front of `input` until a status packet is complete, and returns
    /// it; `None` once `input` is used up. Valid packets that are not status packets (an
    /// instruction echoed on a half-duplex bus) are counted in `not_status` and skipped.
    pub fn next_status(&mut self, input: &mut &[u8]) -> Option<Status> {
        loop {
            let p = self.next_packet(input)?;
            if p.inst != INST_STATUS || p.len == 0 {
                self.stats.packets -= 1;
                self.stats.not_status += 1;
                self.stats.bytes_skipped += u64::from(p.wire_len);
                continue;
            }
            let mut status = Status {
                id: p.id,
                error: p.params[0],
                data: [0; MAX_STATUS_DATA],
                len: 0,
            };
            let data = &p.params()[1..];
            let k = data.len().min(MAX_STATUS_DATA);
            status.data[..k].copy_from_slice(&data[..k]);
            status.len = k as u8;
            return Some(status);
        }
    }

    /// Takes bytes from the front of `input` until any valid packet (instruction or status) is
    /// complete, and returns it with stuffing removed; `None` once `input` is used up.
    pub fn next_packet(&mut self, input: &mut &[u8]) -> Option<Packet> {
        loop {
            // The length field, once buffered, must be plausible before it sizes anything.
            let mut need = 7;
            if self.len >= 7 {
                let plen = usize::from(u16::from_le_bytes([self.buf[5], self.buf[6]]));
                if !(3..=MAX_PACKET_LEN - 7).contains(&plen) {
                    self.stats.bad_length += 1;
                    self.resync();
                    continue;
                }
                need = 7 + plen;
            }
            // Fill one byte at a time up to what the candidate needs: the header and length,
            // then the whole packet.
            let mut rescan = false;
            while self.len < need {
                let (&b, rest) = input.split_first()?;
                *input = rest;
                self.stats.bytes_in += 1;
                self.buf[self.len] = b;
                self.len += 1;
                if self.len <= 4 && self.buf[self.len - 1] != HEADER[self.len - 1] {
                    // Not a header: drop the first byte and rescan what is buffered.
                    self.resync();
                    rescan = true;
                    break;
                }
            }
            if rescan || self.len == 7 {
                continue;
            }
            // A whole candidate: check the CRC.
            let n = self.len;
            let crc = u16::from_le_bytes([self.buf[n - 2], self.buf[n - 1]]);
            if crc16(0, &self.buf[..n - 2]) != crc {
                self.stats.bad_crc += 1;
                self.resync();
                continue;
            }
            // Remove stuffing from the body (instruction on): an FD that follows FF FF FD in
            // the stuffed stream is the stuffing byte.
            let stuffed = &self.buf[7..n - 2];
            let mut body = [0u8; MAX_PACKET_LEN];
            let mut k = 0usize;
            for (j, &b) in stuffed.iter().enumerate() {
                let is_stuffing = j >= 3 && b == 0xFD && stuffed[j - 3..j] == [0xFF, 0xFF, 0xFD];
                if !is_stuffing {
                    body[k] = b;
                    k += 1;
                }
            }
            let mut packet = Packet {
                id: self.buf[4],
                inst: body[0],
                params: [0; MAX_PACKET_LEN],
                len: (k - 1) as u8,
                wire_len: n as u8,
            };
            packet.params[..k - 1].copy_from_slice(&body[1..k]);
            self.stats.packets += 1;
            self.len = 0;
            return Some(packet);
        }
    }

    /// Drops the first buffered byte and everything up to the next `FF` that could start a
    /// header.
    fn resync(&mut self) {
        loop {
            let next = self.buf[1..self.len]
                .iter()
                .position(|&b| b == 0xFF)
                .map(|p| p + 1);
            let drop = next.unwrap_or(self.len);
            self.buf.copy_within(drop..self.len, 0);
            self.len -= drop;
            self.stats.bytes_skipped += drop as u64;
            // The kept bytes must themselves be a header prefix, or go too.
            if self.buf[..self.len.min(4)]
                .iter()
                .zip(HEADER)
                .all(|(a, b)| *a == b)
            {
                return;
            }
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    // Golden packets from the ROBOTIS e-manual, Protocol 2.0 ("Ping" and "Read" examples).
    const PING_ID1: [u8; 10] = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E];
    const READ_ID1_132_4: [u8; 14] = [
        0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15,
    ];
    const STATUS_ID1_166: [u8; 15] = [
        0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0,
    ];

    #[test]
    fn crc_check_value() {
        assert_eq!(crc16(0, b"123456789"), 0xFEE8);
    }

    #[test]
    fn golden_instructions() {
        let mut out = [0u8; 32];
        let n = emit(1, INST_PING, &[], &mut out).unwrap();
        assert_eq!(&out[..n], &PING_ID1);
        let n = read_request(1, 132, 4, &mut out).unwrap();
        assert_eq!(&out[..n], &READ_ID1_132_4);
    }

    #[test]
    fn golden_status() {
        let mut d = StatusDecoder::new();
        let mut input = &STATUS_ID1_166[..];
        let s = d.next_status(&mut input).unwrap();
        assert_eq!((s.id, s.error), (1, 0));
        assert_eq!(s.i32_at(0), Some(166));
        assert_eq!(d.stats().bytes_skipped, 0);
    }

    #[test]
    fn stuffing_round_trip() {
        // Data containing the header pattern twice.
        let data = [0xFF, 0xFF, 0xFD, 0x01, 0xFF, 0xFF, 0xFD, 0xFD];
        let mut params = [0u8; 9];
        params[0] = 0; // error byte
        params[1..].copy_from_slice(&data);
        let mut out = [0u8; 40];
        let n = emit(200, INST_STATUS, &params, &mut out).unwrap();
        // Two stuffed FDs (the second FF FF FD FD in the data gets one more).
        assert_eq!(n, 4 + 3 + 1 + 9 + 2 + 2);
        assert!(
            !out[4..n].windows(4).any(|w| w == HEADER),
            "header inside the packet"
        );
        let mut d = StatusDecoder::new();
        let mut input = &out[..n];
        let s = d.next_status(&mut input).unwrap();
        assert_eq!(s.data(), &data);
    }

    #[test]
    fn header_heavy_noise_never_panics() {
        // Regression for a fuzzer find: after a resync, the bytes kept could hold an unchecked
        // length field that sized the buffer. Noise made mostly of header bytes hits that path.
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut d = StatusDecoder::new();
        let mut fed = 0u64;
        for _ in 0..50_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let b = x.to_le_bytes();
            // A quarter of the time a header with a random id and length, else one random byte.
            let piece: &[u8] = if x & 3 == 0 {
                &[0xFF, 0xFF, 0xFD, 0x00, b[1], b[2], b[3] & 0x01]
            } else {
                &b[4..5]
            };
            for chunk in piece.chunks(1 + (b[5] & 3) as usize) {
                let mut input = chunk;
                while d.next_status(&mut input).is_some() {}
            }
            fed += piece.len() as u64;
        }
        let st = d.stats();
        assert_eq!(st.bytes_in, fed);
        assert!(st.bad_length > 0 && st.bytes_skipped > 0);
    }

    #[test]
    fn garbage_and_corruption() {
        let mut stream = std::vec::Vec::new();
        stream.extend_from_slice(&[0xFF, 0x00, 0xFF, 0xFF, 0xFD, 0x00, 0xFF]);
        stream.extend_from_slice(&STATUS_ID1_166);
        let mut bad = STATUS_ID1_166;
        bad[10] ^= 0x10;
        stream.extend_from_slice(&bad);
        stream.extend_from_slice(&READ_ID1_132_4); // an echoed instruction
        stream.extend_from_slice(&STATUS_ID1_166[..9]); // cut short…
        stream.extend_from_slice(&STATUS_ID1_166); // …then a good one
        let mut d = StatusDecoder::new();
        let mut out = std::vec::Vec::new();
        for chunk in stream.chunks(5) {
            let mut input = chunk;
            while let Some(s) = d.next_status(&mut input) {
                out.push(s.i32_at(0));
            }
        }
        assert_eq!(out, [Some(166), Some(166)]);
        let st = d.stats();
        assert_eq!(st.bad_crc, 2);
        assert_eq!(st.not_status, 1);
        assert_eq!(st.bytes_in, stream.len() as u64);
        assert_eq!(st.bytes_in, st.bytes_skipped + 2 * 15 + d.buffered() as u64);
    }
}
