//! Shared helpers of umbra's hardware-in-the-loop and end-to-end tests (in `tests/`).
#![deny(missing_docs)]

use std::path::PathBuf;

/// The shared data folder (`../shared/data` beside the repository), if present.
pub fn shared_data() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    dir.is_dir().then_some(dir)
}

/// Opens a pseudo-terminal pair and points the symlink `link` at its slave side, as udev points
/// `/dev/serial/by-id/…` at a USB adapter; the slave handle is closed so that the code under test
/// can open the path. Returns the master side (the "device"), with `timeout` on its reads.
/// Calling it again on the same `link` is a replug: a new pty behind the same path.
///
/// # Panics
/// If the pty or the symlink cannot be made (a test fixture: failing loudly is right).
pub fn plug_pty(link: &std::path::Path, timeout: std::time::Duration) -> serialport::TTYPort {
    use serialport::SerialPort;
    let (mut master, slave) = serialport::TTYPort::pair().expect("pty pair");
    let name = slave.name().expect("slave name");
    drop(slave);
    master.set_timeout(timeout).expect("pty timeout");
    let tmp = link.with_extension("new");
    let _ = std::fs::remove_file(&tmp);
    std::os::unix::fs::symlink(&name, &tmp).expect("symlink");
    std::fs::rename(&tmp, link).expect("rename symlink");
    master
}
