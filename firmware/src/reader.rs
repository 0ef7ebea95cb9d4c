//! Reader threads: the devices' blocking I/O off the frame loop, handed over through
//! fixed-capacity queues.
//!
//! * [`LidarReader`] owns a LiDAR's [`SerialLink`] and reads into [`Chunk`]s taken from a pool
//!   of [`CHUNK_POOL`] boxes made at start-up; a full chunk goes to the loop through a bounded
//!   channel and comes back to the pool when the loop has fed it to the decoder. When the loop
//!   falls behind the pool runs dry, the thread stops reading, and the bytes wait in the
//!   kernel's buffer, where [`LidarReader::backlog_bytes`] sees them: nothing is dropped and
//!   nothing queues without bound.
//! * [`DeviceReader`] polls the OpenCR and the compass at [`DEVICE_POLL_HZ`] and hands each
//!   sample, stamped with the host's monotonic clock, through a bounded channel of
//!   [`DEVICE_QUEUE`]; a sample that finds it full is dropped and counted.
//!
//! Neither thread allocates per read (a lost link's message is the only `String`). The loop
//! maps host stamps onto the LiDAR's clock with [`ClockMap`].

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, TrySendError, sync_channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use drivers::opencr::OpencrReader;
use drivers::serial::{LinkRead, SerialLink};

/// Reads the compass once; the error names the device. Runs on the device thread.
pub type CompassReader = Box<dyn FnMut() -> Result<[f32; 3], String> + Send>;

/// Opens an LSM303AGR on the I²C bus at `bus` (e.g. `/dev/i2c-1`); a failure is reported once
/// and the runtime goes on without a compass.
pub fn open_compass(bus: &str) -> Option<CompassReader> {
    let i2c = match linux_embedded_hal::I2cdev::new(bus) {
        Ok(i2c) => i2c,
        Err(e) => {
            log::warn!("--compass {bus}: cannot open the I2C bus ({e}); running without a compass");
            return None;
        }
    };
    match drivers::compass::Lsm303Compass::new(i2c, linux_embedded_hal::Delay) {
        Ok(mut c) => {
            let bus = bus.to_owned();
            Some(Box::new(move || {
                c.read_ut().map_err(|e| format!("--compass {bus}: {e}"))
            }))
        }
        Err(e) => {
            log::warn!("--compass {bus}: no LSM303AGR answers ({e}); running without a compass");
            None
        }
    }
}

/// Bytes one chunk holds (a LiDAR read returns what is there, usually far less).
pub const CHUNK_BYTES: usize = 512;
/// Chunks in the LiDAR pool: 16 KiB, over six LDS-01 revolutions.
pub const CHUNK_POOL: usize = 32;
/// How often the device thread polls the OpenCR and the compass.
pub const DEVICE_POLL_HZ: f64 = 20.0;
/// Device samples waiting for the loop, at most (2 s at 20 Hz).
pub const DEVICE_QUEUE: usize = 40;

/// Bytes read from the LiDAR at one time.
pub struct Chunk {
    /// Bytes used in `data`.
    pub len: usize,
    /// When they were read.
    pub host: Instant,
    /// The bytes.
    pub data: [u8; CHUNK_BYTES],
}

/// What the LiDAR thread tells the loop.
pub enum LidarEvent {
    /// Bytes; hand the box back with [`LidarReader::recycle`].
    Data(Box<Chunk>),
    /// The link was lost (the thread reopens it with back-off); the message names the device.
    Lost(String),
    /// The link came back.
    Reopened,
}

/// What the loop sees of the LiDAR thread.
#[derive(Debug, Default)]
struct LidarShared {
    stop: AtomicBool,
    /// Bytes waiting in the kernel, `u32::MAX` when unknown.
    backlog: AtomicU32,
    /// Chunks sent and not yet taken by the loop.
    queued: AtomicUsize,
    /// Bytes in those chunks.
    queued_bytes: AtomicUsize,
    errors: AtomicU64,
    reopens: AtomicU64,
}

/// The loop's end of the LiDAR reader thread.
pub struct LidarReader {
    events: Receiver<LidarEvent>,
    pool: SyncSender<Box<Chunk>>,
    shared: Arc<LidarShared>,
    thread: Option<JoinHandle<()>>,
    path: String,
    max_queued: usize,
}

impl std::fmt::Debug for LidarReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LidarReader")
            .field("path", &self.path)
            .finish()
    }
}

impl LidarReader {
    /// Starts the thread that reads `link`; the link (and its motor stop on drop) goes with
    /// it and is dropped when the reader is.
    pub fn start(link: SerialLink) -> Result<LidarReader, String> {
        let path = link.path().to_owned();
        let shared = Arc::new(LidarShared {
            backlog: AtomicU32::new(u32::MAX),
            ..LidarShared::default()
        });
        let (pool_tx, pool_rx) = sync_channel::<Box<Chunk>>(CHUNK_POOL);
        for _ in 0..CHUNK_POOL {
            let _ = pool_tx.try_send(Box::new(Chunk {
                len: 0,
                host: Instant::now(),
                data: [0; CHUNK_BYTES],
            }));
        }
        // Every chunk is in the pool, in the queue or in the loop's hands: the queue never
        // holds more than the pool has.
        let (events_tx, events) = sync_channel::<LidarEvent>(CHUNK_POOL + 2);
        let sh = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("umbra-lidar".into())
            .spawn(move || lidar_thread(link, &pool_rx, &events_tx, &sh))
            .map_err(|e| format!("cannot start the LiDAR reader thread: {e}"))?;
        Ok(LidarReader {
            events,
            pool: pool_tx,
            shared,
            thread: Some(thread),
            path,
            max_queued: 0,
        })
    }

    /// The port's path.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The next event, waiting at most `wait`; `None` when nothing came.
    pub fn next(&mut self, wait: Duration) -> Option<LidarEvent> {
        let ev = match self.events.try_recv() {
            Ok(ev) => Some(ev),
            Err(TryRecvError::Empty) => self.events.recv_timeout(wait).ok(),
            Err(TryRecvError::Disconnected) => None,
        };
        if let Some(LidarEvent::Data(c)) = &ev {
            let before = self.shared.queued.fetch_sub(1, Ordering::AcqRel);
            self.max_queued = self.max_queued.max(before);
            self.shared.queued_bytes.fetch_sub(c.len, Ordering::AcqRel);
        }
        ev
    }

    /// Gives a chunk back to the pool.
    pub fn recycle(&self, chunk: Box<Chunk>) {
        let _ = self.pool.try_send(chunk);
    }

    /// Bytes read but not yet taken by the loop, plus bytes waiting in the kernel (`None`
    /// while the port is closed).
    pub fn backlog_bytes(&self) -> Option<u32> {
        let kernel = self.shared.backlog.load(Ordering::Acquire);
        (kernel != u32::MAX)
            .then(|| kernel.saturating_add(self.shared.queued_bytes.load(Ordering::Acquire) as u32))
    }

    /// Chunks waiting for the loop now.
    pub fn queue_depth(&self) -> usize {
        self.shared.queued.load(Ordering::Acquire)
    }

    /// The deepest the queue has been when the loop took a chunk.
    pub fn max_queue_depth(&self) -> usize {
        self.max_queued
    }

    /// (read errors + end-of-files, reopens) of the link.
    pub fn link_counts(&self) -> (u64, u64) {
        (
            self.shared.errors.load(Ordering::Acquire),
            self.shared.reopens.load(Ordering::Acquire),
        )
    }
}

impl Drop for LidarReader {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn lidar_thread(
    mut link: SerialLink,
    pool: &Receiver<Box<Chunk>>,
    events: &SyncSender<LidarEvent>,
    shared: &LidarShared,
) {
    let publish = |link: &SerialLink| {
        let s = link.stats();
        shared
            .backlog
            .store(link.backlog_bytes().unwrap_or(u32::MAX), Ordering::Release);
        shared
            .errors
            .store(s.read_errors + s.eofs, Ordering::Release);
        shared.reopens.store(s.reopens, Ordering::Release);
    };
    let mut chunk: Option<Box<Chunk>> = None;
    while !shared.stop.load(Ordering::Acquire) {
        let Some(mut c) = chunk.take().or_else(|| {
            // An empty pool means the loop is behind: stop reading, let the kernel hold the
            // bytes (and show them as backlog).
            publish(&link);
            pool.recv_timeout(Duration::from_millis(50)).ok()
        }) else {
            continue;
        };
        let ev = match link.read(&mut c.data) {
            LinkRead::Data(n) => {
                c.len = n;
                c.host = Instant::now();
                shared.queued.fetch_add(1, Ordering::AcqRel);
                shared.queued_bytes.fetch_add(n, Ordering::AcqRel);
                LidarEvent::Data(c)
            }
            LinkRead::Idle => {
                chunk = Some(c);
                publish(&link);
                continue;
            }
            LinkRead::Lost(e) => {
                chunk = Some(c);
                LidarEvent::Lost(e.to_string())
            }
            LinkRead::Reopened => {
                chunk = Some(c);
                LidarEvent::Reopened
            }
        };
        publish(&link);
        if !send_until_stopped(events, ev, &shared.stop) {
            break; // the loop is gone or stopping
        }
    }
    // Dropping the link stops the motor.
    drop(link);
}

/// Sends `ev`, waiting while the queue is full (only link events can fill it) unless `stop`
/// is set; `false` when the loop is gone or stopping.
fn send_until_stopped(
    events: &SyncSender<LidarEvent>,
    mut ev: LidarEvent,
    stop: &AtomicBool,
) -> bool {
    loop {
        match events.try_send(ev) {
            Ok(()) => return true,
            Err(TrySendError::Disconnected(_)) => return false,
            Err(TrySendError::Full(back)) => {
                if stop.load(Ordering::Acquire) {
                    return false;
                }
                ev = back;
                std::thread::sleep(Duration::from_millis(10));
            }
        }
    }
}

/// One poll of the pose devices.
#[derive(Debug, Clone, Copy)]
pub struct DeviceSample {
    /// When it was taken.
    pub host: Instant,
    /// Wheel positions (left, right), ticks, if the OpenCR answered.
    pub ticks: Option<(i32, i32)>,
    /// Magnetometer, µT, robot frame, if the compass answered.
    pub mag_ut: Option<[f32; 3]>,
}

#[derive(Debug, Default)]
struct DeviceShared {
    stop: AtomicBool,
    encoder_errors: AtomicU64,
    compass_errors: AtomicU64,
    dropped: AtomicU64,
}

/// The loop's end of the pose-device thread.
pub struct DeviceReader {
    samples: Receiver<DeviceSample>,
    shared: Arc<DeviceShared>,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for DeviceReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DeviceReader").finish()
    }
}

impl DeviceReader {
    /// Starts polling the OpenCR and/or the compass at [`DEVICE_POLL_HZ`].
    pub fn start(
        opencr: Option<OpencrReader>,
        compass: Option<CompassReader>,
    ) -> Result<DeviceReader, String> {
        let shared = Arc::new(DeviceShared::default());
        let (tx, samples) = sync_channel(DEVICE_QUEUE);
        let sh = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("umbra-devices".into())
            .spawn(move || device_thread(opencr, compass, &tx, &sh))
            .map_err(|e| format!("cannot start the device reader thread: {e}"))?;
        Ok(DeviceReader {
            samples,
            shared,
            thread: Some(thread),
        })
    }

    /// The next waiting sample, if any (never blocks).
    pub fn try_next(&self) -> Option<DeviceSample> {
        self.samples.try_recv().ok()
    }

    /// OpenCR polls that failed.
    pub fn encoder_errors(&self) -> u64 {
        self.shared.encoder_errors.load(Ordering::Acquire)
    }

    /// Compass reads that failed.
    pub fn compass_errors(&self) -> u64 {
        self.shared.compass_errors.load(Ordering::Acquire)
    }

    /// Samples dropped because the queue was full (the loop was stalled).
    pub fn dropped(&self) -> u64 {
        self.shared.dropped.load(Ordering::Acquire)
    }
}

impl Drop for DeviceReader {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn device_thread(
    mut opencr: Option<OpencrReader>,
    mut compass: Option<CompassReader>,
    tx: &SyncSender<DeviceSample>,
    shared: &DeviceShared,
) {
    let period = Duration::from_secs_f64(1.0 / DEVICE_POLL_HZ);
    let mut next = Instant::now();
    while !shared.stop.load(Ordering::Acquire) {
        let ticks = opencr.as_mut().and_then(|b| match b.poll() {
            Ok(t) => Some(t),
            Err(e) => {
                if shared.encoder_errors.fetch_add(1, Ordering::AcqRel) == 0 {
                    log::warn!("{e}; pose continues from the last good ticks");
                }
                None
            }
        });
        let mag_ut = compass.as_mut().and_then(|read| match read() {
            Ok(m) => Some(m),
            Err(e) => {
                if shared.compass_errors.fetch_add(1, Ordering::AcqRel) == 0 {
                    log::warn!("{e}; heading continues on odometry");
                }
                None
            }
        });
        if ticks.is_some() || mag_ut.is_some() {
            let s = DeviceSample {
                host: Instant::now(),
                ticks,
                mag_ut,
            };
            if tx.try_send(s).is_err() {
                shared.dropped.fetch_add(1, Ordering::AcqRel);
            }
        }
        next += period;
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        } else {
            next = now; // a slow poll: do not try to catch up in a burst
        }
    }
}

/// Revolutions the clock map remembers.
pub const CLOCK_WINDOW: usize = 16;

/// Host monotonic time → the LiDAR's sensor clock. Each revolution the loop finishes gives one
/// pair (when its last bytes were read on the host, the sensor time they end at); the bytes
/// arrive some latency after the sensor sent them, never before, so the smallest
/// `host − sensor` of the last [`CLOCK_WINDOW`] revolutions is the offset (a windowed minimum
/// also follows a slow drift between the two clocks).
#[derive(Debug, Clone)]
pub struct ClockMap {
    offsets: [f64; CLOCK_WINDOW],
    n: usize,
    next: usize,
}

impl Default for ClockMap {
    fn default() -> Self {
        ClockMap {
            offsets: [0.0; CLOCK_WINDOW],
            n: 0,
            next: 0,
        }
    }
}

impl ClockMap {
    /// Records that sensor time `sensor_s` was read on the host at `host_s`.
    pub fn observe(&mut self, host_s: f64, sensor_s: f64) {
        self.offsets[self.next] = host_s - sensor_s;
        self.next = (self.next + 1) % CLOCK_WINDOW;
        self.n = (self.n + 1).min(CLOCK_WINDOW);
    }

    /// The sensor time of host time `host_s` (`None` before the first revolution).
    pub fn sensor_time(&self, host_s: f64) -> Option<f64> {
        let offset = self.offsets[..self.n]
            .iter()
            .copied()
            .fold(None, |m: Option<f64>, o| Some(m.map_or(o, |m| m.min(o))))?;
        Some(host_s - offset)
    }

    /// Forgets every pair (the sensor clock restarted, e.g. after a replug).
    pub fn reset(&mut self) {
        self.n = 0;
        self.next = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clock_map_takes_the_least_latency_and_forgets_old_pairs() {
        let mut m = ClockMap::default();
        assert_eq!(m.sensor_time(1.0), None);
        // Sensor clock started 2 s after the host's; reads arrive 5–30 ms late.
        m.observe(2.2 + 0.030, 0.2);
        m.observe(2.4 + 0.005, 0.4);
        m.observe(2.6 + 0.020, 0.6);
        let t = m.sensor_time(3.0).unwrap();
        assert!((t - (1.0 - 0.005)).abs() < 1e-9, "{t}");
        // After a window of later pairs, the early 5 ms one is gone.
        for k in 0..CLOCK_WINDOW {
            let s = 1.0 + k as f64 * 0.2;
            m.observe(2.0 + s + 0.010, s);
        }
        let t = m.sensor_time(5.0).unwrap();
        assert!((t - (3.0 - 0.010)).abs() < 1e-9, "{t}");
        m.reset();
        assert_eq!(m.sensor_time(5.0), None);
    }
}
