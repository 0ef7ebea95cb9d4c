//! One LiDAR revolution, the same type for every model: 360 bins in our angle convention,
//! with time stamps.
//!
//! ## Angle convention
//!
//! Angles follow ROS REP 103: radians, **counter-clockwise** from the LiDAR's forward axis
//! (x forward, y left, seen from above). Bin `d` holds the reading closest to `d` degrees
//! counter-clockwise, `d = 0..360`: [0°, 360°), no duplicate end, **the same count for every
//! model and every revolution** whatever the sensor's native beam count (the complaint of
//! `docs/hardware.md` §1d.3 cannot happen). Every model we support sweeps **clockwise**; each family
//! maps its raw angle into this convention once, in its own module:
//!
//! * LDS-01: raw reading `i = 6·k + j` (packet `k`, reading `j`) lies at `(359 − i)°`, the
//!   mapping of the vendor's ROS driver (`ranges[359 − i]`), which every TurtleBot3 map made
//!   with that driver relies on ([`raw_to_bin`]);
//! * LDROBOT (LDS-02/LD08, LD06, LD19): raw angle θ → `(360 − θ)°` (the vendor drivers'
//!   right-hand conversion), plus the LD08 geometry correction;
//! * RPLIDAR A1/A2: raw angle θ → `(180 − θ)°` (the vendor ROS driver's `π − θ`).
//!
//! The LiDAR frame is not the robot frame: on a TurtleBot3 Burger the LiDAR sits at
//! x = −0.032 m, unrotated. Moving points into the robot frame is the pose code's job.
//!
//! ## Sectors
//!
//! Coverage is kept in 60 **sectors** of 6° in sweep order: sector `k` holds the bins swept
//! from `6k/360` to `6(k+1)/360` of the revolution after [`Revolution::sweep_start_bin`]. For
//! the LDS-01 a sector is exactly one packet; for the other models a sector is present when any
//! point landed in it, and a sector the sweep passed without data is a missing one.
//!
//! ## Time stamps
//!
//! [`Revolution::t_start_s`] is on the sensor's own clock (`docs/interfaces.md` §2): the start of
//! the sweep (for the LDS-01, the start of packet slot 0). The bin swept `f` of the way round
//! was taken at `t_start_s + f · period_s` ([`Revolution::reading_time_s`]), so a moving robot's
//! scan can be de-skewed; the frame's stamp is the first ray's time
//! ([`Revolution::first_ray_time_s`]), never the publish time. [`Revolution::host_time_us`] is
//! the host's monotonic clock when the first data of the revolution was decoded, when the
//! caller supplied one.

/// Bins per revolution, for every model.
pub const BINS: usize = 360;
/// Sectors per revolution (6° each; an LDS-01 packet).
pub const SECTORS: usize = 60;
/// Bins per sector.
pub const BINS_PER_SECTOR: usize = BINS / SECTORS;
const READINGS_PER_REV: usize = BINS;
const PACKETS_PER_REV: usize = SECTORS;

/// One reading in our convention.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reading {
    /// Counter-clockwise angle from the LiDAR's forward axis, radians, in [0, 2π).
    pub angle_rad: f32,
    /// Measured range in metres (0 = no return). Kept even when `valid` is false.
    pub range_m: f32,
    /// Return strength as sent (not a "no return" flag: real units send intensity on zeros).
    pub intensity: u16,
    /// `true` if the range is non-zero and inside the configured [min, max] range window.
    pub valid: bool,
}

/// LDS-01: the raw reading number `i` (0..360, clockwise) → the bin `d` (degrees
/// counter-clockwise). Values outside 0..360 are taken modulo 360. The mapping is its own
/// inverse.
#[inline]
pub const fn raw_to_bin(i: usize) -> usize {
    (READINGS_PER_REV - 1) - (i % READINGS_PER_REV)
}

/// The angle of bin `d` in radians.
#[inline]
pub fn bin_angle_rad(d: usize) -> f32 {
    (d % READINGS_PER_REV) as f32 * DEG_TO_RAD
}

/// A revolution as the assembler hands it out.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Revolution {
    /// Revolution number since start (0, 1, 2, …); gaps never occur, lost ones are not numbered.
    pub seq: u32,
    /// Sensor-clock time of the start of packet slot 0, seconds.
    pub t_start_s: f64,
    /// Duration of this revolution, `60 / rpm` seconds.
    pub period_s: f32,
    /// Mean motor speed over the packets received, rpm.
    pub rpm: f32,
    /// Host clock (caller's monotonic µs) when the first packet received was decoded.
    pub host_time_us: Option<u64>,
    /// Sectors received (60 = complete; for the LDS-01, its packets).
    pub packets: u8,
    /// Bit `k` set if sector `k` (sweep order) was received.
    pub present: u64,
    /// Packets received with a failed checksum (only under the LDS-01's `Count` policy).
    pub bad_checksum_packets: u8,
    /// The bin the sweep starts at (LDS-01: 359); sweep order runs clockwise from it.
    pub sweep_start_bin: u16,
    /// Readings by bin: `readings[d]` is at `d` degrees counter-clockwise.
    pub readings: [Reading; READINGS_PER_REV],
}

/// The readings of an empty revolution: every bin at its angle, no return, invalid.
pub const EMPTY_READINGS: [Reading; READINGS_PER_REV] = {
    let mut readings = [Reading {
        angle_rad: 0.0,
        range_m: 0.0,
        intensity: 0,
        valid: false,
    }; READINGS_PER_REV];
    let mut d = 0;
    while d < READINGS_PER_REV {
        readings[d].angle_rad = d as f32 * DEG_TO_RAD;
        d += 1;
    }
    readings
};

const DEG_TO_RAD: f32 = core::f32::consts::PI / 180.0;

impl Revolution {
    /// An empty revolution: every reading invalid at its bin's angle.
    pub fn empty() -> Self {
        let readings = EMPTY_READINGS;
        Revolution {
            seq: 0,
            t_start_s: 0.0,
            period_s: 0.0,
            rpm: 0.0,
            host_time_us: None,
            packets: 0,
            present: 0,
            bad_checksum_packets: 0,
            sweep_start_bin: (READINGS_PER_REV - 1) as u16,
            readings,
        }
    }

    /// `true` if all 60 sectors arrived.
    pub fn is_complete(&self) -> bool {
        usize::from(self.packets) == PACKETS_PER_REV
    }

    /// Sectors that did not arrive.
    pub fn missing_packets(&self) -> u8 {
        PACKETS_PER_REV as u8 - self.packets
    }

    /// `true` if sector `k` (0..60, sweep order) arrived.
    pub fn has_packet(&self, k: usize) -> bool {
        k < PACKETS_PER_REV && self.present & (1 << k) != 0
    }

    /// Position of bin `d` in sweep order, 0..360 (0 = the first bin swept).
    pub fn sweep_position(&self, d: usize) -> usize {
        let start = usize::from(self.sweep_start_bin) % READINGS_PER_REV;
        (start + READINGS_PER_REV - d % READINGS_PER_REV) % READINGS_PER_REV
    }

    /// The sector (sweep order) bin `d` belongs to.
    pub fn sector_of(&self, d: usize) -> usize {
        self.sweep_position(d) / BINS_PER_SECTOR
    }

    /// Sensor-clock time (s) at which the reading of bin `d` was taken.
    pub fn reading_time_s(&self, d: usize) -> f64 {
        let i = self.sweep_position(d);
        self.t_start_s + (i as f64 / READINGS_PER_REV as f64) * f64::from(self.period_s)
    }

    /// Sensor-clock time (s) of the first ray actually received: the start of the first
    /// packet present (the frame's time stamp). Equals `t_start_s` for a complete revolution.
    pub fn first_ray_time_s(&self) -> f64 {
        let first = if self.present == 0 {
            0
        } else {
            self.present.trailing_zeros()
        };
        self.t_start_s + f64::from(first) / PACKETS_PER_REV as f64 * f64::from(self.period_s)
    }

    /// Number of valid readings.
    pub fn valid_count(&self) -> usize {
        self.readings.iter().filter(|r| r.valid).count()
    }

    /// Readings with a range of exactly 0 (no return) among the sectors received.
    pub fn no_return_count(&self) -> usize {
        (0..READINGS_PER_REV)
            .filter(|&d| self.has_packet(self.sector_of(d)) && self.readings[d].range_m == 0.0)
            .count()
    }

    /// Summary statistics of the valid ranges (metres): (min, mean, max), or `None` if none.
    pub fn range_stats(&self) -> Option<(f32, f32, f32)> {
        let mut n = 0u32;
        let (mut lo, mut hi, mut sum) = (f32::INFINITY, 0.0f32, 0.0f32);
        for r in self.readings.iter().filter(|r| r.valid) {
            n += 1;
            lo = lo.min(r.range_m);
            hi = hi.max(r.range_m);
            sum += r.range_m;
        }
        (n > 0).then(|| (lo, sum / n as f32, hi))
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn raw_index_mapping_follows_vendor_driver() {
        // Vendor driver: ranges[359 - i] with angle_min 0 and +1° per step (CCW).
        assert_eq!(raw_to_bin(0), 359);
        assert_eq!(raw_to_bin(359), 0);
        assert_eq!(raw_to_bin(89), 270); // right
        assert_eq!(raw_to_bin(269), 90); // left
        assert_eq!(raw_to_bin(179), 180); // behind
        for i in 0..360 {
            assert_eq!(raw_to_bin(raw_to_bin(i)), i);
        }
    }

    #[test]
    fn empty_has_angles() {
        let r = Revolution::empty();
        assert_eq!(r.valid_count(), 0);
        assert!((r.readings[90].angle_rad - core::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert!(r.range_stats().is_none());
        assert_eq!(r.missing_packets(), 60);
    }

    #[test]
    fn sectors_follow_the_sweep() {
        let mut r = Revolution::empty();
        // LDS-01: sector k = packet k = raw readings 6k..6k+6 = bins 359-6k down to 354-6k.
        for i in 0..360 {
            assert_eq!(r.sector_of(raw_to_bin(i)), i / 6);
        }
        // A sweep starting at bin 0 (LDROBOT): 0, 359, 358, ...
        r.sweep_start_bin = 0;
        assert_eq!(r.sweep_position(0), 0);
        assert_eq!(r.sweep_position(359), 1);
        assert_eq!(r.sector_of(355), 0);
        assert_eq!(r.sector_of(354), 1);
        assert_eq!(r.sector_of(1), 59);
    }

    #[test]
    fn reading_time_runs_clockwise() {
        let mut r = Revolution::empty();
        r.t_start_s = 10.0;
        r.period_s = 0.2;
        // Raw 0 (bin 359) is first, raw 359 (bin 0) last.
        assert!((r.reading_time_s(359) - 10.0).abs() < 1e-9);
        assert!((r.reading_time_s(0) - (10.0 + 0.2 * 359.0 / 360.0)).abs() < 1e-6);
    }
}
