//! Arbitrary bytes, split into arbitrary chunks, through the RPLIDAR decoder (descriptors,
//! replies, nodes with the one-byte slide resync) and stream. Checks the revolution's bounds
//! and that every byte is accounted for; a panic anywhere is a bug.
#![no_main]

use drivers::lidar::points::PointConfig;
use drivers::lidar::{LidarModel, RevolutionStream};
use drivers::rplidar::{RplidarConfig, RplidarStream};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&shape, bytes)) = data.split_first() else {
        return;
    };
    let model = if shape & 1 == 0 {
        LidarModel::RplidarA1
    } else {
        LidarModel::RplidarA2
    };
    let chunk = usize::from(shape >> 1).max(1);
    let mut stream = RplidarStream::new(RplidarConfig {
        model,
        points: PointConfig {
            min_range_m: 0.15,
            max_range_m: 12.0,
            stale_after_us: 500_000,
        },
    });
    let mut host_us = 0u64;
    for piece in bytes.chunks(chunk) {
        host_us += 3_000;
        stream.feed(piece, Some(host_us), |rev| {
            assert!(rev.packets as usize <= 60);
            assert_eq!(rev.packets as u32, rev.present.count_ones());
            assert!(rev.t_start_s.is_finite() && rev.period_s.is_finite() && rev.period_s > 0.0);
        });
        let _ = stream.poll(host_us);
    }
    let d = *stream.decoder().stats();
    assert_eq!(d.bytes_in, bytes.len() as u64);
    assert!(d.bytes_skipped + 5 * d.nodes + stream.decoder().buffered() as u64 <= d.bytes_in);
    let _ = stream.finish();
});
