//! Arbitrary bytes through the DYNAMIXEL 2.0 status decoder in arbitrary chunks (byte
//! accounting must hold, nothing may panic), and arbitrary status contents through
//! `emit` → decode (must round-trip, stuffing included).
#![no_main]

use drivers::dynamixel::{INST_STATUS, MAX_STATUS_DATA, StatusDecoder, emit};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&shape, bytes)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(shape).max(1);
    let mut d = StatusDecoder::new();
    let mut packets = 0u64;
    let mut consumed = 0u64;
    for piece in bytes.chunks(chunk) {
        let mut input = piece;
        while let Some(s) = d.next_status(&mut input) {
            assert!(s.data().len() <= MAX_STATUS_DATA);
            packets += 1;
        }
        consumed += piece.len() as u64;
    }
    let st = *d.stats();
    assert_eq!(st.bytes_in, consumed);
    assert_eq!(st.packets, packets);
    assert!(st.bytes_skipped + d.buffered() as u64 <= st.bytes_in);

    // Round trip: the same bytes as the contents of a status packet.
    let contents = &bytes[..bytes.len().min(20)];
    let mut params = [0u8; 21];
    params[0] = shape & 0x7F; // error byte
    params[1..=contents.len()].copy_from_slice(contents);
    let mut out = [0u8; 64];
    if let Ok(n) = emit(shape, INST_STATUS, &params[..=contents.len()], &mut out) {
        let mut dec = StatusDecoder::new();
        let mut input = &out[..n];
        let s = dec
            .next_status(&mut input)
            .expect("an emitted status decodes");
        assert_eq!(s.id, shape);
        assert_eq!(s.error, shape & 0x7F);
        assert_eq!(s.data(), contents);
    }
});
