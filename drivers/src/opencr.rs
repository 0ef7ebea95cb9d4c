//! The OpenCR board of a TurtleBot3 as an encoder source: it answers DYNAMIXEL 2.0 READ
//! requests for the wheels' present positions (i32 ticks, cumulative, wrapping) from its control
//! table. Addresses and the device id are configuration ([`OpencrConfig`]), since firmware
//! versions differ (`docs/hardware.md`: id 200, left at 136, right at 140, 1 Mbps).
//!
//! [`OpencrReader::poll`] sends one READ covering both positions and waits for the status up to
//! [`OpencrConfig::timeout`]; timeouts, bad answers and lost links are counted and returned as
//! errors, never panics. The serial link reopens itself after an unplug.

use std::fmt;
use std::time::{Duration, Instant};

use crate::dynamixel::{StatusDecoder, read_request};
use crate::serial::{LinkError, LinkRead, SerialConfig, SerialLink};

/// OpenCR settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OpencrConfig {
    /// DYNAMIXEL id of the board.
    pub id: u8,
    /// Control-table address of the left wheel's present position (i32).
    pub left_addr: u16,
    /// Control-table address of the right wheel's present position (i32).
    pub right_addr: u16,
    /// Longest wait for an answer.
    pub timeout: Duration,
}

impl Default for OpencrConfig {
    fn default() -> Self {
        OpencrConfig {
            id: 200,
            left_addr: 136,
            right_addr: 140,
            timeout: Duration::from_millis(20),
        }
    }
}

/// Why a poll gave no ticks.
#[derive(Debug)]
pub enum EncoderError {
    /// No valid answer within the timeout.
    Timeout,
    /// The board answered with an error byte.
    Device(u8),
    /// The answer was too short for both positions.
    ShortAnswer,
    /// The link is down (it reopens by itself).
    Link(LinkError),
}

impl fmt::Display for EncoderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EncoderError::Timeout => f.write_str("OpenCR: no answer within the timeout"),
            EncoderError::Device(e) => write!(f, "OpenCR: error byte 0x{e:02x}"),
            EncoderError::ShortAnswer => {
                f.write_str("OpenCR: answer too short for both wheel positions")
            }
            EncoderError::Link(e) => write!(f, "OpenCR: {e}"),
        }
    }
}

impl std::error::Error for EncoderError {}

/// Counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OpencrStats {
    /// Requests sent.
    pub requests: u64,
    /// Good answers.
    pub answers: u64,
    /// Polls that failed (all reasons).
    pub errors: u64,
}

/// Polls wheel ticks from an OpenCR.
pub struct OpencrReader {
    link: SerialLink,
    cfg: OpencrConfig,
    decoder: StatusDecoder,
    stats: OpencrStats,
}

impl OpencrReader {
    /// Opens the board's serial port (1 Mbps). Failing to open at start is an error naming the
    /// device; losses after that are survived.
    pub fn open(path: &str, cfg: OpencrConfig) -> Result<Self, LinkError> {
        Ok(OpencrReader {
            link: SerialLink::open(path, SerialConfig::opencr())?,
            cfg,
            decoder: StatusDecoder::new(),
            stats: OpencrStats::default(),
        })
    }

    /// Counters.
    pub fn stats(&self) -> &OpencrStats {
        &self.stats
    }

    /// The link's counters.
    pub fn link(&self) -> &SerialLink {
        &self.link
    }

    /// Reads both wheel positions (left, right), ticks.
    pub fn poll(&mut self) -> Result<(i32, i32), EncoderError> {
        let r = self.poll_inner();
        if r.is_err() {
            self.stats.errors += 1;
        }
        r
    }

    fn poll_inner(&mut self) -> Result<(i32, i32), EncoderError> {
        let lo = self.cfg.left_addr.min(self.cfg.right_addr);
        let hi = self.cfg.left_addr.max(self.cfg.right_addr);
        let len = hi - lo + 4;
        let mut req = [0u8; 16];
        let n =
            read_request(self.cfg.id, lo, len, &mut req).map_err(|_| EncoderError::ShortAnswer)?;
        self.decoder.reset();
        self.link.write(&req[..n]).map_err(EncoderError::Link)?;
        self.stats.requests += 1;
        let deadline = Instant::now() + self.cfg.timeout;
        let mut buf = [0u8; 64];
        while Instant::now() < deadline {
            match self.link.read(&mut buf) {
                LinkRead::Data(n) => {
                    let mut input = &buf[..n.min(buf.len())];
                    while let Some(s) = self.decoder.next_status(&mut input) {
                        if s.id != self.cfg.id {
                            continue;
                        }
                        if s.error & 0x7F != 0 {
                            return Err(EncoderError::Device(s.error));
                        }
                        let at = |addr: u16| usize::from(addr - lo);
                        let (Some(l), Some(r)) = (
                            s.i32_at(at(self.cfg.left_addr)),
                            s.i32_at(at(self.cfg.right_addr)),
                        ) else {
                            return Err(EncoderError::ShortAnswer);
                        };
                        self.stats.answers += 1;
                        return Ok((l, r));
                    }
                }
                LinkRead::Idle | LinkRead::Reopened => {}
                LinkRead::Lost(e) => return Err(EncoderError::Link(e)),
            }
        }
        Err(EncoderError::Timeout)
    }
}
