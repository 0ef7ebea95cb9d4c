//! Arbitrary bytes as one packet: `new_checked`, every accessor, `parse`, and `emit` back.
//! A checked packet whose checksum holds must re-emit to the same 42 bytes.
#![no_main]

use drivers::lds01::{PACKET_LEN, Packet, Repr};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(packet) = Packet::new_checked(data) else {
        return;
    };
    for j in 0..8 {
        let _ = (packet.intensity(j), packet.range_mm(j), packet.reserved(j));
    }
    let repr = Repr::parse(&packet);
    assert!(repr.index < 60);
    let mut out = [0u8; PACKET_LEN];
    repr.emit_into(&mut out).unwrap();
    if packet.checksum_ok() {
        assert_eq!(&out[..], &data[..PACKET_LEN]);
    }
});
