//! Arbitrary bytes, split into arbitrary chunks, through the streaming decoder and the
//! revolution assembler under both checksum policies. Checks the byte accounting invariant
//! and the assembler's bounds; a panic anywhere is a bug.
//!
//! No `cfg(fuzzing)` checksum bypass is needed: the `Count` policy already lets packets with
//! bad checksums through to the assembler.
#![no_main]

use drivers::lds01::{ChecksumPolicy, Lds01Config, Lds01Stream, PACKET_LEN};
use drivers::lidar::RevolutionStream;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&shape, bytes)) = data.split_first() else {
        return;
    };
    let policy = if shape & 1 == 0 {
        ChecksumPolicy::Verify
    } else {
        ChecksumPolicy::Count
    };
    let chunk = usize::from(shape >> 1).max(1);
    let mut stream = Lds01Stream::new(Lds01Config {
        checksum: policy,
        ..Lds01Config::default()
    });
    let mut host_us = 0u64;
    for piece in bytes.chunks(chunk) {
        host_us += 3_000;
        stream.feed(piece, Some(host_us), |rev| {
            assert!(rev.packets as usize <= 60);
            assert_eq!(rev.packets as u32, rev.present.count_ones());
            assert!(rev.t_start_s.is_finite() && rev.period_s.is_finite());
            if policy == ChecksumPolicy::Verify {
                assert_eq!(rev.bad_checksum_packets, 0);
            }
        });
        let _ = stream.poll(host_us);
    }
    let d = *stream.decoder().stats();
    assert_eq!(d.bytes_in, bytes.len() as u64);
    assert_eq!(
        d.bytes_in,
        d.bytes_skipped + PACKET_LEN as u64 * d.packets + stream.decoder().buffered() as u64
    );
    let _ = stream.finish();
});
