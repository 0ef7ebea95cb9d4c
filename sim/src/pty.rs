//! Devices on pseudo-terminals, for hardware-in-the-loop tests (feature `pty`): a pty pair
//! whose slave is reached through a symlink, as udev's `/dev/serial/by-id/…` reaches a USB
//! adapter (plugging again is a replug), and the small protocol pieces the emulated LDS-01 and
//! OpenCR need: waiting for the motor-start byte, hearing the stop byte, answering DYNAMIXEL 2.0
//! READs from a control table.
//!
//! These are test fixtures: a pty or symlink that cannot be made panics (failing loudly is
//! right there).

use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use drivers::dynamixel::{INST_STATUS, StatusDecoder, emit};
use serialport::{SerialPort, TTYPort};

/// The OpenCR's DYNAMIXEL id.
pub const OPENCR_ID: u8 = 200;
/// Control-table addresses of the wheels' present positions (i32, little-endian).
pub const PRESENT_POSITION: (usize, usize) = (136, 140);

/// Opens a pty pair and points `link` at its slave side; returns the master side (the
/// "device") with `timeout` on its reads. The slave handle is closed so that the code under
/// test can open the path. The master is made close-on-exec (`serialport` opens it without):
/// otherwise a child process (the `umbra` binary under test) inherits it and holds the pty
/// open through an "unplug".
///
/// # Panics
/// If the pty or the symlink cannot be made.
pub fn plug(link: &Path, timeout: Duration) -> TTYPort {
    use std::os::fd::{FromRawFd, IntoRawFd, OwnedFd};
    let (master, slave) = TTYPort::pair().expect("pty pair");
    let name = slave.name().expect("slave name");
    drop(slave);
    // SAFETY: the descriptor comes from `into_raw_fd`: open, and owned by nobody else.
    #[allow(unsafe_code)]
    let raw = unsafe { OwnedFd::from_raw_fd(master.into_raw_fd()) };
    // `try_clone` duplicates with F_DUPFD_CLOEXEC; dropping `raw` closes the inheritable one.
    let cloexec = raw.try_clone().expect("dup pty master");
    drop(raw);
    // SAFETY: as above.
    #[allow(unsafe_code)]
    let mut master = unsafe { TTYPort::from_raw_fd(cloexec.into_raw_fd()) };
    master.set_timeout(timeout).expect("pty timeout");
    let tmp = link.with_extension("new");
    let _ = std::fs::remove_file(&tmp);
    std::os::unix::fs::symlink(&name, &tmp).expect("symlink");
    std::fs::rename(&tmp, link).expect("rename symlink");
    master
}

/// Waits up to `timeout` for `byte` on `master`; everything heard is appended to `heard`.
pub fn expect_byte(master: &mut TTYPort, byte: u8, timeout: Duration, heard: &mut Vec<u8>) -> bool {
    let end = Instant::now() + timeout;
    let mut buf = [0u8; 64];
    while Instant::now() < end {
        if let Ok(n) = master.read(&mut buf) {
            heard.extend_from_slice(&buf[..n]);
            if buf[..n].contains(&byte) {
                return true;
            }
        }
    }
    false
}

/// Whether the stop byte `e` is in `heard` or arrives before the host closes its side (or 5 s
/// pass). Plain file reads: `serialport` reports a hang-up before the bytes that preceded it,
/// and a host writes `e` right before closing.
pub fn saw_stop_byte(master: TTYPort, heard: &[u8]) -> bool {
    use std::os::fd::{FromRawFd, IntoRawFd};
    if heard.contains(&b'e') {
        return true;
    }
    // SAFETY: the descriptor comes from `into_raw_fd`, so it is open and owned by nobody else.
    #[allow(unsafe_code)]
    let mut file = unsafe { std::fs::File::from_raw_fd(master.into_raw_fd()) };
    let end = Instant::now() + Duration::from_secs(5);
    let mut buf = [0u8; 64];
    while Instant::now() < end {
        match file.read(&mut buf) {
            Ok(n) if buf[..n].contains(&b'e') => return true,
            Ok(0) | Err(_) => std::thread::sleep(Duration::from_millis(20)),
            Ok(_) => {}
        }
    }
    false
}

/// Plays the OpenCR on `master` until `stop`: answers every DYNAMIXEL 2.0 READ addressed to
/// [`OPENCR_ID`] from a control table whose present positions are `ticks()` (left, right) at
/// the moment of the request. Returns the READs answered.
pub fn serve_opencr(
    master: &mut TTYPort,
    stop: &AtomicBool,
    mut ticks: impl FnMut() -> (i32, i32),
) -> u64 {
    let mut dec = StatusDecoder::new();
    let mut buf = [0u8; 256];
    let mut answered = 0;
    while !stop.load(Ordering::Relaxed) {
        let n = match master.read(&mut buf) {
            Ok(n) => n,
            // No slave side open yet (EIO / hang-up on a pty master) or nothing to read.
            Err(_) => {
                std::thread::sleep(Duration::from_millis(2));
                continue;
            }
        };
        let mut input = &buf[..n];
        while let Some(p) = dec.next_packet(&mut input) {
            let Some((addr, len)) = p.read_args().filter(|_| p.id == OPENCR_ID) else {
                continue;
            };
            let (l, r) = ticks();
            let mut table = [0u8; 256];
            let (al, ar) = PRESENT_POSITION;
            table[al..al + 4].copy_from_slice(&l.to_le_bytes());
            table[ar..ar + 4].copy_from_slice(&r.to_le_bytes());
            let (a, l) = (usize::from(addr), usize::from(len).min(64));
            let mut params = [0u8; 65];
            let end = (a + l).min(table.len());
            params[1..=end - a].copy_from_slice(&table[a..end]);
            let mut out = [0u8; 96];
            if let Ok(n) = emit(OPENCR_ID, INST_STATUS, &params[..=l], &mut out) {
                let _ = master.write_all(&out[..n]);
                answered += 1;
            }
        }
    }
    answered
}
