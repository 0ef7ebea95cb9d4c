//! The Slamtec RPLIDAR serial protocol, standard SCAN mode (`docs/hardware.md` §1c): requests, the
//! response descriptor, the 5-byte measurement node, the GET_INFO / GET_HEALTH payloads.
//! Checked parsers that never panic and `emit` for the simulator and tests.
//!
//! Node layout:
//!
//! | byte | bits                                               |
//! |------|----------------------------------------------------|
//! | 0    | bit 0 S (new 360° scan), bit 1 !S, bits 2–7 quality |
//! | 1    | bit 0 C (check, always 1), bits 1–7 angle_q6 bits 6–0   |
//! | 2    | angle_q6 bits 14–7                                 |
//! | 3–4  | distance_q2 (u16 LE; mm = value / 4; 0 = no return) |

/// Request start byte.
pub const SYNC: u8 = 0xA5;
/// Second byte of a response descriptor.
pub const SYNC2: u8 = 0x5A;
/// Descriptor length.
pub const DESCRIPTOR_LEN: usize = 7;
/// Node length.
pub const NODE_LEN: usize = 5;

/// Commands (host → LiDAR).
pub mod cmd {
    /// Start scanning.
    pub const SCAN: u8 = 0x20;
    /// Start scanning without waiting for a stable motor.
    pub const FORCE_SCAN: u8 = 0x21;
    /// Stop scanning (wait 100 ms before the next request).
    pub const STOP: u8 = 0x25;
    /// Reset the core.
    pub const RESET: u8 = 0x40;
    /// Device information.
    pub const GET_INFO: u8 = 0x50;
    /// Device health.
    pub const GET_HEALTH: u8 = 0x52;
    /// Motor PWM (A2 with the accessory board), u16 payload.
    pub const SET_MOTOR_PWM: u8 = 0xF0;
    /// Accessory-board flag query, u32 payload 0.
    pub const GET_ACC_BOARD_FLAG: u8 = 0xFF;
}

/// Response types (descriptor byte 6).
pub mod kind {
    /// Measurement nodes.
    pub const MEASUREMENT: u8 = 0x81;
    /// GET_INFO reply.
    pub const DEVINFO: u8 = 0x04;
    /// GET_HEALTH reply.
    pub const DEVHEALTH: u8 = 0x06;
}

/// Waits the SDK keeps: after STOP before anything else, after SCAN before reading.
pub mod delay {
    /// After STOP, ms.
    pub const AFTER_STOP_MS: u32 = 100;
    /// After SCAN, ms.
    pub const AFTER_SCAN_MS: u32 = 10;
}

/// A request without payload: `A5 cmd`.
pub const fn request(command: u8) -> [u8; 2] {
    [SYNC, command]
}

/// A request with payload into `out`: `A5 cmd len payload… xor`; returns the bytes written,
/// or `None` if `out` is short or the payload longer than 255.
pub fn request_with_payload(command: u8, payload: &[u8], out: &mut [u8]) -> Option<usize> {
    let n = 4 + payload.len();
    let len = u8::try_from(payload.len()).ok()?;
    let b = out.get_mut(..n)?;
    b[0] = SYNC;
    b[1] = command;
    b[2] = len;
    b[3..3 + payload.len()].copy_from_slice(payload);
    b[n - 1] = b[..n - 1].iter().fold(0, |x, &v| x ^ v);
    Some(n)
}

/// A response descriptor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Descriptor {
    /// Bytes per response (low 30 bits).
    pub len: u32,
    /// Send mode (top 2 bits): 0 single, 1 multiple.
    pub mode: u8,
    /// Response type.
    pub kind: u8,
}

/// The descriptor a SCAN request answers with: 5-byte nodes, multiple, type 0x81.
pub const SCAN_DESCRIPTOR: Descriptor = Descriptor {
    len: 5,
    mode: 1,
    kind: kind::MEASUREMENT,
};

impl Descriptor {
    /// Parses 7 bytes `A5 5A len:u32 type`.
    pub fn parse(b: &[u8]) -> Option<Descriptor> {
        let b = b.get(..DESCRIPTOR_LEN)?;
        if b[0] != SYNC || b[1] != SYNC2 {
            return None;
        }
        let word = u32::from_le_bytes([b[2], b[3], b[4], b[5]]);
        Some(Descriptor {
            len: word & 0x3FFF_FFFF,
            mode: (word >> 30) as u8,
            kind: b[6],
        })
    }

    /// The 7 bytes.
    pub fn to_bytes(&self) -> [u8; DESCRIPTOR_LEN] {
        let w = (self.len & 0x3FFF_FFFF) | (u32::from(self.mode & 3) << 30);
        let l = w.to_le_bytes();
        [SYNC, SYNC2, l[0], l[1], l[2], l[3], self.kind]
    }
}

/// One measurement node, parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Node {
    /// S: this node starts a new 360° scan.
    pub start: bool,
    /// Quality, 0–63.
    pub quality: u8,
    /// Raw (clockwise) angle, 1/64 degree.
    pub angle_q6: u16,
    /// Distance, 1/4 mm (0 = no return).
    pub distance_q2: u16,
}

/// Why 5 bytes are not a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NodeError {
    /// Fewer than 5 bytes.
    Truncated,
    /// S and !S agree (byte 0) or the check bit C is 0 (byte 1): the SDK's resync test.
    BadSync,
    /// Angle at or beyond 360°.
    BadAngle,
}

/// The largest valid `angle_q6` + 1 (360° · 64).
pub const ANGLE_Q6_FULL: u16 = 360 * 64;

impl Node {
    /// Parses 5 bytes with the SDK's checks plus an angle range check.
    pub fn parse(b: &[u8]) -> Result<Node, NodeError> {
        let b = b.get(..NODE_LEN).ok_or(NodeError::Truncated)?;
        if !sync_ok(b[0], b[1]) {
            return Err(NodeError::BadSync);
        }
        let angle_q6 = u16::from_le_bytes([b[1], b[2]]) >> 1;
        if angle_q6 >= ANGLE_Q6_FULL {
            return Err(NodeError::BadAngle);
        }
        Ok(Node {
            start: b[0] & 1 == 1,
            quality: b[0] >> 2,
            angle_q6,
            distance_q2: u16::from_le_bytes([b[3], b[4]]),
        })
    }

    /// The 5 bytes.
    pub fn to_bytes(&self) -> [u8; NODE_LEN] {
        let s = u8::from(self.start);
        let b0 = (self.quality.min(63) << 2) | ((1 - s) << 1) | s;
        let a = ((self.angle_q6 % ANGLE_Q6_FULL) << 1) | 1;
        let [a0, a1] = a.to_le_bytes();
        let [d0, d1] = self.distance_q2.to_le_bytes();
        [b0, a0, a1, d0, d1]
    }

    /// Raw angle, degrees (clockwise).
    pub fn angle_deg(&self) -> f32 {
        f32::from(self.angle_q6) / 64.0
    }

    /// Distance, metres.
    pub fn distance_m(&self) -> f32 {
        f32::from(self.distance_q2) / 4000.0
    }
}

/// The SDK's resync test on the first two bytes of a node.
#[inline]
pub const fn sync_ok(b0: u8, b1: u8) -> bool {
    ((b0 >> 1) ^ b0) & 1 == 1 && b1 & 1 == 1
}

/// GET_HEALTH reply (3 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HealthReply {
    /// 0 OK, 1 warning, 2 error.
    pub status: u8,
    /// Device error code.
    pub error_code: u16,
}

impl HealthReply {
    /// Parses the 3-byte payload.
    pub fn parse(b: &[u8]) -> Option<HealthReply> {
        let b = b.get(..3)?;
        Some(HealthReply {
            status: b[0],
            error_code: u16::from_le_bytes([b[1], b[2]]),
        })
    }
}

/// GET_INFO reply (20 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InfoReply {
    /// Model id.
    pub model: u8,
    /// Firmware (major, minor).
    pub firmware: (u8, u8),
    /// Hardware version (≥ 6: A2M12/A3, 256000 baud).
    pub hardware: u8,
    /// Serial number.
    pub serial: [u8; 16],
}

impl InfoReply {
    /// Parses the 20-byte payload.
    pub fn parse(b: &[u8]) -> Option<InfoReply> {
        let b = b.get(..20)?;
        let mut serial = [0u8; 16];
        serial.copy_from_slice(&b[4..20]);
        Some(InfoReply {
            model: b[0],
            firmware: (b[2], b[1]),
            hardware: b[3],
            serial,
        })
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn golden_scan_descriptor_and_requests() {
        assert_eq!(
            SCAN_DESCRIPTOR.to_bytes(),
            [0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81]
        );
        assert_eq!(
            Descriptor::parse(&[0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81]),
            Some(SCAN_DESCRIPTOR)
        );
        assert_eq!(request(cmd::SCAN), [0xA5, 0x20]);
        assert_eq!(request(cmd::STOP), [0xA5, 0x25]);
        let mut out = [0u8; 8];
        // SET_MOTOR_PWM 660: A5 F0 02 94 02 xor.
        let n = request_with_payload(cmd::SET_MOTOR_PWM, &660u16.to_le_bytes(), &mut out);
        assert_eq!(n, Some(6));
        assert_eq!(
            &out[..6],
            &[
                0xA5,
                0xF0,
                0x02,
                0x94,
                0x02,
                0xA5 ^ 0xF0 ^ 0x02 ^ 0x94 ^ 0x02
            ]
        );
    }

    #[test]
    fn golden_node() {
        // S = 1, quality 47, angle 90.0° (q6 5760), distance 1500 mm (q2 6000).
        let b = [
            (47 << 2) | 0b01,
            ((5760u16 << 1) | 1) as u8,
            ((5760u16 << 1) >> 8) as u8,
            0x70,
            0x17,
        ];
        let n = Node::parse(&b).unwrap();
        assert!(n.start);
        assert_eq!(n.quality, 47);
        assert_eq!(n.angle_deg(), 90.0);
        assert_eq!(n.distance_m(), 1.5);
        assert_eq!(n.to_bytes(), b);
        let mut bad = b;
        bad[1] &= !1;
        assert_eq!(Node::parse(&bad), Err(NodeError::BadSync));
        let mut both = b;
        both[0] |= 0b11;
        assert_eq!(Node::parse(&both), Err(NodeError::BadSync));
        let far = Node {
            angle_q6: 0x7FFF,
            ..n
        }
        .to_bytes();
        // to_bytes wraps the angle, so build the out-of-range one by hand.
        let mut out_of_range = far;
        out_of_range[1] = 0xFF;
        out_of_range[2] = 0xFF;
        assert_eq!(Node::parse(&out_of_range), Err(NodeError::BadAngle));
    }
}
