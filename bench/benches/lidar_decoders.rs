//! The LDROBOT and RPLIDAR streams' throughput, MB/s, on about 1 MB of each model's simulated
//! bytes through the noisy line (1e-3 bit flips, inserted/dropped bytes, bursts), each against
//! a peer in the same run written after the vendor's parsing rule (`docs/hardware.md` §1): the LDROBOT
//! SDK's byte state machine (collect 47 bytes, then check the CRC, restart at the next byte)
//! and the RPLIDAR SDK's node loop (slide one byte on a failed bit test). The peers only frame
//! and parse; ours also bin into revolutions, so the ratio is conservative.
//!
//! `cargo bench -p umbra-bench --bench lidar_decoders`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use drivers::ldrobot::frame::{FRAME_LEN, FrameRepr, crc8};
use drivers::lidar::{AnyLidar, LidarConfig, LidarModel, RevolutionStream};
use drivers::rplidar::protocol::{NODE_LEN, Node, sync_ok};
use sim::corrupt::{Corruption, corrupt};
use sim::scenario::{Scenario, ScenarioConfig};
use sim::wire::WireSim;
use std::hint::black_box;

const CHUNK: usize = 512;

fn noisy(model: LidarModel) -> Vec<u8> {
    let mut sim = WireSim::new(Scenario::new(1, &ScenarioConfig::standard()), model);
    let mut clean = Vec::new();
    while clean.len() < 1 << 20 {
        sim.emit_revolution(&mut clean);
    }
    corrupt(clean.chunks(sim.unit_len()), Corruption::ISSUE_MIX, 1).bytes
}

/// The LDROBOT SDK's rule: a 47-byte state machine that checks the CRC only when full.
fn ldrobot_peer(bytes: &[u8]) -> usize {
    let (mut buf, mut len, mut frames) = ([0u8; FRAME_LEN], 0usize, 0usize);
    for &b in bytes {
        match len {
            0 if b != 0x54 => continue,
            1 if b != 0x2C => {
                len = 0;
                continue;
            }
            _ => {}
        }
        buf[len] = b;
        len += 1;
        if len == FRAME_LEN {
            if crc8(&buf[..46]) == buf[46] {
                black_box(FrameRepr::parse_unchecked(&buf));
                frames += 1;
            }
            len = 0;
        }
    }
    frames
}

/// The RPLIDAR SDK's rule: slide one byte until the S/!S/C bits pass, then take 5 bytes.
fn rplidar_peer(bytes: &[u8]) -> usize {
    let (mut i, mut nodes) = (0, 0);
    while i + NODE_LEN <= bytes.len() {
        if sync_ok(bytes[i], bytes[i + 1]) {
            black_box(Node::parse(&bytes[i..i + NODE_LEN]).ok());
            nodes += 1;
            i += NODE_LEN;
        } else {
            i += 1;
        }
    }
    nodes
}

fn decoders(c: &mut Criterion) {
    for (model, peer) in [
        (LidarModel::Ld06, ldrobot_peer as fn(&[u8]) -> usize),
        (LidarModel::RplidarA1, rplidar_peer),
    ] {
        let bytes = noisy(model);
        let mut group = c.benchmark_group(format!("{}_1MB_1e-3", model.cli_name()));
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_function("umbra_stream", |b| {
            b.iter(|| {
                let mut s = AnyLidar::new(model, &LidarConfig::default());
                let mut revs = 0usize;
                for chunk in bytes.chunks(CHUNK) {
                    revs += s.feed(black_box(chunk), None, |r| {
                        black_box(r);
                    });
                }
                black_box(revs)
            })
        });
        group.bench_function("vendor_rule_peer", |b| {
            b.iter(|| black_box(peer(black_box(&bytes))))
        });
        group.finish();
    }
}

criterion_group!(benches, decoders);
criterion_main!(benches);
