//! Property tests of the LDROBOT and RPLIDAR decoders and of the revolution every model
//! yields, over random frames, random streams and random chunkings.

use drivers::ldrobot::{self, FRAME_LEN, FrameRepr, RawPoint};
use drivers::lidar::{AnyLidar, LidarConfig, LidarModel, RevolutionStream};
use drivers::rplidar::{self, NODE_LEN, Node};
use proptest::prelude::*;

fn arb_frame() -> impl Strategy<Value = FrameRepr> {
    (
        any::<u16>(),
        0u16..36_000,
        prop::array::uniform12((any::<u16>(), any::<u8>())),
        0u16..36_000,
        0u16..30_000,
    )
        .prop_map(|(speed_dps, start, pts, end, ts)| FrameRepr {
            speed_dps,
            start_angle_cdeg: start,
            points: pts.map(|(distance_mm, confidence)| RawPoint {
                distance_mm,
                confidence,
            }),
            end_angle_cdeg: end,
            timestamp_ms: ts,
        })
}

fn arb_node() -> impl Strategy<Value = Node> {
    (any::<bool>(), 0u8..64, 0u16..23_040, any::<u16>()).prop_map(|(start, quality, a, d)| Node {
        start,
        quality,
        angle_q6: a,
        distance_q2: d,
    })
}

/// Feeds `bytes` in chunks of the given lengths (cycled) to `step`.
fn chunked(bytes: &[u8], chunks: &[usize], mut step: impl FnMut(&[u8])) {
    let mut rest = bytes;
    let mut i = 0;
    while !rest.is_empty() {
        let n = chunks[i % chunks.len()].clamp(1, rest.len());
        step(&rest[..n]);
        rest = &rest[n..];
        i += 1;
    }
}

proptest! {
    #[test]
    fn ldrobot_frame_round_trips(f in arb_frame()) {
        let mut b = [0u8; FRAME_LEN];
        f.emit_into(&mut b).unwrap();
        prop_assert_eq!(FrameRepr::parse(&b), Ok(f));
        for i in 0..12 {
            let a = f.point_angle_deg(i);
            prop_assert!((0.0..360.0).contains(&a));
        }
    }

    #[test]
    fn rplidar_node_round_trips(n in arb_node()) {
        prop_assert_eq!(Node::parse(&n.to_bytes()), Ok(n));
    }

    /// Good frames with garbage between them, in any chunking: every frame comes out, in
    /// order, and every byte is accounted for. The garbage holds no header byte (0x54): a
    /// header in the garbage within a frame's length of a real frame makes a candidate that
    /// passes the CRC-8 once in 256 and then covers the real frame's header — a loss no
    /// decoder can avoid (CI once drew one); the corruption tests measure those rates.
    #[test]
    fn ldrobot_stream_finds_every_frame(
        frames in prop::collection::vec(arb_frame(), 1..20),
        garbage in prop::collection::vec(
            prop::collection::vec(any::<u8>().prop_map(|b| if b == 0x54 { 0x55 } else { b }), 0..60),
            20,
        ),
        chunks in prop::collection::vec(1usize..100, 1..8),
    ) {
        let mut bytes = Vec::new();
        for (k, f) in frames.iter().enumerate() {
            bytes.extend_from_slice(&garbage[k % garbage.len()]);
            let mut b = [0u8; FRAME_LEN];
            f.emit_into(&mut b).unwrap();
            bytes.extend_from_slice(&b);
        }
        let mut d = ldrobot::Decoder::new();
        let mut out = Vec::new();
        chunked(&bytes, &chunks, |c| {
            let mut input = c;
            while let Some(item) = d.next_frame(&mut input) {
                if let ldrobot::Decoded::Measurement(f) = item {
                    out.push(f);
                }
            }
        });
        // No header in the garbage: exactly the frames sent, never fewer.
        let mut it = out.iter();
        for f in &frames {
            prop_assert!(it.any(|g| g == f), "frame lost");
        }
        let s = d.stats();
        prop_assert_eq!(s.bytes_in, bytes.len() as u64);
        prop_assert!(s.bytes_skipped + d.buffered() as u64 <= s.bytes_in);
    }

    /// Nodes in any chunking come out exactly; every model's stream on random bytes yields
    /// revolutions of 360 bins with sane fields and never panics.
    #[test]
    fn rplidar_nodes_in_any_chunking(
        nodes in prop::collection::vec(arb_node(), 1..200),
        chunks in prop::collection::vec(1usize..64, 1..8),
    ) {
        let mut bytes = Vec::new();
        for n in &nodes {
            bytes.extend_from_slice(&n.to_bytes());
        }
        let mut d = rplidar::Decoder::new();
        let mut out = Vec::new();
        chunked(&bytes, &chunks, |c| {
            let mut input = c;
            while let Some(item) = d.next_item(&mut input) {
                if let rplidar::Decoded::Node(n) = item {
                    out.push(n);
                }
            }
        });
        prop_assert_eq!(out, nodes);
        prop_assert_eq!(d.stats().bytes_in, (NODE_LEN * d.stats().nodes as usize) as u64);
    }

    #[test]
    fn any_model_on_random_bytes(
        bytes in prop::collection::vec(any::<u8>(), 0..4000),
        m in 0usize..6,
        chunks in prop::collection::vec(1usize..300, 1..6),
    ) {
        let model = LidarModel::ALL[m];
        let mut s = AnyLidar::new(model, &LidarConfig::default());
        let mut host = 0u64;
        let mut bad = None;
        chunked(&bytes, &chunks, |c| {
            host += 5_000;
            s.feed(c, Some(host), |r| {
                if r.packets > 60 || r.present.count_ones() != u32::from(r.packets)
                    || !r.t_start_s.is_finite() || r.period_s.is_nan() || r.period_s <= 0.0
                    || r.readings.iter().any(|x| !x.range_m.is_finite())
                {
                    bad = Some(r.seq);
                }
            });
        });
        let _ = s.finish();
        prop_assert_eq!(bad, None);
        prop_assert!(s.sensor_time_s().is_finite());
    }
}
