//! LDS-01 decoder throughput, MB/s, on a 1 MB stream with 1e-3 bit flips (plus inserted and
//! dropped bytes and bursts), against the vendor driver's polling loop on the same bytes.
//!
//! `cargo bench -p umbra-bench --bench lds01_decoder`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use drivers::lds01::{Lds01Config, Lds01Stream};
use drivers::lidar::RevolutionStream as _;
use sim::corrupt::Corruption;
use std::hint::black_box;

const CHUNK: usize = 512;

fn decoders(c: &mut Criterion) {
    let bytes = bench::stream(1 << 20, Corruption::ISSUE_MIX, 1);
    let mut group = c.benchmark_group("lds01_1MB_1e-3");
    group.throughput(Throughput::Bytes(bytes.len() as u64));
    group.bench_function("umbra_stream", |b| {
        b.iter(|| {
            let mut s = Lds01Stream::new(Lds01Config::default());
            let mut revs = 0usize;
            for chunk in bytes.chunks(CHUNK) {
                revs += s.feed(black_box(chunk), None, |r| {
                    black_box(r);
                });
            }
            black_box(revs)
        })
    });
    group.bench_function("vendor_poll_peer", |b| {
        b.iter(|| {
            let mut cursor = black_box(&bytes[..]);
            let mut buff = [0u8; 2520];
            let mut revs = 0usize;
            while let Some(scan) = bench::vendor_poll(&mut cursor, &mut buff) {
                black_box(&scan);
                revs += 1;
            }
            black_box(revs)
        })
    });
    group.finish();
}

criterion_group!(benches, decoders);
criterion_main!(benches);
