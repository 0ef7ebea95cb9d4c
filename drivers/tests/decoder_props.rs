//! Property tests of the LDS-01 decoder and assembler over random streams.

use drivers::lds01::{
    ChecksumPolicy, Decoded, Decoder, Lds01Config, Lds01Stream, PACKET_LEN, Packet, RawReading,
    Repr,
};
use drivers::lidar::RevolutionStream as _;
use proptest::prelude::*;

fn arb_repr() -> impl Strategy<Value = Repr> {
    (
        0u8..60,
        any::<u16>(),
        prop::array::uniform6((any::<u16>(), any::<u16>(), any::<u16>())),
    )
        .prop_map(|(index, speed_raw, r)| Repr {
            index,
            speed_raw,
            readings: r.map(|(intensity, range_mm, reserved)| RawReading {
                intensity,
                range_mm,
                reserved,
            }),
        })
}

fn emit(repr: &Repr) -> [u8; PACKET_LEN] {
    let mut b = [0u8; PACKET_LEN];
    repr.emit_into(&mut b).unwrap();
    b
}

/// Decodes `bytes` split at the given chunk lengths (cycled).
fn decode_chunked(d: &mut Decoder, bytes: &[u8], chunks: &[usize]) -> Vec<Decoded> {
    let mut out = Vec::new();
    let mut rest = bytes;
    let mut i = 0;
    while !rest.is_empty() {
        let n = chunks[i % chunks.len()].clamp(1, rest.len());
        out.extend(d.feed(&rest[..n]));
        rest = &rest[n..];
        i += 1;
    }
    out
}

fn accounting_holds(d: &Decoder) -> bool {
    let s = d.stats();
    s.bytes_in == s.bytes_skipped + PACKET_LEN as u64 * s.packets + d.buffered() as u64
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn emit_parse_round_trip(repr in arb_repr()) {
        let bytes = emit(&repr);
        let p = Packet::new_checked(&bytes[..]).unwrap();
        prop_assert!(p.checksum_ok());
        prop_assert_eq!(Repr::parse(&p), repr);
    }

    #[test]
    fn arbitrary_bytes_never_panic_and_are_accounted(
        bytes in prop::collection::vec(any::<u8>(), 0..4000),
        chunks in prop::collection::vec(1usize..200, 1..8),
        count in any::<bool>(),
    ) {
        let policy = if count { ChecksumPolicy::Count } else { ChecksumPolicy::Verify };
        let mut d = Decoder::new(policy);
        let out = decode_chunked(&mut d, &bytes, &chunks);
        prop_assert!(accounting_holds(&d));
        prop_assert_eq!(d.stats().bytes_in, bytes.len() as u64);
        prop_assert_eq!(out.len() as u64, d.stats().packets);
        if !count {
            prop_assert!(out.iter().all(|p| p.checksum_ok));
        }
        // The assembler swallows anything the decoder yields.
        let mut s = Lds01Stream::new(Lds01Config { checksum: policy, ..Lds01Config::default() });
        let mut revs = 0;
        s.feed(&bytes, None, |r| { revs += 1; assert!(r.packets <= 60); });
        if s.finish().is_some() {
            revs += 1;
        }
        prop_assert!(s.assembler().stats().revolutions == revs);
    }

    #[test]
    fn packets_survive_garbage_between_them(
        reprs in prop::collection::vec(arb_repr(), 1..40),
        garbage in prop::collection::vec(prop::collection::vec(any::<u8>().prop_filter("no sync", |b| *b != 0xFA), 0..60), 1..40),
        chunks in prop::collection::vec(1usize..300, 1..8),
    ) {
        let mut stream = Vec::new();
        for (i, r) in reprs.iter().enumerate() {
            stream.extend_from_slice(&garbage[i % garbage.len()]);
            stream.extend_from_slice(&emit(r));
        }
        let mut d = Decoder::default();
        let out = decode_chunked(&mut d, &stream, &chunks);
        let got: Vec<Repr> = out.iter().map(|p| p.repr).collect();
        prop_assert_eq!(&got, &reprs);
        prop_assert!(accounting_holds(&d));
        prop_assert_eq!(d.buffered(), 0);
    }

    #[test]
    fn chunking_does_not_change_the_result(
        bytes in prop::collection::vec(any::<u8>(), 0..3000),
        a in prop::collection::vec(1usize..100, 1..6),
        b in prop::collection::vec(1usize..500, 1..6),
    ) {
        let mut da = Decoder::new(ChecksumPolicy::Count);
        let mut db = Decoder::new(ChecksumPolicy::Count);
        let oa = decode_chunked(&mut da, &bytes, &a);
        let ob = decode_chunked(&mut db, &bytes, &b);
        prop_assert_eq!(oa, ob);
        prop_assert_eq!(da.stats(), db.stats());
    }

    #[test]
    fn a_truncated_packet_never_hides_the_next(
        r1 in arb_repr(), r2 in arb_repr(), cut in 1usize..PACKET_LEN,
    ) {
        let mut stream = emit(&r1)[..cut].to_vec();
        stream.extend_from_slice(&emit(&r2));
        let mut d = Decoder::default();
        let out: Vec<Repr> = d.feed(&stream).map(|p| p.repr).collect();
        // r2 always comes out; the truncated r1 only in the vanishing case that its prefix
        // plus r2's bytes happen to form a valid packet, which then consumed r2's start.
        let found = out.last() == Some(&r2);
        let collision = out.len() == 1 && out[0] != r2;
        prop_assert!(found || collision, "lost the packet after a truncated one: {:?}", out);
        prop_assert!(accounting_holds(&d));
    }
}
