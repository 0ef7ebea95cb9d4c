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
    sim::pty::plug(link, timeout)
}

/// A global allocator that counts the allocations (and reallocations) made on the current
/// thread while [`counted`] watches; everything is forwarded to the system allocator. A test
/// binary installs it with `#[global_allocator] static A: umbra_tests::Counting =
/// umbra_tests::Counting;`.
pub struct Counting;

thread_local! {
    static WATCH: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    static COUNT: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

fn note_allocation() {
    if WATCH.with(|w| w.get()) {
        COUNT.with(|c| c.set(c.get() + 1));
    }
}

#[allow(unsafe_code)]
// SAFETY: every call is forwarded unchanged to the system allocator.
unsafe impl std::alloc::GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        note_allocation();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new: usize) -> *mut u8 {
        note_allocation();
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { std::alloc::System.realloc(ptr, layout, new) }
    }
}

/// Runs `f` and returns how many allocations this thread made meanwhile (needs [`Counting`]
/// installed as the global allocator; 0 otherwise).
pub fn counted(f: impl FnOnce()) -> u64 {
    COUNT.with(|c| c.set(0));
    WATCH.with(|w| w.set(true));
    f();
    WATCH.with(|w| w.set(false));
    COUNT.with(|c| c.get())
}

/// The allocations counted so far inside the innermost running [`counted`] (for marking
/// points inside a long call, e.g. at every frame of a run).
pub fn allocations() -> u64 {
    COUNT.with(|c| c.get())
}
