//! The LDS-01 decoder on a noisy line: a clean simulated stream (1,000 revolutions, 60,000
//! packets) with bit flips at 1e-3 per bit plus inserted and dropped bytes and garbage bursts.
//!
//! * ≥ 99 % of the packets that crossed the line untouched must be recovered.
//! * Every error the LDS-01 checksum can detect must be rejected under `verify`: with framing
//!   errors and up to one flipped bit per packet, 0 corrupt packets may come out.
//! * With independent flips at 1e-3 per bit, ~6 % of packets carry two or more flipped bits, and
//!   an 8-bit additive checksum cannot see two flips of the same bit column in opposite
//!   directions (or two flips of bit 7): those packets carry a valid checksum and are
//!   indistinguishable from real ones. No decoder can reject them; we measure how many there are
//!   (printed) and fail if it exceeds what that weakness explains (1 % of corrupted packets;
//!   measured ~0.6 %).

use std::collections::HashMap;

use drivers::lds01::{ChecksumPolicy, Decoder, PACKET_LEN};
use sim::corrupt::{Corruption, corrupt};
use sim::lds01::{Lds01Sim, Lds01SimConfig};
use sim::world::World;

struct Figures {
    sent: usize,
    untouched: usize,
    decoded: usize,
    corrupt_accepted: usize,
    untouched_recovered: usize,
    bad_checksum: u64,
}

fn run(revolutions: usize, mix: Corruption, seed: u64, policy: ChecksumPolicy) -> Figures {
    let mut sim = Lds01Sim::new(World::random_room(seed), Lds01SimConfig::default(), seed);
    let mut clean = Vec::new();
    sim.emit_revolutions(revolutions, &mut clean);
    let packets: Vec<&[u8]> = clean.chunks_exact(PACKET_LEN).collect();
    let noisy = corrupt(packets.iter().copied(), mix, seed ^ 0x5eed);

    // Multiset of sent packets, and of untouched ones.
    let mut sent: HashMap<&[u8], usize> = HashMap::new();
    let mut untouched: HashMap<&[u8], usize> = HashMap::new();
    for (p, ok) in packets.iter().zip(&noisy.untouched) {
        *sent.entry(p).or_default() += 1;
        if *ok {
            *untouched.entry(p).or_default() += 1;
        }
    }
    let n_untouched = noisy.untouched.iter().filter(|u| **u).count();

    let mut decoder = Decoder::new(policy);
    let (mut decoded, mut corrupt_accepted, mut recovered) = (0, 0, 0);
    // Feed in uneven chunks, as a serial port delivers them.
    let mut rest = &noisy.bytes[..];
    let mut chunk = 1;
    while !rest.is_empty() {
        let n = chunk.min(rest.len());
        for d in decoder.feed(&rest[..n]) {
            decoded += 1;
            let mut bytes = [0u8; PACKET_LEN];
            d.repr.emit_into(&mut bytes).unwrap();
            // Under `verify` an accepted packet's checksum holds, so re-emitting it gives back
            // exactly the bytes received.
            match sent.get_mut(&bytes[..]) {
                Some(c) if *c > 0 => {
                    *c -= 1;
                    if let Some(u) = untouched.get_mut(&bytes[..]).filter(|u| **u > 0) {
                        *u -= 1;
                        recovered += 1;
                    }
                }
                _ => corrupt_accepted += 1,
            }
        }
        rest = &rest[n..];
        chunk = chunk % 300 + 37;
    }
    Figures {
        sent: packets.len(),
        untouched: n_untouched,
        decoded,
        corrupt_accepted,
        untouched_recovered: recovered,
        bad_checksum: decoder.stats().bad_checksum,
    }
}

fn report(name: &str, f: &Figures) {
    println!(
        "{name}: sent {} packets, {} untouched; decoded {}; corrupt accepted {}; untouched recovered {} ({:.3} %); bad checksum {}",
        f.sent,
        f.untouched,
        f.decoded,
        f.corrupt_accepted,
        f.untouched_recovered,
        100.0 * f.untouched_recovered as f64 / f.untouched.max(1) as f64,
        f.bad_checksum
    );
}

#[test]
fn detectable_errors_never_accepted_under_verify() {
    let mix = Corruption {
        max_flips_per_packet: 1,
        ..Corruption::ISSUE_MIX
    };
    let f = run(1000, mix, 42, ChecksumPolicy::Verify);
    report(
        "1e-3 bit flips (≤ 1 per packet) + inserts + drops + bursts, verify",
        &f,
    );
    assert!(f.untouched_recovered as f64 >= 0.99 * f.untouched as f64);
    assert_eq!(
        f.corrupt_accepted, 0,
        "corrupt packets accepted under verify"
    );
}

#[test]
fn issue_mix_under_verify() {
    let f = run(1000, Corruption::ISSUE_MIX, 42, ChecksumPolicy::Verify);
    report("1e-3 bit flips + inserts + drops + bursts, verify", &f);
    assert!(f.untouched_recovered as f64 >= 0.99 * f.untouched as f64);
    let corrupted = f.sent - f.untouched;
    println!(
        "corrupt accepted: {} of {} corrupted packets ({:.3} %), {:.4} % of all packets",
        f.corrupt_accepted,
        corrupted,
        100.0 * f.corrupt_accepted as f64 / corrupted as f64,
        100.0 * f.corrupt_accepted as f64 / f.sent as f64
    );
    assert!(
        (f.corrupt_accepted as f64) <= 0.01 * corrupted as f64,
        "more corrupt packets accepted than checksum collisions explain"
    );
}
