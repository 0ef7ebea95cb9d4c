//! Power: where the watts come from, and the 10 W budget check.
//!
//! Sources, best first (`[power] source = "auto"` tries them in this order):
//! 1. an **INA219** supply-side monitor on I²C (`ina219` crate, embedded-hal 1.0): bus voltage
//!    × shunt voltage / shunt resistance, read on its own thread every [`SAMPLE_PERIOD`];
//! 2. the **Pi 5 PMIC** (`vcgencmd pmic_read_adc`): rail V·I summed, watts ≈ 1.1451 × Σ + 0.5879
//!    (`docs/hardware.md`), on its own thread every [`SAMPLE_PERIOD`];
//! 3. a **model** from this process's CPU time: idle + (full − idle) × load + the LiDAR, with the
//!    board's measured idle and all-cores figures (`docs/hardware.md`). On a host that is not a Pi the
//!    CPU time is scaled by how much slower the modelled board is ([`Board::slowdown`]).
//!
//! The frame loop only reads the latest figure ([`PowerMeter::watts`]): no allocation, no I/O
//! on the frame's path except the model's read of `/proc/self/stat` into a stack buffer (once
//! every [`SAMPLE_PERIOD`]).

use std::io::Read as _;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serde::Deserialize;

/// How often the threaded sources sample, and the model's window.
pub const SAMPLE_PERIOD: Duration = Duration::from_millis(500);

/// Which source to use (`[power] source`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SourceChoice {
    /// The best one that answers.
    #[default]
    Auto,
    /// An INA219 (fails at start-up if none answers).
    Ina219,
    /// The Pi 5 PMIC (fails at start-up if `vcgencmd pmic_read_adc` gives no rails).
    Pmic,
    /// The CPU-time model.
    Model,
}

/// A board of the model (`[power] board`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Board {
    /// From `/proc/device-tree/model`; a host that is no Pi is modelled as a Pi 5.
    #[default]
    Auto,
    /// Raspberry Pi 5.
    Pi5,
    /// Raspberry Pi 3 B+.
    #[serde(rename = "pi3b+")]
    Pi3bPlus,
    /// Raspberry Pi 3 B.
    Pi3b,
}

impl Board {
    /// Idle and all-cores-stressed watts at the wall (`docs/hardware.md`).
    pub fn watts(self) -> (f64, f64) {
        match self {
            Board::Pi5 | Board::Auto => (2.8, 9.7),
            Board::Pi3bPlus => (3.1, 5.6),
            Board::Pi3b => (1.4, 3.7),
        }
    }

    /// How many times slower one core of the board is than a current desktop core
    /// (`docs/hardware.md`: Pi 5 ≈ 3.7×, a Pi 3 ≈ 13× slower than a Pi 5 on CNN work).
    pub fn slowdown(self) -> f64 {
        match self {
            Board::Pi5 | Board::Auto => 3.7,
            Board::Pi3bPlus | Board::Pi3b => 3.7 * 13.0,
        }
    }

    /// Cores (all four boards have four).
    pub fn cores(self) -> f64 {
        4.0
    }

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Board::Pi5 | Board::Auto => "Pi 5",
            Board::Pi3bPlus => "Pi 3 B+",
            Board::Pi3b => "Pi 3 B",
        }
    }

    /// The board this runs on: the configured one, else the one `device_tree` (the contents
    /// of `/proc/device-tree/model`, [`device_tree_model`]) names (`None`: not a Pi we know).
    pub fn this(cfg: Board, device_tree: Option<&str>) -> Option<Board> {
        match cfg {
            Board::Auto => device_tree.and_then(Board::from_device_tree),
            b => Some(b),
        }
    }

    /// The board named by a device-tree model string (`None`: not a Pi we know).
    pub fn from_device_tree(model: &str) -> Option<Board> {
        let m = model.trim_end_matches('\0');
        if m.contains("Raspberry Pi 5") {
            Some(Board::Pi5)
        } else if m.contains("Raspberry Pi 3 Model B Plus") {
            Some(Board::Pi3bPlus)
        } else if m.contains("Raspberry Pi 3") {
            Some(Board::Pi3b)
        } else {
            None
        }
    }
}

/// `[power]` settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PowerSettings {
    /// The budget, W.
    pub budget_w: f64,
    /// Which source.
    pub source: SourceChoice,
    /// The board of the model.
    pub board: Board,
    /// What the LiDAR adds in the model, W (the LDS-01 draws up to 2 W).
    pub lidar_w: f64,
    /// I²C bus of the INA219.
    pub ina219_bus: String,
    /// Its 7-bit address.
    pub ina219_address: u8,
    /// Its shunt, ohms.
    pub shunt_ohm: f64,
}

impl Default for PowerSettings {
    fn default() -> Self {
        PowerSettings {
            budget_w: 10.0,
            source: SourceChoice::Auto,
            board: Board::Auto,
            lidar_w: 2.0,
            ina219_bus: "/dev/i2c-1".into(),
            ina219_address: 0x40,
            shunt_ohm: 0.1,
        }
    }
}

impl PowerSettings {
    /// Checks the values; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        let pos = |name: &str, v: f64, hi: f64| {
            if v.is_finite() && v > 0.0 && v <= hi {
                Ok(())
            } else {
                Err(format!("power.{name} = {v}: must be within (0, {hi}]"))
            }
        };
        pos("budget_w", self.budget_w, 1000.0)?;
        pos("shunt_ohm", self.shunt_ohm, 100.0)?;
        if !(self.lidar_w.is_finite() && (0.0..=50.0).contains(&self.lidar_w)) {
            return Err(format!(
                "power.lidar_w = {}: must be within [0, 50]",
                self.lidar_w
            ));
        }
        if !(0x40..=0x4F).contains(&self.ina219_address) {
            return Err(format!(
                "power.ina219_address = {:#x}: an INA219 answers at 0x40..=0x4f",
                self.ina219_address
            ));
        }
        Ok(())
    }
}

/// Sums a `vcgencmd pmic_read_adc` listing into watts: each rail's `NAME_A current(k)=xA`
/// times its `NAME_V volt(k)=yV`, then the public fit 1.1451 × Σ + 0.5879. `None` when no rail
/// has both.
pub fn pmic_watts(text: &str) -> Option<f64> {
    let value = |line: &str, unit: char| -> Option<(String, f64)> {
        let line = line.trim();
        let (name, rest) = line.split_once(' ')?;
        let v = rest.split_once('=')?.1.trim().strip_suffix(unit)?;
        Some((name.to_owned(), v.parse().ok()?))
    };
    let mut currents = Vec::new();
    let mut volts = Vec::new();
    for line in text.lines() {
        if let Some((n, a)) = value(line, 'A')
            && let Some(rail) = n.strip_suffix("_A")
        {
            currents.push((rail.to_owned(), a));
        } else if let Some((n, v)) = value(line, 'V')
            && let Some(rail) = n.strip_suffix("_V")
        {
            volts.push((rail.to_owned(), v));
        }
    }
    let mut sum = 0.0;
    let mut rails = 0;
    for (rail, a) in &currents {
        if let Some((_, v)) = volts.iter().find(|(r, _)| r == rail) {
            sum += a * v;
            rails += 1;
        }
    }
    (rails > 0).then_some(1.1451 * sum + 0.5879)
}

/// This process's CPU time (user + system, all threads), seconds, from `/proc/self/stat`
/// (clock ticks of 1/100 s), read into a stack buffer: no allocation.
pub fn process_cpu_s() -> Option<f64> {
    let mut buf = [0u8; 1024];
    let mut f = std::fs::File::open("/proc/self/stat").ok()?;
    let mut n = 0;
    while n < buf.len() {
        match f.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(_) => return None,
        }
    }
    parse_stat_cpu_s(&buf[..n])
}

/// utime + stime of a `/proc/PID/stat` line, seconds (fields 14 and 15, after the command
/// name in parentheses, which may hold spaces).
pub fn parse_stat_cpu_s(stat: &[u8]) -> Option<f64> {
    let close = stat.iter().rposition(|&b| b == b')')?;
    let rest = core::str::from_utf8(&stat[close + 1..]).ok()?;
    // After ")": field 3 (state) is the first; utime is field 14, stime 15.
    let mut it = rest.split_ascii_whitespace().skip(11);
    let utime: u64 = it.next()?.parse().ok()?;
    let stime: u64 = it.next()?.parse().ok()?;
    Some((utime + stime) as f64 / 100.0)
}

/// The CPU-time model's state.
#[derive(Debug, Clone)]
struct Model {
    board: Board,
    /// The host is the modelled board (else CPU time is scaled by its slowdown).
    native: bool,
    lidar_w: f64,
    last: Option<(Instant, f64)>,
    watts: Option<f64>,
}

impl Model {
    fn sample(&mut self) -> Option<f64> {
        let now = Instant::now();
        let cpu = process_cpu_s()?;
        match self.last {
            None => self.last = Some((now, cpu)),
            Some((t0, c0)) => {
                let wall = now.duration_since(t0).as_secs_f64();
                if wall >= SAMPLE_PERIOD.as_secs_f64() {
                    let scale = if self.native {
                        1.0
                    } else {
                        self.board.slowdown()
                    };
                    self.watts = Some(model_watts(
                        self.board,
                        (cpu - c0) * scale,
                        wall,
                        self.lidar_w,
                    ));
                    self.last = Some((now, cpu));
                }
            }
        }
        self.watts
    }
}

/// The model: the board's idle watts, plus its (full − idle) span times the share of its
/// cores that `cpu_s` of work keeps busy over `wall_s` (at most all), plus the LiDAR.
pub fn model_watts(board: Board, cpu_s: f64, wall_s: f64, lidar_w: f64) -> f64 {
    let (idle, full) = board.watts();
    let load = if wall_s > 0.0 {
        (cpu_s / (wall_s * board.cores())).clamp(0.0, 1.0)
    } else {
        0.0
    };
    idle + (full - idle) * load + lidar_w
}

enum Kind {
    /// A sampling thread writes the latest watts (f64 bits; NaN = none yet).
    Threaded {
        latest: Arc<AtomicU64>,
        stop: Arc<AtomicBool>,
        thread: Option<JoinHandle<()>>,
    },
    Model(Model),
}

/// The run's power source.
pub struct PowerMeter {
    kind: Kind,
    source: String,
}

impl std::fmt::Debug for PowerMeter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PowerMeter")
            .field("source", &self.source)
            .finish()
    }
}

impl PowerMeter {
    /// Picks the source as configured; an explicitly named one that does not answer is an
    /// error naming it.
    pub fn start(cfg: &PowerSettings) -> Result<PowerMeter, String> {
        if matches!(cfg.source, SourceChoice::Auto | SourceChoice::Ina219) {
            match ina219_reader(cfg) {
                Ok(read) => {
                    let source =
                        format!("INA219 at {:#x} on {}", cfg.ina219_address, cfg.ina219_bus);
                    return Ok(Self::threaded(source, read));
                }
                Err(e) if cfg.source == SourceChoice::Ina219 => {
                    return Err(format!("power.source = \"ina219\": {e}"));
                }
                Err(_) => {}
            }
        }
        if matches!(cfg.source, SourceChoice::Auto | SourceChoice::Pmic) {
            match read_pmic() {
                Ok(_) => {
                    return Ok(Self::threaded(
                        "Pi 5 PMIC (vcgencmd pmic_read_adc)".into(),
                        Box::new(read_pmic),
                    ));
                }
                Err(e) if cfg.source == SourceChoice::Pmic => {
                    return Err(format!("power.source = \"pmic\": {e}"));
                }
                Err(_) => {}
            }
        }
        Ok(Self::model(cfg, device_tree_model().as_deref()))
    }

    /// The CPU-time model for the configured board, or the one `device_tree` names.
    pub fn model(cfg: &PowerSettings, device_tree: Option<&str>) -> PowerMeter {
        let board = Board::this(cfg.board, device_tree).unwrap_or(Board::Pi5);
        let native = device_tree.and_then(Board::from_device_tree) == Some(board);
        let source = if native {
            format!("model ({} figures, this board's CPU time)", board.name())
        } else {
            format!(
                "model ({} figures; host is not a {0}: CPU time × {:.1})",
                board.name(),
                board.slowdown()
            )
        };
        let mut m = Model {
            board,
            native,
            lidar_w: cfg.lidar_w,
            last: None,
            watts: None,
        };
        m.sample();
        PowerMeter {
            kind: Kind::Model(m),
            source,
        }
    }

    fn threaded(source: String, mut read: Box<dyn FnMut() -> Result<f64, String> + Send>) -> Self {
        let latest = Arc::new(AtomicU64::new(f64::NAN.to_bits()));
        let stop = Arc::new(AtomicBool::new(false));
        let (l, s) = (latest.clone(), stop.clone());
        let thread = std::thread::Builder::new()
            .name("umbra-power".into())
            .spawn(move || {
                let mut errors = 0u64;
                while !s.load(Ordering::Relaxed) {
                    match read() {
                        Ok(w) => l.store(w.to_bits(), Ordering::Relaxed),
                        Err(e) => {
                            if errors == 0 {
                                log::warn!("power: {e}");
                            }
                            errors += 1;
                        }
                    }
                    std::thread::sleep(SAMPLE_PERIOD);
                }
            })
            .ok();
        PowerMeter {
            kind: Kind::Threaded {
                latest,
                stop,
                thread,
            },
            source,
        }
    }

    /// The latest figure, W (`None` until the first one).
    pub fn watts(&mut self) -> Option<f64> {
        match &mut self.kind {
            Kind::Threaded { latest, .. } => {
                let w = f64::from_bits(latest.load(Ordering::Relaxed));
                w.is_finite().then_some(w)
            }
            Kind::Model(m) => m.sample(),
        }
    }

    /// Where the watts come from.
    pub fn source(&self) -> &str {
        &self.source
    }
}

impl Drop for PowerMeter {
    fn drop(&mut self) {
        if let Kind::Threaded { stop, thread, .. } = &mut self.kind {
            stop.store(true, Ordering::Relaxed);
            if let Some(t) = thread.take() {
                let _ = t.join();
            }
        }
    }
}

/// The contents of `/proc/device-tree/model` (`None` off a board that has one).
pub fn device_tree_model() -> Option<String> {
    std::fs::read_to_string("/proc/device-tree/model").ok()
}

fn read_pmic() -> Result<f64, String> {
    let out = std::process::Command::new("vcgencmd")
        .arg("pmic_read_adc")
        .output()
        .map_err(|e| format!("vcgencmd: {e}"))?;
    if !out.status.success() {
        return Err(format!("vcgencmd pmic_read_adc: {}", out.status));
    }
    pmic_watts(&String::from_utf8_lossy(&out.stdout))
        .ok_or_else(|| "vcgencmd pmic_read_adc: no rail with both volts and amps".into())
}

type Reader = Box<dyn FnMut() -> Result<f64, String> + Send>;

fn ina219_reader(cfg: &PowerSettings) -> Result<Reader, String> {
    use ina219::SyncIna219;
    use ina219::address::Address;
    let bus = cfg.ina219_bus.clone();
    let i2c = linux_embedded_hal::I2cdev::new(&bus).map_err(|e| format!("{bus}: {e}"))?;
    let addr = Address::from_byte(cfg.ina219_address)
        .map_err(|_| format!("address {:#x} out of range", cfg.ina219_address))?;
    let mut ina = SyncIna219::new(i2c, addr)
        .map_err(|_| format!("no INA219 answers at {:#x} on {bus}", cfg.ina219_address))?;
    let shunt = cfg.shunt_ohm;
    let mut read = move || -> Result<f64, String> {
        let v = ina
            .bus_voltage()
            .map_err(|_| format!("INA219 on {bus}: bus voltage unreadable"))?;
        let s = ina
            .shunt_voltage()
            .map_err(|_| format!("INA219 on {bus}: shunt voltage unreadable"))?;
        Ok(ina219_watts(v.voltage_mv(), s.shunt_voltage_uv(), shunt))
    };
    read()?;
    Ok(Box::new(read))
}

/// Watts from an INA219's bus voltage (mV) and shunt voltage (µV) across `shunt_ohm`.
pub fn ina219_watts(bus_mv: u16, shunt_uv: i32, shunt_ohm: f64) -> f64 {
    f64::from(bus_mv) / 1e3 * (f64::from(shunt_uv) / 1e6 / shunt_ohm).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pmic_listing_is_summed_by_rail_and_fitted() {
        let text = "     3V7_WL_SW_A current(0)=0.10000000A\n\
                    3V3_SYS_A current(1)=0.20000000A\n\
                    VDD_CORE_A current(7)=1.4288A\n\
                    3V7_WL_SW_V volt(8)=3.70000000V\n\
                    3V3_SYS_V volt(9)=3.30000000V\n\
                    VDD_CORE_V volt(15)=0.9066V\n\
                    EXT5V_V volt(24)=5.12000000V\n\
                    BATT_V volt(25)=0.00000000V\n";
        let sum = 0.1 * 3.7 + 0.2 * 3.3 + 1.4288 * 0.9066;
        let w = pmic_watts(text).unwrap();
        assert!((w - (1.1451 * sum + 0.5879)).abs() < 1e-9, "{w}");
        assert_eq!(pmic_watts("vcgencmd: command not found"), None);
        assert_eq!(pmic_watts(""), None);
    }

    #[test]
    fn stat_line_gives_user_plus_system_time() {
        let line = b"4242 (umbra (x) y) R 1 2 3 4 5 6 7 8 9 10 150 50 0 0 20 0 1 0";
        assert_eq!(parse_stat_cpu_s(line), Some(2.0));
        assert_eq!(parse_stat_cpu_s(b"garbage"), None);
        assert!(process_cpu_s().is_some(), "this test runs on Linux");
    }

    #[test]
    fn model_spans_idle_to_full_load_plus_the_lidar() {
        assert_eq!(model_watts(Board::Pi5, 0.0, 1.0, 2.0), 4.8);
        assert!((model_watts(Board::Pi5, 4.0, 1.0, 0.0) - 9.7).abs() < 1e-12);
        assert!((model_watts(Board::Pi5, 1.0, 1.0, 0.0) - (2.8 + 6.9 / 4.0)).abs() < 1e-12);
        assert_eq!(model_watts(Board::Pi3b, 100.0, 1.0, 0.0), 3.7);
    }

    #[test]
    fn boards_come_from_the_device_tree() {
        assert_eq!(
            Board::from_device_tree("Raspberry Pi 5 Model B Rev 1.0\0"),
            Some(Board::Pi5)
        );
        assert_eq!(
            Board::from_device_tree("Raspberry Pi 3 Model B Plus Rev 1.3"),
            Some(Board::Pi3bPlus)
        );
        assert_eq!(
            Board::from_device_tree("Raspberry Pi 3 Model B Rev 1.2"),
            Some(Board::Pi3b)
        );
        assert_eq!(Board::from_device_tree("QEMU Virtual Machine"), None);
        let m = PowerMeter::model(&PowerSettings::default(), Some("QEMU"));
        assert!(m.source().contains("host is not a Pi 5"), "{}", m.source());
        let m = PowerMeter::model(&PowerSettings::default(), Some("Raspberry Pi 5 Model B"));
        assert_eq!(m.source(), "model (Pi 5 figures, this board's CPU time)");
    }

    #[test]
    fn ina219_watts_are_volts_times_amps() {
        // 5 V bus, 50 mV across 0.1 Ω = 0.5 A → 2.5 W.
        assert!((ina219_watts(5000, 50_000, 0.1) - 2.5).abs() < 1e-12);
    }

    #[test]
    fn bad_settings_name_the_field() {
        let s = PowerSettings {
            budget_w: 0.0,
            ..Default::default()
        };
        assert!(s.validate().unwrap_err().starts_with("power.budget_w"));
        let s = PowerSettings {
            ina219_address: 0x10,
            ..Default::default()
        };
        assert!(
            s.validate()
                .unwrap_err()
                .starts_with("power.ina219_address")
        );
    }
}
