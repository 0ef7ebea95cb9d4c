//! Arbitrary bytes, split into arbitrary chunks, through the LDROBOT decoder and stream
//! (plausibility filter, angle interpolation, LD08 correction, point assembler) for each of
//! the three models. Checks the decoder's byte accounting and the revolution's bounds; a panic
//! anywhere is a bug.
#![no_main]

use drivers::ldrobot::{FRAME_LEN, LdrobotConfig, LdrobotStream};
use drivers::lidar::points::PointConfig;
use drivers::lidar::{LidarModel, RevolutionStream};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&shape, bytes)) = data.split_first() else {
        return;
    };
    let model = [LidarModel::Lds02, LidarModel::Ld06, LidarModel::Ld19][usize::from(shape % 3)];
    let chunk = usize::from(shape / 3).max(1);
    let mut stream = LdrobotStream::new(LdrobotConfig {
        model,
        points: PointConfig {
            min_range_m: 0.02,
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
            assert!(
                rev.readings
                    .iter()
                    .all(|r| r.range_m.is_finite() && r.range_m >= 0.0)
            );
        });
        let _ = stream.poll(host_us);
    }
    let d = *stream.decoder().stats();
    assert_eq!(d.bytes_in, bytes.len() as u64);
    // Frames yielded: 47 bytes each; health 4, info 27 (counted together in other_frames, so
    // bound rather than equate).
    let framed = d.bytes_in - d.bytes_skipped - stream.decoder().buffered() as u64;
    assert!(framed >= FRAME_LEN as u64 * d.frames + 4 * d.other_frames);
    assert!(framed <= FRAME_LEN as u64 * d.frames + 27 * d.other_frames);
    let _ = stream.finish();
});
