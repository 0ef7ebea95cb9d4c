//! Slamtec RPLIDAR A1/A2 in standard SCAN mode (`docs/hardware.md` §1c).
//!
//! | module        | owns                                                            |
//! |---------------|-----------------------------------------------------------------|
//! | [`protocol`]  | requests, descriptor, 5-byte node, GET_INFO / GET_HEALTH replies |
//! | [`decoder`]   | bytes in any chunking → items; one-byte slide resync            |
//! | [`motor`]     | start/stop sequences: DTR (A1, A2 without board) or PWM, STOP delay |
//! | this module   | [`RplidarStream`]: nodes → REP 103 points, sensor clock, revolutions |
//!
//! ## Direction and sweep
//!
//! Raw angles run clockwise; the vendor's ROS driver publishes raw θ at `π − θ`, so ours is
//! `(180 − θ)°`. A revolution starts at a node with the S flag, or where the raw angle wraps
//! when that node was lost; either only once at least 270° have been swept since the last
//! start, so a lost or repeated flag cannot cut a revolution into pieces.
//!
//! ## Sensor clock (`docs/interfaces.md` §2)
//!
//! Nodes carry no time: t = 0 at the first node and each node advances t by one sample period
//! of the model (A1 2 kHz, A2 4 kHz in SCAN mode).

pub mod decoder;
pub mod motor;
pub mod protocol;

pub use decoder::{Decoded, Decoder, DecoderStats};
pub use protocol::{Descriptor, NODE_LEN, Node, SCAN_DESCRIPTOR};

use crate::lidar::points::{Point, PointAssembler, PointConfig};
use crate::lidar::{LidarFaults, LidarModel, Revolution, RevolutionStream};

/// RPLIDAR stream settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RplidarConfig {
    /// A1 or A2 (another model is treated as the A1).
    pub model: LidarModel,
    /// Range window and staleness.
    pub points: PointConfig,
}

/// Counters beyond the decoder's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RplidarStats {
    /// GET_HEALTH replies with status error (2).
    pub health_errors: u64,
    /// S flags ignored because less than 270° had been swept.
    pub early_start_flags: u64,
    /// Revolutions started by an angle wrap because the S-flag node was lost.
    pub wrap_starts: u64,
}

/// Decoder + point assembler for an RPLIDAR; see the module docs.
#[derive(Debug, Clone)]
pub struct RplidarStream {
    model: LidarModel,
    decoder: Decoder,
    points: PointAssembler,
    stats: RplidarStats,
    /// Nodes seen (the clock).
    nodes: u64,
    last_raw_deg: Option<f32>,
    /// Degrees swept clockwise since the last revolution start.
    swept_deg: f32,
    scanning: bool,
}

/// Degrees that must be swept before a new revolution may start.
pub const MIN_SWEEP_DEG: f32 = 270.0;

impl RplidarStream {
    /// A new stream.
    pub fn new(cfg: RplidarConfig) -> Self {
        let model = match cfg.model {
            m @ (LidarModel::RplidarA1 | LidarModel::RplidarA2) => m,
            _ => LidarModel::RplidarA1,
        };
        RplidarStream {
            model,
            decoder: Decoder::new(),
            points: PointAssembler::new(cfg.points),
            stats: RplidarStats::default(),
            nodes: 0,
            last_raw_deg: None,
            swept_deg: 0.0,
            scanning: false,
        }
    }

    /// The decoder (its counters).
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// Stream counters.
    pub fn stats(&self) -> &RplidarStats {
        &self.stats
    }

    /// `true` once a SCAN descriptor was seen.
    pub fn scan_confirmed(&self) -> bool {
        self.scanning
    }

    fn sample_s(&self) -> f64 {
        1.0 / f64::from(self.model.sample_rate_hz())
    }

    fn nominal_period_s(&self) -> f32 {
        // Without a speed field, assume the nominal 5.5 Hz of SCAN mode until a full sweep is
        // timed (only used when a revolution is cut short).
        self.points.last().map_or(1.0 / 5.5, |r| r.period_s)
    }

    fn push_node(&mut self, n: &Node, host_us: Option<u64>) -> bool {
        let raw = n.angle_deg();
        let wrapped = self.last_raw_deg.is_some_and(|last| raw < last - 180.0);
        if let Some(last) = self.last_raw_deg {
            let step = (raw - last + 360.0) % 360.0;
            if step < 180.0 {
                self.swept_deg += step;
            }
        }
        self.last_raw_deg = Some(raw);
        let t_s = self.nodes as f64 * self.sample_s();
        self.nodes += 1;
        let ready = self.swept_deg >= MIN_SWEEP_DEG;
        let new_sweep = (n.start || wrapped) && ready;
        if n.start && !ready && self.nodes > 1 {
            self.stats.early_start_flags += 1;
        }
        if new_sweep {
            if !n.start {
                self.stats.wrap_starts += 1;
            }
            self.swept_deg = 0.0;
        }
        let p = Point {
            angle_deg: 180.0 - raw,
            sweep_deg: 180.0 - raw,
            range_m: n.distance_m(),
            intensity: u16::from(n.quality) << 2,
            t_s,
        };
        let period = self.nominal_period_s();
        self.points.push(&p, new_sweep, period, host_us)
    }
}

impl RevolutionStream for RplidarStream {
    fn model(&self) -> Option<LidarModel> {
        Some(self.model)
    }

    fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool {
        while let Some(item) = self.decoder.next_item(input) {
            match item {
                Decoded::Node(n) => {
                    if self.push_node(&n, host_us) {
                        return true;
                    }
                }
                Decoded::Descriptor(d) => {
                    if d == SCAN_DESCRIPTOR {
                        self.scanning = true;
                    }
                }
                Decoded::Health(h) => {
                    if h.status >= 2 {
                        self.stats.health_errors += 1;
                    }
                }
                Decoded::Info(_) => {}
            }
        }
        false
    }

    fn last_revolution(&self) -> Option<&Revolution> {
        self.points.last()
    }

    fn poll(&mut self, now_us: u64) -> Option<&Revolution> {
        let period = self.nominal_period_s();
        self.points.poll(now_us, period)
    }

    fn finish(&mut self) -> Option<&Revolution> {
        self.decoder.reset();
        let period = self.nominal_period_s();
        self.points.flush(period)
    }

    fn link_reset(&mut self) {
        self.decoder.reset();
    }

    fn sensor_time_s(&self) -> f64 {
        self.points.sensor_time_s()
    }

    fn faults(&self) -> LidarFaults {
        let d = self.decoder.stats();
        let p = self.points.stats();
        LidarFaults {
            bytes_skipped: d.bytes_skipped,
            bad_index: d.bad_angle,
            missing_packets: p.missing_sectors,
            incomplete_revolutions: p.incomplete_revolutions,
            partial_revolutions_dropped: p.partial_dropped,
            sensor_errors: self.stats.health_errors,
            ..LidarFaults::default()
        }
    }
}
