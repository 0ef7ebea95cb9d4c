//! The streaming RPLIDAR decoder: bytes in arbitrary chunks → response descriptors, replies
//! and measurement nodes.
//!
//! It owns one reply-sized buffer ([`DECODER_BUFFER_LEN`] bytes) and nothing else.
//!
//! ## Framing and resynchronisation
//!
//! * `A5 5A` starts a **descriptor** (7 bytes). A SCAN descriptor switches nothing (nodes are
//!   recognised with or without one, so a capture may start anywhere); a GET_HEALTH or
//!   GET_INFO descriptor is followed by its payload, which is read and passed on.
//! * Anything else must be a **node**: byte 0's S and !S bits must differ, byte 1's check bit
//!   must be 1 (the SDK's test), and the angle must be below 360°. A failure slides the
//!   window by **one byte** and counts it; a node that begins inside bad bytes is never lost.
//!
//! The node check is weak (about 1 in 8 random byte pairs pass the bit test), so while the
//! decoder is hunting for the node boundary (after a rejected window) a candidate must also
//! continue the sweep: an angle at most 10° clockwise of the last good node's. A node has no
//! checksum at all, so a flipped distance bit cannot be seen by any decoder; the corruption test
//! measures what gets through. Every byte fed is accounted for:
//! `bytes_in == bytes_skipped + 5·nodes + descriptor and reply bytes + buffered()`.

use super::protocol::{
    DESCRIPTOR_LEN, Descriptor, HealthReply, InfoReply, NODE_LEN, Node, NodeError, SYNC, SYNC2,
    kind,
};
use crate::framing::Candidate;

/// Largest clockwise step from the last good node a node found while hunting may take
/// (10°, 1/64° units).
pub const HUNT_MAX_STEP_Q6: u16 = 10 * 64;
/// Bytes of hunting after which the angle condition is dropped.
pub const HUNT_GIVE_UP_BYTES: u32 = 256;

/// `true` if `b` lies at most [`HUNT_MAX_STEP_Q6`] clockwise of `a` (and is not `a`).
fn close(a: u16, b: u16) -> bool {
    let full = super::protocol::ANGLE_Q6_FULL;
    let step = (b % full + full - a % full) % full;
    step > 0 && step <= HUNT_MAX_STEP_Q6
}

/// Bytes the decoder buffers: the longest reply (GET_INFO, 20 bytes).
pub const DECODER_BUFFER_LEN: usize = 20;

/// One decoded item.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Decoded {
    /// A response descriptor.
    Descriptor(Descriptor),
    /// A measurement node.
    Node(Node),
    /// A GET_HEALTH reply.
    Health(HealthReply),
    /// A GET_INFO reply.
    Info(InfoReply),
}

/// Counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Bytes fed in.
    pub bytes_in: u64,
    /// Bytes discarded.
    pub bytes_skipped: u64,
    /// Nodes yielded.
    pub nodes: u64,
    /// Descriptors seen.
    pub descriptors: u64,
    /// Window positions rejected by the S/!S/C bit test.
    pub bad_sync: u64,
    /// Window positions rejected for an angle ≥ 360°.
    pub bad_angle: u64,
}

/// The decoder; see the module docs.
#[derive(Debug, Clone, Default)]
pub struct Decoder {
    cand: Candidate<DECODER_BUFFER_LEN>,
    /// Payload length of a single reply announced by the last descriptor, still to read.
    reply: Option<(u8, usize)>,
    /// Bytes slid past since the last good node (0 = in step).
    hunted: u32,
    /// Angle of the last node that continued the sweep (the hunting reference).
    trusted_q6: Option<u16>,
    /// Angle of the last node yielded.
    prev_q6: Option<u16>,
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

    /// Bytes held.
    pub fn buffered(&self) -> usize {
        self.cand.len()
    }

    /// Drops partial data (link reset, end of stream), counting it as skipped.
    pub fn reset(&mut self) {
        self.stats.bytes_skipped += self.cand.clear() as u64;
        self.reply = None;
        self.hunted = 0;
    }

    /// Takes bytes from the front of `input` until one item is complete and returns it;
    /// `None` once `input` is used up.
    pub fn next_item(&mut self, input: &mut &[u8]) -> Option<Decoded> {
        loop {
            // Fast path: nodes straight from the input.
            if self.cand.len() == 0
                && self.reply.is_none()
                && self.hunted == 0
                && let Some(b) = input.get(..NODE_LEN)
                && !(b[0] == SYNC && b[1] == SYNC2)
                && let Ok(node) = Node::parse(b)
            {
                self.stats.bytes_in += NODE_LEN as u64;
                self.stats.nodes += 1;
                self.track(node.angle_q6);
                *input = &input[NODE_LEN..];
                return Some(Decoded::Node(node));
            }
            if self.reply.is_none() {
                // Two bytes tell a descriptor from a node.
                self.stats.bytes_in += self.cand.fill(input, 2) as u64;
                if self.cand.len() < 2 {
                    return None;
                }
            }
            let want = match self.reply {
                Some((_, n)) => n,
                None if self.cand.bytes()[..2] == [SYNC, SYNC2] => DESCRIPTOR_LEN,
                None => NODE_LEN,
            };
            self.stats.bytes_in += self.cand.fill(input, want) as u64;
            if self.cand.len() < want {
                return None;
            }
            let bytes = self.cand.bytes();
            if let Some((k, n)) = self.reply.take() {
                let body = &bytes[..n];
                let item = match k {
                    kind::DEVHEALTH => HealthReply::parse(body).map(Decoded::Health),
                    _ => InfoReply::parse(body).map(Decoded::Info),
                };
                self.cand.consume(n);
                match item {
                    Some(item) => return Some(item),
                    None => continue,
                }
            }
            if want == DESCRIPTOR_LEN {
                if let Some(d) = Descriptor::parse(bytes) {
                    self.stats.descriptors += 1;
                    self.cand.consume(DESCRIPTOR_LEN);
                    let single = d.mode == 0;
                    self.reply = match (d.kind, d.len) {
                        (kind::DEVHEALTH, 3) if single => Some((d.kind, 3)),
                        (kind::DEVINFO, 20) if single => Some((d.kind, 20)),
                        _ => None,
                    };
                    return Some(Decoded::Descriptor(d));
                }
                self.slide();
                continue;
            }
            match Node::parse(bytes) {
                Ok(node) if self.continues(&node) => {
                    self.cand.consume(NODE_LEN);
                    self.stats.nodes += 1;
                    self.hunted = 0;
                    self.track(node.angle_q6);
                    return Some(Decoded::Node(node));
                }
                Ok(_) => {
                    self.stats.bad_sync += 1;
                    self.slide();
                }
                Err(e) => {
                    if e == NodeError::BadAngle {
                        self.stats.bad_angle += 1;
                    } else {
                        self.stats.bad_sync += 1;
                    }
                    self.slide();
                }
            }
        }
    }

    /// Drops the first buffered byte (now hunting for the node boundary).
    fn slide(&mut self) {
        if self.cand.len() > 0 {
            self.cand.consume(1);
            self.stats.bytes_skipped += 1;
            self.hunted = self.hunted.saturating_add(1);
        }
    }

    /// While hunting for the node boundary, a candidate must also continue the sweep: its
    /// angle at most [`HUNT_MAX_STEP_Q6`] clockwise of the last good node's. Misaligned bytes
    /// pass the bit test one time in eight; they almost never land that close. After
    /// [`HUNT_GIVE_UP_BYTES`] bytes of hunting (the sensor restarted, or the last node was
    /// itself bad) any node passing the bit test is taken again.
    fn continues(&self, node: &Node) -> bool {
        if self.hunted == 0 || self.hunted > HUNT_GIVE_UP_BYTES {
            return true;
        }
        match self.trusted_q6 {
            Some(t) => close(t, node.angle_q6),
            None => true,
        }
    }

    /// A node was yielded: it becomes the hunting reference only if it continues the
    /// reference or the node before it, so one bogus node from a garbage burst (which passes
    /// the bit test in step one time in eight) cannot move the reference away from the sweep,
    /// while two real nodes in a row (a restarted sensor) re-establish it.
    fn track(&mut self, a: u16) {
        let continues = self.trusted_q6.is_none_or(|t| close(t, a))
            || self.prev_q6.is_some_and(|p| close(p, a));
        if continues {
            self.trusted_q6 = Some(a);
        }
        self.prev_q6 = Some(a);
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::rplidar::protocol::SCAN_DESCRIPTOR;

    fn node(i: u16, start: bool) -> [u8; NODE_LEN] {
        Node {
            start,
            quality: 40,
            angle_q6: i * 64,
            distance_q2: 4000 + i,
        }
        .to_bytes()
    }

    #[test]
    fn descriptor_then_nodes_in_any_chunking_with_garbage() {
        let mut bytes = [0u8; 3 + DESCRIPTOR_LEN + 10 * NODE_LEN];
        bytes[..3].copy_from_slice(&[0x00, 0x02, 0x00]); // garbage that fails every test
        bytes[3..10].copy_from_slice(&SCAN_DESCRIPTOR.to_bytes());
        for i in 0..10u16 {
            let at = 10 + NODE_LEN * usize::from(i);
            bytes[at..at + NODE_LEN].copy_from_slice(&node(i, i == 0));
        }
        for chunk in [1, 2, 5, 6, 7, 100] {
            let mut d = Decoder::new();
            let (mut nodes, mut descs) = (0, 0);
            for c in bytes.chunks(chunk) {
                let mut input = c;
                while let Some(item) = d.next_item(&mut input) {
                    match item {
                        Decoded::Node(n) => {
                            assert_eq!(n.angle_q6, nodes * 64);
                            nodes += 1;
                        }
                        Decoded::Descriptor(x) => {
                            assert_eq!(x, SCAN_DESCRIPTOR);
                            descs += 1;
                        }
                        _ => panic!("unexpected"),
                    }
                }
            }
            assert_eq!((nodes, descs), (10, 1), "chunk {chunk}");
            let s = d.stats();
            assert_eq!(s.bytes_skipped, 3, "chunk {chunk}");
            assert_eq!(s.bytes_in, bytes.len() as u64);
        }
    }

    #[test]
    fn health_reply_is_read() {
        let mut bytes = [0u8; DESCRIPTOR_LEN + 3 + NODE_LEN];
        bytes[..7].copy_from_slice(
            &Descriptor {
                len: 3,
                mode: 0,
                kind: kind::DEVHEALTH,
            }
            .to_bytes(),
        );
        bytes[7..10].copy_from_slice(&[2, 0x34, 0x12]);
        bytes[10..].copy_from_slice(&node(1, true));
        let mut d = Decoder::new();
        let mut input = &bytes[..];
        assert!(matches!(
            d.next_item(&mut input),
            Some(Decoded::Descriptor(_))
        ));
        assert_eq!(
            d.next_item(&mut input),
            Some(Decoded::Health(HealthReply {
                status: 2,
                error_code: 0x1234
            }))
        );
        assert!(matches!(d.next_item(&mut input), Some(Decoded::Node(_))));
    }
}

#[cfg(test)]
mod resync_test {
    use super::*;

    #[test]
    fn one_inserted_byte_loses_at_most_the_node_it_hit() {
        let mut bytes = std::vec::Vec::new();
        for i in 0..200u16 {
            let n = Node {
                start: i % 100 == 0,
                quality: 30,
                angle_q6: (i % 100) * 230,
                distance_q2: 1000 + 7 * i,
            };
            bytes.extend_from_slice(&n.to_bytes());
            if i == 50 {
                bytes.push(0x33);
            }
        }
        let mut d = Decoder::new();
        let mut input = &bytes[..];
        let mut n = 0;
        while let Some(Decoded::Node(_)) = d.next_item(&mut input) {
            n += 1;
        }
        assert!(n >= 199, "{n} {:?}", d.stats());
    }
}
