//! LDROBOT LiDARs: the ROBOTIS LDS-02 (= LD08, TurtleBot3 since 2022), LD06 and LD19. One wire
//! format (`docs/hardware.md` §1a–1b), three models that differ in baud rate, sample rate and, for the
//! LD08, a geometry correction.
//!
//! | module      | owns                                                              |
//! |-------------|-------------------------------------------------------------------|
//! | [`frame`]   | the 47-byte frame, health and info frames, CRC-8, `emit`          |
//! | [`decoder`] | bytes in any chunking → checked frames; resync inside bad frames  |
//! | this module | [`LdrobotStream`]: plausibility filter, in-frame angles, LD08 correction, clockwise → REP 103, sensor clock, revolutions |
//!
//! ## From a frame to points
//!
//! 1. **Plausibility** (after the CRC passed): a frame whose span in whole degrees exceeds
//!    `speed · 12 / sample_rate · 1.5`, or whose speed is 0, is dropped and counted
//!    ([`crate::lidar::LidarFaults::implausible_frames`]), as the vendors' drivers do.
//! 2. **Angles** inside the frame by the vendors' interpolation
//!    ([`frame::FrameRepr::point_angle_deg`]).
//! 3. **LD08 geometry** ([`ld08_correct`]): the LDS-02 measures by triangulation from an
//!    offset origin; the ROBOTIS driver's correction (`x = d + 5.9`, `y = 0.11923·d − 20.14`,
//!    `d' = |(x, y)|`, shift `atan(y/x)`) is applied to every return.
//! 4. **Direction:** the raw angle runs clockwise; ours is `360° − θ` (+ the LD08 shift).
//! 5. **Sweep:** a new revolution starts where the raw angle wraps (drops by more than 180°).
//!
//! ## Sensor clock (`docs/interfaces.md` §2)
//!
//! t = 0 at the first valid frame; each frame's millisecond timestamp (wrapping at 30000)
//! advances the clock by its difference to the previous one (a stamp behind the previous one
//! by less than half the wrap holds the clock, counted); point `i` of a frame lies
//! `i / sample_rate` after the frame's stamp.

pub mod decoder;
pub mod frame;

pub use decoder::{Decoded, Decoder, DecoderStats};
pub use frame::{FRAME_LEN, FrameRepr, HEADER, Health, POINTS, RawPoint};

use crate::lidar::points::{Point, PointAssembler, PointConfig};
use crate::lidar::{LidarFaults, LidarModel, Revolution, RevolutionStream};

/// LD08 geometry constants of the ROBOTIS driver (`transform.cpp`, `LD_EIGHT`).
pub mod ld08 {
    /// Offset along the beam, mm.
    pub const OFFSET_X_MM: f32 = 5.9;
    /// Lateral offset, mm.
    pub const OFFSET_Y_MM: f32 = -20.14;
    /// Lateral growth with distance.
    pub const SLOPE: f32 = 0.11923;
}

/// The LD08 correction: raw distance (mm) → (corrected distance mm, angle shift in degrees
/// to add after the clockwise → counter-clockwise conversion). Distance 0 stays 0, shift 0.
pub fn ld08_correct(d_mm: f32) -> (f32, f32) {
    if d_mm <= 0.0 {
        return (0.0, 0.0);
    }
    let x = d_mm + ld08::OFFSET_X_MM;
    let y = d_mm * ld08::SLOPE + ld08::OFFSET_Y_MM;
    (libm::sqrtf(x * x + y * y), libm::atanf(y / x).to_degrees())
}

/// The inverse of the LD08 correction's distance: the raw distance (mm) that the sensor sends
/// for a true distance `d_true_mm` (for the simulator and tests). Solves
/// `(d + 5.9)² + (0.11923·d − 20.14)² = d_true²` for its positive root.
pub fn ld08_raw_distance(d_true_mm: f32) -> f32 {
    let (a, ox, oy) = (ld08::SLOPE, ld08::OFFSET_X_MM, ld08::OFFSET_Y_MM);
    let qa = 1.0 + a * a;
    let qb = 2.0 * (ox + oy * a);
    let qc = ox * ox + oy * oy - d_true_mm * d_true_mm;
    let disc = qb * qb - 4.0 * qa * qc;
    if disc < 0.0 {
        return 0.0;
    }
    ((-qb + libm::sqrtf(disc)) / (2.0 * qa)).max(0.0)
}

/// LDROBOT stream settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LdrobotConfig {
    /// LDS-02, LD06 or LD19 (another model is treated as the LD06).
    pub model: LidarModel,
    /// Range window and staleness.
    pub points: PointConfig,
}

/// Counters of the LDROBOT stream beyond the decoder's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LdrobotStats {
    /// Frames dropped by the plausibility filter (or speed 0).
    pub implausible: u64,
    /// Health frames with a non-zero error code.
    pub health_errors: u64,
    /// The last health error code seen (0 = none).
    pub last_health_error: u8,
    /// Frame stamps behind the previous one (held, not read as a wrap).
    pub stamp_steps_back: u64,
}

/// Decoder + point assembler for an LDROBOT LiDAR; see the module docs.
#[derive(Debug, Clone)]
pub struct LdrobotStream {
    model: LidarModel,
    decoder: Decoder,
    points: PointAssembler,
    stats: LdrobotStats,
    /// Sensor time of the last frame's stamp, s, and its raw timestamp.
    clock: Option<(f64, u16)>,
    /// Raw angle of the last point, degrees (for the wrap).
    last_raw_deg: Option<f32>,
    nominal_period_s: f32,
    /// Points of the current frame not yet handed to the assembler (a revolution can end
    /// mid-frame; the rest go in on the next call).
    pending: [Point; POINTS],
    pending_new_sweep: [bool; POINTS],
    pending_len: usize,
    pending_at: usize,
    pending_host_us: Option<u64>,
}

impl LdrobotStream {
    /// A new stream.
    pub fn new(cfg: LdrobotConfig) -> Self {
        let model = match cfg.model {
            m @ (LidarModel::Lds02 | LidarModel::Ld06 | LidarModel::Ld19) => m,
            _ => LidarModel::Ld06,
        };
        LdrobotStream {
            model,
            decoder: Decoder::new(),
            points: PointAssembler::new(cfg.points),
            stats: LdrobotStats::default(),
            clock: None,
            last_raw_deg: None,
            nominal_period_s: 0.2,
            pending: [Point {
                angle_deg: 0.0,
                sweep_deg: 0.0,
                range_m: 0.0,
                intensity: 0,
                t_s: 0.0,
            }; POINTS],
            pending_new_sweep: [false; POINTS],
            pending_len: 0,
            pending_at: 0,
            pending_host_us: None,
        }
    }

    /// The decoder (its counters).
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// Stream counters.
    pub fn stats(&self) -> &LdrobotStats {
        &self.stats
    }

    /// The point assembler (its counters).
    pub fn assembler(&self) -> &PointAssembler {
        &self.points
    }

    /// `true` if the frame passes the vendors' plausibility rule.
    pub fn plausible(&self, f: &FrameRepr) -> bool {
        if f.speed_dps == 0 {
            return false;
        }
        let limit =
            f32::from(f.speed_dps) * POINTS as f32 / self.model.sample_rate_hz() as f32 * 1.5;
        f.span_whole_deg() as f32 <= limit
    }

    /// Turns a frame into pending points.
    fn load(&mut self, f: &FrameRepr, host_us: Option<u64>) {
        let t_frame = match self.clock {
            None => 0.0,
            Some((t, ts)) => {
                let wrap = u32::from(frame::TIMESTAMP_WRAP_MS);
                let (now, prev) = (u32::from(f.timestamp_ms) % wrap, u32::from(ts) % wrap);
                let step = (now + wrap - prev) % wrap;
                // A stamp a little behind the last one is jitter, not a 30 s wrap: the clock
                // never runs backwards, so it stands still.
                if step > wrap / 2 {
                    self.stats.stamp_steps_back += 1;
                    t
                } else {
                    t + f64::from(step) / 1000.0
                }
            }
        };
        self.clock = Some((t_frame, f.timestamp_ms));
        self.nominal_period_s = 360.0 / f32::from(f.speed_dps.max(1));
        let dt = 1.0 / f64::from(self.model.sample_rate_hz());
        for (i, p) in f.points.iter().enumerate() {
            let raw = f.point_angle_deg(i);
            let new_sweep = self.last_raw_deg.is_some_and(|last| raw < last - 180.0);
            self.last_raw_deg = Some(raw);
            let d = f32::from(p.distance_mm);
            let (d, shift) = if self.model == LidarModel::Lds02 {
                ld08_correct(d)
            } else {
                (d, 0.0)
            };
            self.pending[i] = Point {
                angle_deg: 360.0 - raw + shift,
                sweep_deg: 360.0 - raw,
                range_m: d / 1000.0,
                intensity: u16::from(p.confidence),
                t_s: t_frame + i as f64 * dt,
            };
            self.pending_new_sweep[i] = new_sweep;
        }
        self.pending_len = POINTS;
        self.pending_at = 0;
        self.pending_host_us = host_us;
    }

    /// Feeds pending points; `true` when one finished a revolution.
    fn drain_pending(&mut self) -> bool {
        while self.pending_at < self.pending_len {
            let i = self.pending_at;
            self.pending_at += 1;
            if self.points.push(
                &self.pending[i],
                self.pending_new_sweep[i],
                self.nominal_period_s,
                self.pending_host_us,
            ) {
                return true;
            }
        }
        false
    }
}

impl RevolutionStream for LdrobotStream {
    fn model(&self) -> Option<LidarModel> {
        Some(self.model)
    }

    fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool {
        loop {
            if self.drain_pending() {
                return true;
            }
            match self.decoder.next_frame(input) {
                None => return false,
                Some(Decoded::Measurement(f)) => {
                    if self.plausible(&f) {
                        self.load(&f, host_us);
                    } else {
                        self.stats.implausible += 1;
                    }
                }
                Some(Decoded::Health(h)) => {
                    if h.error_code != 0 {
                        self.stats.health_errors += 1;
                        self.stats.last_health_error = h.error_code;
                    }
                }
                Some(Decoded::Info) => {}
            }
        }
    }

    fn last_revolution(&self) -> Option<&Revolution> {
        self.points.last()
    }

    fn poll(&mut self, now_us: u64) -> Option<&Revolution> {
        self.points.poll(now_us, self.nominal_period_s)
    }

    fn finish(&mut self) -> Option<&Revolution> {
        self.decoder.reset();
        // Points of a frame already decoded are real data: put them in first.
        while self.pending_at < self.pending_len {
            let i = self.pending_at;
            self.pending_at += 1;
            self.points.push(
                &self.pending[i],
                false,
                self.nominal_period_s,
                self.pending_host_us,
            );
        }
        self.points.flush(self.nominal_period_s)
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
            bad_checksum: d.bad_crc,
            missing_packets: p.missing_sectors,
            incomplete_revolutions: p.incomplete_revolutions,
            partial_revolutions_dropped: p.partial_dropped,
            implausible_frames: self.stats.implausible,
            sensor_errors: self.stats.health_errors,
            ..LidarFaults::default()
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn ld08_correction_matches_the_driver_formula_and_inverts() {
        // d = 1000: x = 1005.9, y = 99.09 → d' = 1010.77, shift = 5.626°.
        let (d, s) = ld08_correct(1000.0);
        assert!((d - 1010.769).abs() < 0.01, "{d}");
        assert!((s - 5.6260).abs() < 1e-3, "{s}");
        for t in [200.0f32, 500.0, 1000.0, 3000.0, 7999.0] {
            let raw = ld08_raw_distance(t);
            let (back, _) = ld08_correct(raw);
            assert!((back - t).abs() < 0.05, "{t} → {raw} → {back}");
        }
        assert_eq!(ld08_correct(0.0), (0.0, 0.0));
    }
}
