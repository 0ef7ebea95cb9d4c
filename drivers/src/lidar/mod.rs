//! What every LiDAR model shares: the [`Revolution`] the pipeline consumes, the
//! [`RevolutionStream`] trait each model's byte decoder implements, the fault counters, the model
//! list with its link facts, and [`AnyLidar`], one stream for whichever model was found.
//!
//! | module          | owns                                                              |
//! |-----------------|-------------------------------------------------------------------|
//! | [`revolution`]  | 360 bins in REP 103 angles, sectors, time stamps (all models)     |
//! | [`points`]      | native-angle points → revolutions: binning, sweep, staleness      |
//! | [`detect`]      | which framing a byte stream speaks (auto-detection), with a diagnosis |
//! | this module     | [`LidarModel`], [`RevolutionStream`], [`LidarFaults`], [`AnyLidar`]     |
//!
//! A model's decoder turns bytes into revolutions of **360 bins, [0°, 360°), counter-clockwise,
//! stamped at the first ray on the sensor's own clock**, whatever the sensor's native beam
//! count, direction or time base: the three most common complaints against the vendors'
//! drivers (changing beam counts, mirrored scans, publish-time stamps; `docs/hardware.md` §1d) cannot
//! happen past this layer. Everything here is `no_std` and allocation-free.

pub mod detect;
pub mod points;
pub mod revolution;

use crate::ldrobot::{LdrobotConfig, LdrobotStream};
use crate::lds01::{Lds01Config, Lds01Stream};
use crate::rplidar::{RplidarConfig, RplidarStream};
pub use revolution::{BINS, Reading, Revolution, SECTORS};

/// The LiDAR models umbra reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LidarModel {
    /// ROBOTIS LDS-01 (HLS-LFCD2), TurtleBot3 until 2022: 42-byte `0xFA` packets, 230400 baud.
    Lds01,
    /// ROBOTIS LDS-02 = LDROBOT LD08, TurtleBot3 since 2022: `0x54 0x2C` frames, 115200 baud.
    Lds02,
    /// LDROBOT LD06: `0x54 0x2C` frames, 230400 baud.
    Ld06,
    /// LDROBOT LD19: `0x54 0x2C` frames, 230400 baud.
    Ld19,
    /// Slamtec RPLIDAR A1 (and A2M8): SCAN-mode 5-byte nodes, 115200 baud, motor on DTR.
    RplidarA1,
    /// Slamtec RPLIDAR A2M12 (hardware ≥ 6): 256000 baud.
    RplidarA2,
}

/// The wire family a model speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Family {
    /// 42-byte `0xFA` packets ([`crate::lds01`]).
    Lds01,
    /// 47-byte `0x54 0x2C` frames with CRC-8 ([`crate::ldrobot`]).
    Ldrobot,
    /// Response descriptor + 5-byte nodes after a SCAN request ([`crate::rplidar`]).
    Rplidar,
}

impl LidarModel {
    /// Every model, in the order auto-detection reports them.
    pub const ALL: [LidarModel; 6] = [
        LidarModel::Lds01,
        LidarModel::Lds02,
        LidarModel::Ld06,
        LidarModel::Ld19,
        LidarModel::RplidarA1,
        LidarModel::RplidarA2,
    ];

    /// The name `--lidar-model` takes.
    pub const fn cli_name(self) -> &'static str {
        match self {
            LidarModel::Lds01 => "lds01",
            LidarModel::Lds02 => "lds02",
            LidarModel::Ld06 => "ld06",
            LidarModel::Ld19 => "ld19",
            LidarModel::RplidarA1 => "rplidar-a1",
            LidarModel::RplidarA2 => "rplidar-a2",
        }
    }

    /// A name for people.
    pub const fn display_name(self) -> &'static str {
        match self {
            LidarModel::Lds01 => "LDS-01",
            LidarModel::Lds02 => "LDS-02 (LD08)",
            LidarModel::Ld06 => "LD06",
            LidarModel::Ld19 => "LD19",
            LidarModel::RplidarA1 => "RPLIDAR A1",
            LidarModel::RplidarA2 => "RPLIDAR A2",
        }
    }

    /// The wire family.
    pub const fn family(self) -> Family {
        match self {
            LidarModel::Lds01 => Family::Lds01,
            LidarModel::Lds02 | LidarModel::Ld06 | LidarModel::Ld19 => Family::Ldrobot,
            LidarModel::RplidarA1 | LidarModel::RplidarA2 => Family::Rplidar,
        }
    }

    /// Native baud rate, 8N1.
    pub const fn baud(self) -> u32 {
        match self {
            LidarModel::Lds01 | LidarModel::Ld06 | LidarModel::Ld19 => 230_400,
            LidarModel::Lds02 | LidarModel::RplidarA1 => 115_200,
            LidarModel::RplidarA2 => 256_000,
        }
    }

    /// Range samples per second (LDS-01: 360 × 5 Hz; LDROBOT: the vendor SDK's figure;
    /// RPLIDAR: the standard SCAN mode's, from Slamtec's datasheets).
    pub const fn sample_rate_hz(self) -> u32 {
        match self {
            LidarModel::Lds01 => 1800,
            LidarModel::Lds02 => 2300,
            LidarModel::Ld06 | LidarModel::Ld19 => 4500,
            LidarModel::RplidarA1 => 2000,
            LidarModel::RplidarA2 => 4000,
        }
    }

    /// The specified range window, metres (min, max).
    pub const fn range_window_m(self) -> (f32, f32) {
        match self {
            LidarModel::Lds01 => (0.12, 3.5),
            LidarModel::Lds02 => (0.16, 8.0),
            LidarModel::Ld06 | LidarModel::Ld19 => (0.02, 12.0),
            LidarModel::RplidarA1 | LidarModel::RplidarA2 => (0.15, 12.0),
        }
    }

    /// Nominal revolutions a second (LDS-01 300 rpm; LDS-02 "5 Hz or above", about 6; LD06 /
    /// LD19 10 Hz; RPLIDAR SCAN mode 5.5 Hz A1, 10 Hz A2).
    pub const fn nominal_rev_hz(self) -> f32 {
        match self {
            LidarModel::Lds01 => 5.0,
            LidarModel::Lds02 => 6.0,
            LidarModel::Ld06 | LidarModel::Ld19 => 10.0,
            LidarModel::RplidarA1 => 5.5,
            LidarModel::RplidarA2 => 10.0,
        }
    }

    /// Bytes a second on the wire at the nominal rates.
    pub const fn wire_bytes_per_second(self) -> u32 {
        match self.family() {
            Family::Lds01 => 2520 * 5,
            Family::Ldrobot => self.sample_rate_hz() / 12 * 47,
            Family::Rplidar => self.sample_rate_hz() * 5,
        }
    }

    /// Bytes of one revolution on the wire at the nominal rates.
    pub fn bytes_per_revolution(self) -> u32 {
        (self.wire_bytes_per_second() as f32 / self.nominal_rev_hz()) as u32
    }

    /// The models of one family that share a baud rate cannot be told apart from their bytes
    /// (LD06 vs LD19); detection reports the first and says so.
    pub const fn same_bytes_as(self) -> Option<LidarModel> {
        match self {
            LidarModel::Ld06 => Some(LidarModel::Ld19),
            LidarModel::Ld19 => Some(LidarModel::Ld06),
            _ => None,
        }
    }
}

impl core::fmt::Display for LidarModel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.display_name())
    }
}

/// Every LiDAR fault counter, cumulative since start. Each model fills the ones its wire
/// format can have; the rest stay 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LidarFaults {
    /// Bytes that were not part of any packet, frame or node passed on.
    pub bytes_skipped: u64,
    /// Packets or frames whose checksum / CRC failed (LDS-01 `Count` policy: kept).
    pub bad_checksum: u64,
    /// LDS-01: sync bytes followed by an out-of-range index; RPLIDAR: nodes whose angle is
    /// out of range.
    pub bad_index: u64,
    /// Sectors (LDS-01: packets) missing from revolutions handed out.
    pub missing_packets: u64,
    /// LDS-01: packets received twice in a row.
    pub repeated_packets: u64,
    /// LDS-01: bad-checksum packets kept by `Count` but dropped for an out-of-sequence index.
    pub out_of_sequence_bad_packets: u64,
    /// Revolutions handed out with sectors missing.
    pub incomplete_revolutions: u64,
    /// LDROBOT: frames with a good CRC that failed the plausibility filter (span too wide
    /// for the speed, or speed 0).
    pub implausible_frames: u64,
    /// Error reports from the sensor itself (LDROBOT health frames with an error code).
    pub sensor_errors: u64,
    /// LDS-01: good packets whose speed field says the motor is stalled (below 60 rpm).
    pub stalled_packets: u64,
    /// Point-based models (LDROBOT, RPLIDAR): partial revolutions not handed out as frames,
    /// the lead-in before the stream's first sweep start and an unfinished last one.
    pub partial_revolutions_dropped: u64,
}

/// Wheel ticks that a stream carries besides its scans (a CARMEN log's poses, turned into the
/// ticks of the configured drive), on the stream's clock.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WheelTicks {
    /// Time, s, on the stream's clock.
    pub t: f64,
    /// Left wheel ticks, cumulative.
    pub left: i64,
    /// Right wheel ticks, cumulative.
    pub right: i64,
}

/// A revolution stream: bytes in any chunking → [`Revolution`]s. Every LiDAR model's decoder
/// implements it, and so does anything else that yields scans from bytes (the runtime's CARMEN
/// log reader). Object-safe (the generic [`RevolutionStream::feed`] needs `Sized`), so
/// [`AnyLidar`] forwards through `&dyn RevolutionStream`.
pub trait RevolutionStream {
    /// The LiDAR whose bytes this decodes; `None` for a stream that is not one LiDAR's bytes
    /// (a log file).
    fn model(&self) -> Option<LidarModel>;

    /// Bytes of one revolution on the wire (the reader is behind when more wait); `None` when
    /// the stream has no such rate.
    fn bytes_per_revolution(&self) -> Option<u32> {
        self.model().map(LidarModel::bytes_per_revolution)
    }

    /// What the stream decodes, for messages.
    fn what(&self) -> &'static str {
        self.model().map_or("scan log", LidarModel::display_name)
    }

    /// Hands wheel ticks decoded from the stream to `out` (logs only); returns how many.
    fn drain_odometry(&mut self, _out: &mut dyn FnMut(WheelTicks)) -> usize {
        0
    }

    /// Consumes bytes from the front of `input` until a revolution is finished (returns
    /// `true`; read it with [`RevolutionStream::last_revolution`]) or `input` is used up (`false`).
    /// `host_us` is the host's monotonic clock for these bytes, if any.
    fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool;

    /// The last revolution finished.
    fn last_revolution(&self) -> Option<&Revolution>;

    /// Hands out a partial revolution if no data arrived for the stale time.
    fn poll(&mut self, now_us: u64) -> Option<&Revolution>;

    /// End of stream: drops partial frames and hands out a partial revolution.
    fn finish(&mut self) -> Option<&Revolution>;

    /// The link was lost and reopened: a partial frame cannot continue.
    fn link_reset(&mut self);

    /// The sensor clock (`docs/interfaces.md` §2) at the latest data, seconds.
    fn sensor_time_s(&self) -> f64;

    /// All fault counters.
    fn faults(&self) -> LidarFaults;

    /// Feeds a chunk of bytes; calls `on_revolution` for each revolution it finishes and
    /// returns how many.
    fn feed(
        &mut self,
        bytes: &[u8],
        host_us: Option<u64>,
        mut on_revolution: impl FnMut(&Revolution),
    ) -> usize
    where
        Self: Sized,
    {
        let mut done = 0;
        let mut input = bytes;
        while self.next_revolution(&mut input, host_us) {
            if let Some(rev) = self.last_revolution() {
                on_revolution(rev);
                done += 1;
            }
        }
        done
    }
}

/// Settings shared by every model's stream.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LidarConfig {
    /// Shortest range counted valid, metres (`None`: the model's spec).
    pub min_range_m: Option<f32>,
    /// Longest range counted valid, metres (`None`: the model's spec; LDS-01: 3.5).
    pub max_range_m: Option<f32>,
    /// Host-clock silence after which a partial revolution is handed out, µs.
    pub stale_after_us: u64,
    /// LDS-01 only: what a checksum failure means.
    pub lds01_checksum: crate::lds01::ChecksumPolicy,
}

impl Default for LidarConfig {
    fn default() -> Self {
        LidarConfig {
            min_range_m: None,
            max_range_m: None,
            stale_after_us: 500_000,
            lds01_checksum: crate::lds01::ChecksumPolicy::default(),
        }
    }
}

impl LidarConfig {
    /// The range window for `model`: the configured bounds, else the model's spec.
    pub fn window(&self, model: LidarModel) -> (f32, f32) {
        let (lo, hi) = model.range_window_m();
        (
            self.min_range_m.unwrap_or(lo),
            self.max_range_m.unwrap_or(hi),
        )
    }
}

/// One stream for whichever model is attached: static dispatch, no heap. The variants differ
/// in size (two revolutions each plus a frame buffer); keep it boxed or static on small MCUs.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)] // one per process, never moved in a hot path
pub enum AnyLidar {
    /// LDS-01.
    Lds01(Lds01Stream),
    /// LDS-02, LD06, LD19.
    Ldrobot(LdrobotStream),
    /// RPLIDAR A1/A2.
    Rplidar(RplidarStream),
}

impl AnyLidar {
    /// The stream for `model` with `cfg`.
    pub fn new(model: LidarModel, cfg: &LidarConfig) -> Self {
        let (min_range_m, max_range_m) = cfg.window(model);
        match model.family() {
            Family::Lds01 => AnyLidar::Lds01(Lds01Stream::new(Lds01Config {
                checksum: cfg.lds01_checksum,
                assembler: crate::lds01::AssemblerConfig {
                    min_range_m,
                    max_range_m,
                    stale_after_us: cfg.stale_after_us,
                },
            })),
            Family::Ldrobot => AnyLidar::Ldrobot(LdrobotStream::new(LdrobotConfig {
                model,
                points: points::PointConfig {
                    min_range_m,
                    max_range_m,
                    stale_after_us: cfg.stale_after_us,
                },
            })),
            Family::Rplidar => AnyLidar::Rplidar(RplidarStream::new(RplidarConfig {
                model,
                points: points::PointConfig {
                    min_range_m,
                    max_range_m,
                    stale_after_us: cfg.stale_after_us,
                },
            })),
        }
    }

    fn inner(&self) -> &dyn RevolutionStream {
        match self {
            AnyLidar::Lds01(s) => s,
            AnyLidar::Ldrobot(s) => s,
            AnyLidar::Rplidar(s) => s,
        }
    }

    fn inner_mut(&mut self) -> &mut dyn RevolutionStream {
        match self {
            AnyLidar::Lds01(s) => s,
            AnyLidar::Ldrobot(s) => s,
            AnyLidar::Rplidar(s) => s,
        }
    }
}

impl RevolutionStream for AnyLidar {
    fn model(&self) -> Option<LidarModel> {
        self.inner().model()
    }
    fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool {
        self.inner_mut().next_revolution(input, host_us)
    }
    fn last_revolution(&self) -> Option<&Revolution> {
        self.inner().last_revolution()
    }
    fn poll(&mut self, now_us: u64) -> Option<&Revolution> {
        self.inner_mut().poll(now_us)
    }
    fn finish(&mut self) -> Option<&Revolution> {
        self.inner_mut().finish()
    }
    fn link_reset(&mut self) {
        self.inner_mut().link_reset()
    }
    fn sensor_time_s(&self) -> f64 {
        self.inner().sensor_time_s()
    }
    fn faults(&self) -> LidarFaults {
        self.inner().faults()
    }
}
