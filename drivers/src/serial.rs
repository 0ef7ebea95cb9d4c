//! Serial transport (std): a port opened with `serialport` and exposed as `embedded-io`
//! through `embedded-io-adapters`, plus [`SerialLink`], which survives unplugging.
//!
//! [`SerialLink`] opens the device (8N1, no flow control, exclusive), writes the sensor's start
//! byte (`b` for the LDS-01), and on drop writes its stop byte (`e`). End of file, a hang-up
//! (USB unplug, the far end of a pseudo-terminal closed) or a read error closes the port,
//! is counted and reported once as [`LinkRead::Lost`], and the link then reopens the same path
//! with exponential back-off ([`SerialConfig::backoff_min`] doubling up to
//! [`SerialConfig::backoff_max`]); success is reported as [`LinkRead::Reopened`]. Opening by a
//! stable path such as `/dev/serial/by-id/…` lets a replugged adapter come back. Nothing here
//! panics on I/O.
//!
//! Reopening allocates (the port object); the steady-state read path does not.

use std::fmt;
use std::time::{Duration, Instant};

use std::io::ErrorKind;

use embedded_io::{Read as _, Write as _};
use embedded_io_adapters::std::FromStd;

/// An open port as an `embedded-io` reader/writer.
pub type Port = FromStd<Box<dyn serialport::SerialPort>>;

/// Link settings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SerialConfig {
    /// Baud rate (8N1, no flow control).
    pub baud: u32,
    /// Longest a read waits for bytes before reporting [`LinkRead::Idle`].
    pub read_timeout: Duration,
    /// First wait before reopening a lost port.
    pub backoff_min: Duration,
    /// Longest wait between reopen attempts.
    pub backoff_max: Duration,
    /// Bytes written after every open (the LDS-01's motor start `b`).
    pub on_open: &'static [u8],
    /// Bytes written before closing (the LDS-01's motor stop `e`).
    pub on_close: &'static [u8],
    /// RPLIDAR: run [`crate::rplidar::motor::start`] after every open (DTR released, SCAN)
    /// and [`crate::rplidar::motor::stop`] before closing (STOP, 100 ms, DTR asserted).
    pub rplidar_motor: bool,
}

impl SerialConfig {
    /// The OpenCR board (DYNAMIXEL 2.0 over USB serial): 1 Mbps, nothing sent on open/close,
    /// short read timeout (the board answers within a few milliseconds).
    pub fn opencr() -> Self {
        SerialConfig {
            baud: 1_000_000,
            read_timeout: Duration::from_millis(5),
            backoff_min: Duration::from_millis(100),
            backoff_max: Duration::from_secs(2),
            on_open: &[],
            on_close: &[],
            rplidar_motor: false,
        }
    }

    /// The LDS-01: 230400 8N1, `b` on open, `e` on close.
    pub fn lds01() -> Self {
        SerialConfig {
            baud: crate::lds01::link::BAUD,
            read_timeout: Duration::from_millis(50),
            backoff_min: Duration::from_millis(100),
            backoff_max: Duration::from_secs(2),
            on_open: &[crate::lds01::link::START_MOTOR],
            on_close: &[crate::lds01::link::STOP_MOTOR],
            rplidar_motor: false,
        }
    }

    /// Any LiDAR model at its native baud rate: the LDS-01's start/stop bytes, nothing for
    /// the LDROBOT models (TX only), the DTR + SCAN / STOP sequences for the RPLIDAR.
    pub fn lidar(model: crate::lidar::LidarModel) -> Self {
        use crate::lidar::Family;
        let base = SerialConfig {
            baud: model.baud(),
            ..SerialConfig::lds01()
        };
        match model.family() {
            Family::Lds01 => base,
            Family::Ldrobot => SerialConfig {
                on_open: &[],
                on_close: &[],
                ..base
            },
            Family::Rplidar => SerialConfig {
                on_open: &[],
                on_close: &[],
                rplidar_motor: true,
                ..base
            },
        }
    }
}

/// [`crate::rplidar::motor::MotorLink`] over an open port. DTR cannot be set on every device
/// (a pseudo-terminal refuses it): such a failure is logged, not fatal, since the bytes still
/// go out.
struct PortMotor<'a>(&'a mut Port);

impl crate::rplidar::motor::MotorLink for PortMotor<'_> {
    type Error = ErrorKind;
    fn set_dtr(&mut self, asserted: bool) -> Result<(), ErrorKind> {
        if let Err(e) = self.0.inner_mut().write_data_terminal_ready(asserted) {
            log::debug!("cannot set DTR ({e}): motor line left as it is");
        }
        Ok(())
    }
    fn write_all(&mut self, bytes: &[u8]) -> Result<(), ErrorKind> {
        write_all(self.0, bytes)
    }
    fn delay_ms(&mut self, ms: u32) {
        std::thread::sleep(Duration::from_millis(u64::from(ms)));
    }
}

/// Sends what a device needs after an open.
pub(crate) fn run_on_open(port: &mut Port, cfg: &SerialConfig) -> Result<(), ErrorKind> {
    write_all(port, cfg.on_open)?;
    if cfg.rplidar_motor {
        crate::rplidar::motor::start(&mut PortMotor(port), None)?;
    }
    Ok(())
}

/// A link failure, naming the device.
#[derive(Debug)]
pub enum LinkError {
    /// The device could not be opened.
    Open {
        /// Device path.
        path: String,
        /// Why.
        source: serialport::Error,
    },
    /// A read or write failed.
    Io {
        /// Device path.
        path: String,
        /// The error kind.
        kind: ErrorKind,
    },
    /// The device reported end of file (hang-up).
    Eof {
        /// Device path.
        path: String,
    },
    /// The port is closed, waiting to be reopened.
    NotConnected {
        /// Device path.
        path: String,
    },
}

impl fmt::Display for LinkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LinkError::Open { path, source } => {
                write!(f, "cannot open serial port {path}: {source}")
            }
            LinkError::Io { path, kind } => write!(f, "serial port {path}: I/O error ({kind:?})"),
            LinkError::Eof { path } => write!(f, "serial port {path}: end of file (hang-up)"),
            LinkError::NotConnected { path } => {
                write!(f, "serial port {path}: not connected (reopening)")
            }
        }
    }
}

impl std::error::Error for LinkError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            LinkError::Open { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// What one [`SerialLink::read`] gave.
#[derive(Debug)]
pub enum LinkRead {
    /// This many bytes were read into the buffer.
    Data(usize),
    /// Nothing arrived within the read timeout (or the link is waiting to reopen).
    Idle,
    /// The port was lost; it will be reopened with back-off.
    Lost(LinkError),
    /// The port was reopened after a loss; bytes of a packet cut by the loss are gone.
    Reopened,
}

/// Link counters, cumulative.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Bytes read.
    pub bytes: u64,
    /// Read or write errors that closed the port.
    pub read_errors: u64,
    /// End-of-file / hang-up events.
    pub eofs: u64,
    /// Successful reopens.
    pub reopens: u64,
    /// Reopen attempts that failed.
    pub failed_reopens: u64,
}

/// Opens `path` at `cfg.baud`, 8N1, no flow control.
pub fn open_port(path: &str, cfg: &SerialConfig) -> Result<Port, LinkError> {
    serialport::new(path, cfg.baud)
        .data_bits(serialport::DataBits::Eight)
        .parity(serialport::Parity::None)
        .stop_bits(serialport::StopBits::One)
        .flow_control(serialport::FlowControl::None)
        .timeout(cfg.read_timeout)
        .open()
        .map(FromStd::new)
        .map_err(|source| LinkError::Open {
            path: path.to_owned(),
            source,
        })
}

/// A serial port that reopens itself; see the module docs.
pub struct SerialLink {
    path: String,
    cfg: SerialConfig,
    port: Option<Port>,
    backoff: Duration,
    next_try: Instant,
    stats: LinkStats,
}

impl fmt::Debug for SerialLink {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SerialLink")
            .field("path", &self.path)
            .field("connected", &self.port.is_some())
            .field("stats", &self.stats)
            .finish()
    }
}

impl SerialLink {
    /// Opens the port and sends the start bytes. A device that cannot be opened at start-up is
    /// an error (the user named it); losses after that are survived.
    pub fn open(path: &str, cfg: SerialConfig) -> Result<Self, LinkError> {
        let mut port = open_port(path, &cfg)?;
        run_on_open(&mut port, &cfg).map_err(|kind| LinkError::Io {
            path: path.to_owned(),
            kind,
        })?;
        Ok(SerialLink {
            path: path.to_owned(),
            backoff: cfg.backoff_min,
            cfg,
            port: Some(port),
            next_try: Instant::now(),
            stats: LinkStats::default(),
        })
    }

    /// Wraps a port already open and started (by [`crate::probe::probe`]).
    pub fn from_open(path: &str, cfg: SerialConfig, port: Port) -> Self {
        SerialLink {
            path: path.to_owned(),
            backoff: cfg.backoff_min,
            cfg,
            port: Some(port),
            next_try: Instant::now(),
            stats: LinkStats::default(),
        }
    }

    /// Device path.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// `true` while the port is open.
    pub fn is_connected(&self) -> bool {
        self.port.is_some()
    }

    /// Bytes the port has received that nobody has read yet (`None` while closed or when the
    /// driver cannot tell): how far a reader lags behind the device.
    pub fn backlog_bytes(&self) -> Option<u32> {
        self.port.as_ref()?.inner().bytes_to_read().ok()
    }

    /// Counters.
    pub fn stats(&self) -> &LinkStats {
        &self.stats
    }

    /// Reads what is available into `buf`, waiting at most the read timeout. Never panics;
    /// see [`LinkRead`].
    pub fn read(&mut self, buf: &mut [u8]) -> LinkRead {
        let Some(port) = self.port.as_mut() else {
            return self.try_reopen();
        };
        match port.read(buf) {
            Ok(0) => {
                self.stats.eofs += 1;
                self.lose();
                LinkRead::Lost(LinkError::Eof {
                    path: self.path.clone(),
                })
            }
            Ok(n) => {
                self.stats.bytes += n as u64;
                LinkRead::Data(n)
            }
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::Interrupted) => {
                LinkRead::Idle
            }
            Err(e) => {
                self.stats.read_errors += 1;
                self.lose();
                LinkRead::Lost(LinkError::Io {
                    path: self.path.clone(),
                    kind: e.kind(),
                })
            }
        }
    }

    /// Writes all of `bytes`. A failure closes the port; a closed port is reopened (with
    /// back-off) by the next `write` or `read`.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        if self.port.is_none() {
            // A request-response device is only ever written to: reopen from here too.
            let _ = self.try_reopen();
        }
        let Some(port) = self.port.as_mut() else {
            return Err(LinkError::NotConnected {
                path: self.path.clone(),
            });
        };
        match write_all(port, bytes) {
            Ok(()) => Ok(()),
            Err(kind) => {
                self.stats.read_errors += 1;
                self.lose();
                Err(LinkError::Io {
                    path: self.path.clone(),
                    kind,
                })
            }
        }
    }

    fn lose(&mut self) {
        self.port = None;
        self.backoff = self.cfg.backoff_min;
        self.next_try = Instant::now() + self.backoff;
    }

    fn try_reopen(&mut self) -> LinkRead {
        let now = Instant::now();
        if now < self.next_try {
            std::thread::sleep((self.next_try - now).min(self.cfg.read_timeout));
            return LinkRead::Idle;
        }
        match open_port(&self.path, &self.cfg) {
            Ok(mut port) => {
                if run_on_open(&mut port, &self.cfg).is_err() {
                    self.stats.failed_reopens += 1;
                    self.schedule_retry();
                    return LinkRead::Idle;
                }
                self.port = Some(port);
                self.stats.reopens += 1;
                self.backoff = self.cfg.backoff_min;
                LinkRead::Reopened
            }
            Err(_) => {
                self.stats.failed_reopens += 1;
                self.schedule_retry();
                LinkRead::Idle
            }
        }
    }

    fn schedule_retry(&mut self) {
        self.next_try = Instant::now() + self.backoff;
        self.backoff = (self.backoff * 2).min(self.cfg.backoff_max);
    }
}

/// Sends what a device needs before a close.
pub(crate) fn run_on_close(port: &mut Port, cfg: &SerialConfig) -> Result<(), ErrorKind> {
    write_all(port, cfg.on_close)?;
    if cfg.rplidar_motor {
        crate::rplidar::motor::stop(&mut PortMotor(port), false)?;
    }
    Ok(())
}

impl Drop for SerialLink {
    fn drop(&mut self) {
        if let Some(port) = self.port.as_mut() {
            // Best effort: the device may already be gone.
            let _ = run_on_close(port, &self.cfg);
        }
    }
}

fn write_all(port: &mut Port, bytes: &[u8]) -> Result<(), ErrorKind> {
    if bytes.is_empty() {
        return Ok(());
    }
    port.write_all(bytes).map_err(|e| e.kind())?;
    port.flush().map_err(|e| e.kind())
}
