//! CARMEN logs (`*.clf`, `*.log`, gzip-compressed or not) replayed through the frame loop
//! (`docs/interfaces.md` §2), for testing against real laser data (`../shared/data/README.md` §1).
//!
//! A [`CarmenStream`] is a `drivers::lidar::RevolutionStream` over the log's text:
//! * each `FLASER` line is one frame: its n beams, evenly spaced over 180° from −90° (right)
//!   counter-clockwise (beam k at −90° + k·180°/n), binned into the 360 one-degree bins like
//!   any LiDAR's points (closest valid return wins a bin; the pipeline's range window applies;
//!   ranges ≥ 80 m mean no return). The laser's half turn is not a LiDAR's revolution, so the
//!   revolution covers the 30 front sectors. Its period is the SICK LMS mirror's (75 turns a
//!   second): the pose barely moves during a scan, so nothing is de-skewed;
//! * the pose each `FLASER` line carries (its `odom_x odom_y odom_theta`, in the "corrected"
//!   logs the scan matcher's pose) is the robot's pose at that scan. The pipeline's pose comes
//!   from wheel ticks, so each step between two scans is turned into the ticks of the
//!   configured differential drive (turn, drive the chord, turn), which the pose filter
//!   integrates back to the scan's pose. `ODOM` lines are
//!   parsed and counted but not used: at the same stamp they differ from the scan's pose by
//!   up to 8 cm and 0.08 rad (a different estimate), and mixing the two zigzags the pose;
//! * the clock is the log's `ipc_timestamp`, from the first stamp seen; a scan stamped before
//!   the previous one (intel has four) is held at the previous time;
//! * other messages (`PARAM`, `NEFF`, `SYNC`, comments) are skipped; a line that does not
//!   parse, or is longer than [`LINE_CAPACITY`], is counted in `lidar_bytes_skipped`.

use std::io::Read as _;
use std::path::Path;

use drivers::lidar::points::{Point, PointAssembler, PointConfig};
use drivers::lidar::{LidarFaults, LidarModel, Revolution, RevolutionStream, WheelTicks};
use perception::geometry::wrap_angle;
use perception::pose::OdometryConfig;

/// The longest line kept (fr079's 360-beam scans are ~3 KB).
pub const LINE_CAPACITY: usize = 16 * 1024;
/// Beams a scan may have.
pub const MAX_BEAMS: usize = 4096;
/// Odometry samples decoded and not yet drained.
pub const ODOM_PENDING: usize = 64;
/// A range at or beyond this is "no return" (SICK: 81.83 or 81.91 m).
pub const NO_RETURN_M: f32 = 80.0;
/// The period given to a scan: one turn of the SICK LMS mirror (75 Hz).
pub const SCAN_PERIOD_S: f32 = 1.0 / 75.0;

/// Whether `head` (a file's first bytes, decompressed) reads like a CARMEN log: its first
/// non-comment line starts with a CARMEN message type.
pub fn looks_like_carmen(head: &[u8]) -> bool {
    const TYPES: [&str; 8] = [
        "PARAM",
        "ODOM",
        "FLASER",
        "RLASER",
        "SYNC",
        "TRUEPOS",
        "NEFF",
        "ROBOTLASER1",
    ];
    String::from_utf8_lossy(head)
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
        .and_then(|l| l.split_whitespace().next())
        .is_some_and(|t| TYPES.contains(&t))
}

/// Reads a log into memory, gunzipping it if it starts with the gzip magic. Errors name the
/// file.
pub fn read_log(path: &Path) -> Result<Vec<u8>, String> {
    let raw =
        std::fs::read(path).map_err(|e| format!("log {}: cannot read: {e}", path.display()))?;
    if raw.starts_with(&[0x1F, 0x8B]) {
        let mut text = Vec::with_capacity(raw.len() * 4);
        flate2::read::MultiGzDecoder::new(&raw[..])
            .read_to_end(&mut text)
            .map_err(|e| format!("log {}: not a readable gzip file: {e}", path.display()))?;
        Ok(text)
    } else {
        Ok(raw)
    }
}

/// The `robot_frontlaser_offset` PARAM of a log (metres, as written), if it has one.
pub fn front_laser_offset(text: &[u8]) -> Option<f32> {
    String::from_utf8_lossy(&text[..text.len().min(256 * 1024)])
        .lines()
        .find_map(|l| {
            let mut t = l.split_whitespace();
            (t.next() == Some("PARAM") && t.next() == Some("robot_frontlaser_offset"))
                .then(|| t.next()?.parse().ok())
                .flatten()
        })
}

/// The fields of a `FLASER` line after its type (`tok` yields them): its beams' ranges as
/// written into `ranges` (cleared first), the odometry pose (x, y, θ) and the stamp. `None`
/// when a field is missing or not a finite number, or the beam count is outside
/// 1..=[`MAX_BEAMS`].
pub fn parse_flaser<'a>(
    tok: &mut impl Iterator<Item = &'a str>,
    ranges: &mut Vec<f32>,
) -> Option<((f64, f64, f64), f64)> {
    let mut num = || {
        tok.next()
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|v| v.is_finite())
    };
    let n = num()?;
    if !(1.0..=MAX_BEAMS as f64).contains(&n) || n.fract() != 0.0 {
        return None;
    }
    // n ranges, the laser pose (x y θ), the odometry pose, then the stamp.
    ranges.clear();
    for _ in 0..n as usize {
        ranges.push(num()? as f32);
    }
    let _laser = (num()?, num()?, num()?);
    let odom = (num()?, num()?, num()?);
    Some((odom, num()?))
}

/// Bearing of beam `k` of a scan of `n`, degrees: evenly over 180° from −90° (right).
pub fn beam_bearing_deg(k: usize, n: usize) -> f32 {
    -90.0 + k as f32 * 180.0 / n as f32
}

/// A beam's range as the pipeline takes it: 0 (no return) at or beyond [`NO_RETURN_M`] or not
/// positive.
pub fn beam_range_m(r: f32) -> f32 {
    if r >= NO_RETURN_M || r <= 0.0 { 0.0 } else { r }
}

/// Counters of the log reader.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CarmenStats {
    /// `FLASER` lines made into frames.
    pub scans: u64,
    /// `ODOM` lines read (checked, not used).
    pub odometry: u64,
    /// Lines skipped as other message types or comments.
    pub other_lines: u64,
    /// Lines that did not parse or were too long.
    pub bad_lines: u64,
    /// Their bytes.
    pub bad_bytes: u64,
}

/// Decodes a CARMEN log's text into frames and odometry samples; see the module docs.
pub struct CarmenStream {
    line: Vec<u8>,
    overlong: bool,
    ranges: Vec<f32>,
    points: PointAssembler,
    odo: OdometryConfig,
    pending: heapless::Deque<WheelTicks, ODOM_PENDING>,
    t0: Option<f64>,
    t_last_scan: f64,
    t_last: f64,
    /// Last odometry pose (x, y, θ) and cumulative wheel distances (left, right), m.
    last_pose: Option<(f64, f64, f64)>,
    wheels: (f64, f64),
    stats: CarmenStats,
    dropped_odometry: u64,
}

impl CarmenStream {
    /// A reader with the pipeline's range window and the drive whose ticks the poses become.
    pub fn new(min_range_m: f32, max_range_m: f32, odo: OdometryConfig) -> Self {
        CarmenStream {
            line: Vec::with_capacity(LINE_CAPACITY),
            overlong: false,
            ranges: Vec::with_capacity(MAX_BEAMS),
            points: PointAssembler::new(PointConfig {
                min_range_m,
                max_range_m,
                stale_after_us: u64::MAX,
            }),
            odo,
            pending: heapless::Deque::new(),
            t0: None,
            t_last_scan: 0.0,
            t_last: 0.0,
            last_pose: None,
            wheels: (0.0, 0.0),
            stats: CarmenStats::default(),
            dropped_odometry: 0,
        }
    }

    /// Counters.
    pub fn stats(&self) -> &CarmenStats {
        &self.stats
    }

    fn clock(&mut self, stamp: f64) -> f64 {
        let t0 = *self.t0.get_or_insert(stamp);
        let t = stamp - t0;
        self.t_last = self.t_last.max(t);
        t
    }

    /// The step from the last pose to (x, y, θ) → wheel ticks of the configured drive, as
    /// samples at `t`: turn to face the chord, drive it (backwards when it lies behind), turn to
    /// the new heading. A differential drive reaches any pose so, and the pose filter
    /// integrates the samples back to it exactly (to a tick), sideways steps of the scan
    /// matcher included; one arc per step would drop them (on intel: 49 m of 485 m, 4.8 m
    /// off by the end).
    fn odometry(&mut self, t: f64, x: f64, y: f64, theta: f64) {
        let Some((x0, y0, th0)) = self.last_pose.replace((x, y, theta)) else {
            self.emit_ticks(t);
            return;
        };
        let (dx, dy) = (x - x0, y - y0);
        let chord = dx.hypot(dy);
        let turn = |a: f64| f64::from(wrap_angle(a as f32));
        if chord < 1e-4 {
            self.turn(turn(theta - th0));
        } else {
            let mut heading = dy.atan2(dx);
            let mut drive = chord;
            if turn(heading - th0).abs() > std::f64::consts::FRAC_PI_2 {
                heading += std::f64::consts::PI;
                drive = -chord;
            }
            self.turn(turn(heading - th0));
            self.emit_ticks(t);
            self.wheels.0 += drive;
            self.wheels.1 += drive;
            self.emit_ticks(t);
            self.turn(turn(theta - heading));
        }
        self.emit_ticks(t);
    }

    fn turn(&mut self, angle: f64) {
        let half = f64::from(self.odo.wheel_separation_m) / 2.0;
        self.wheels.0 -= angle * half;
        self.wheels.1 += angle * half;
    }

    fn emit_ticks(&mut self, t: f64) {
        let per_tick = 2.0 * std::f64::consts::PI * f64::from(self.odo.wheel_radius_m)
            / f64::from(self.odo.ticks_per_rev);
        let r = WheelTicks {
            t,
            left: (self.wheels.0 / per_tick).round() as i64,
            right: (self.wheels.1 / per_tick).round() as i64,
        };
        if self.pending.push_back(r).is_err() {
            // Never: drained after every frame, at most three a scan.
            self.dropped_odometry += 1;
        }
    }

    /// Parses one line; `true` when it finished a frame.
    fn line(&mut self) -> bool {
        let text = std::mem::take(&mut self.line);
        let done = match std::str::from_utf8(&text) {
            Ok(s) => self.parse(s.trim()),
            Err(_) => Err(()),
        };
        let bytes = text.len() as u64 + 1;
        self.line = text;
        self.line.clear();
        match done {
            Ok(finished) => finished,
            Err(()) => {
                self.stats.bad_lines += 1;
                self.stats.bad_bytes += bytes;
                false
            }
        }
    }

    fn parse(&mut self, s: &str) -> Result<bool, ()> {
        let mut tok = s.split_ascii_whitespace();
        let num = |t: Option<&str>| -> Result<f64, ()> {
            t.and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or(())
        };
        match tok.next() {
            None => Ok(false),
            Some("FLASER") => {
                let mut ranges = std::mem::take(&mut self.ranges);
                let parsed = parse_flaser(&mut tok, &mut ranges);
                let Some(((x, y, th), stamp)) = parsed else {
                    self.ranges = ranges;
                    return Err(());
                };
                let n = ranges.len();
                let t = self.clock(stamp).max(self.t_last_scan);
                self.t_last_scan = t;
                self.odometry(t, x, y, th);
                for (k, &r) in ranges.iter().enumerate() {
                    let angle_deg = beam_bearing_deg(k, n);
                    let p = Point {
                        angle_deg,
                        sweep_deg: angle_deg,
                        range_m: beam_range_m(r),
                        intensity: 0,
                        t_s: t,
                    };
                    self.points.push(&p, k == 0, SCAN_PERIOD_S, None);
                }
                self.points.hand_out(SCAN_PERIOD_S);
                self.ranges = ranges;
                self.stats.scans += 1;
                Ok(true)
            }
            Some("ODOM") => {
                // Checked, counted, not used: see the module docs.
                let _pose = (num(tok.next())?, num(tok.next())?, num(tok.next())?);
                let _stamp = num(tok.nth(3))?;
                self.stats.odometry += 1;
                Ok(false)
            }
            Some(_) => {
                self.stats.other_lines += 1;
                Ok(false)
            }
        }
    }
}

impl RevolutionStream for CarmenStream {
    fn model(&self) -> Option<LidarModel> {
        None
    }

    fn next_revolution(&mut self, input: &mut &[u8], _host_us: Option<u64>) -> bool {
        while let Some((&b, rest)) = input.split_first() {
            *input = rest;
            if b == b'\n' {
                if self.overlong {
                    self.overlong = false;
                    self.stats.bad_bytes += self.line.len() as u64 + 1;
                    self.line.clear();
                    continue;
                }
                if self.line() {
                    return true;
                }
            } else if self.overlong {
                self.stats.bad_bytes += 1;
            } else if self.line.len() < LINE_CAPACITY {
                self.line.push(b);
            } else {
                self.overlong = true;
                self.stats.bad_lines += 1;
                self.stats.bad_bytes += 1;
            }
        }
        false
    }

    fn last_revolution(&self) -> Option<&Revolution> {
        self.points.last()
    }

    fn poll(&mut self, _now_us: u64) -> Option<&Revolution> {
        None
    }

    fn finish(&mut self) -> Option<&Revolution> {
        // A last line without a newline.
        if !self.line.is_empty() && !self.overlong && self.line() {
            return self.points.last();
        }
        None
    }

    fn link_reset(&mut self) {
        self.line.clear();
        self.overlong = false;
    }

    fn sensor_time_s(&self) -> f64 {
        self.t_last
    }

    fn faults(&self) -> LidarFaults {
        LidarFaults {
            bytes_skipped: self.stats.bad_bytes,
            ..LidarFaults::default()
        }
    }

    fn bytes_per_revolution(&self) -> Option<u32> {
        None
    }

    fn drain_odometry(&mut self, out: &mut dyn FnMut(WheelTicks)) -> usize {
        let mut n = 0;
        while let Some(r) = self.pending.pop_front() {
            out(r);
            n += 1;
        }
        n
    }

    fn what(&self) -> &'static str {
        "CARMEN log"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stream() -> CarmenStream {
        CarmenStream::new(0.12, 3.5, OdometryConfig::BURGER)
    }

    fn flaser(ranges: &[f32], pose: (f64, f64, f64), stamp: f64) -> String {
        let r: Vec<String> = ranges.iter().map(|r| format!("{r:.3}")).collect();
        let (x, y, th) = pose;
        format!(
            "FLASER {} {} {x} {y} {th} {x} {y} {th} {stamp} pippo {stamp}\n",
            ranges.len(),
            r.join(" ")
        )
    }

    #[test]
    fn a_scan_becomes_a_frame_with_beams_at_their_bins() {
        let mut s = stream();
        // 180 beams: beam k at −90° + k°. Beam 90 (straight ahead) 1.5 m, beam 0 (right)
        // 2 m, beam 179 (89° left) 81.83 m (no return), the rest 5 m (out of window).
        let mut ranges = vec![5.0f32; 180];
        ranges[90] = 1.5;
        ranges[0] = 2.0;
        ranges[179] = 81.83;
        let text = format!(
            "# CARMEN log\nPARAM robot_frontlaser_offset 0.0 0 pippo 0\n{}",
            flaser(&ranges, (0.0, 0.0, 0.0), 10.0)
        );
        let mut input = text.as_bytes();
        assert!(s.next_revolution(&mut input, None));
        let rev = s.last_revolution().unwrap();
        assert!(rev.readings[0].valid && (rev.readings[0].range_m - 1.5).abs() < 1e-6);
        assert!(rev.readings[270].valid && (rev.readings[270].range_m - 2.0).abs() < 1e-6);
        assert!(!rev.readings[89].valid && rev.readings[89].range_m == 0.0);
        assert!(!rev.readings[180].valid, "nothing behind");
        // The front half: 30 six-degree sectors, 31 where it straddles a sector edge.
        assert!((30..=31).contains(&rev.packets), "{}", rev.packets);
        assert_eq!(rev.t_start_s, 0.0, "the clock starts at the first stamp");
        assert_eq!(s.stats().other_lines, 2, "the comment and the PARAM");
        assert_eq!(s.faults().bytes_skipped, 0);
        assert!(input.is_empty());
    }

    #[test]
    fn odometry_poses_become_ticks_that_integrate_back() {
        let mut s = stream();
        let text = [
            flaser(&[1.0], (0.0, 0.0, 0.0), 1.0),
            "ODOM 9 9 0 0 0 0 1.5 pippo 1.5\n".to_owned(),
            flaser(&[1.0], (0.5, 0.0, 0.0), 2.0),
            flaser(&[1.0], (0.5, 0.0, std::f64::consts::FRAC_PI_2), 3.0),
        ]
        .concat();
        let mut input = text.as_bytes();
        let mut q = std::collections::VecDeque::new();
        for _ in 0..3 {
            assert!(s.next_revolution(&mut input, None));
            s.drain_odometry(&mut |r| q.push_back(r));
        }
        // First scan: one sample; then turn–drive–turn a step (a pure turn: one).
        assert_eq!(q.len(), 1 + 3 + 1, "ODOM lines not used");
        assert_eq!(s.stats().odometry, 1);
        let mut f = perception::pose::PoseFilter::new(
            OdometryConfig::BURGER,
            perception::pose::HeadingConfig::default(),
            (0.0, 0.0),
        );
        let mut last = 0.0;
        for r in &q {
            f.encoders(r.left as i32, r.right as i32, (r.t - last) as f32);
            last = r.t;
        }
        let p = f.pose();
        assert!((p.x - 0.5).abs() < 1e-3 && p.y.abs() < 1e-3, "{p:?}");
        assert!(
            (p.theta - core::f32::consts::FRAC_PI_2).abs() < 1e-3,
            "{p:?}"
        );
        assert_eq!(q[3].t, 1.0, "the clock starts at the first stamp");
    }

    #[test]
    fn broken_and_overlong_lines_are_counted_and_skipped() {
        let mut s = stream();
        let long = "X".repeat(LINE_CAPACITY + 10);
        let text = format!(
            "FLASER 3 1 2\nODOM a b c\n{long}\n{}",
            flaser(&[1.0, 1.0, 1.0], (0.0, 0.0, 0.0), 1.0)
        );
        let mut input = text.as_bytes();
        assert!(s.next_revolution(&mut input, None));
        assert_eq!(s.stats().bad_lines, 3);
        assert_eq!(
            s.faults().bytes_skipped,
            ("FLASER 3 1 2\nODOM a b c\n".len() + long.len() + 1) as u64
        );
    }

    #[test]
    fn recognises_logs_by_their_first_line() {
        assert!(looks_like_carmen(b"# header\n\nPARAM x 1 0 h 0\n"));
        assert!(looks_like_carmen(b"FLASER 1 1.0 0 0 0 0 0 0 1 h 1\n"));
        assert!(!looks_like_carmen(&[0xFA, 0xA0, 0x10, 0x0B]));
        assert!(!looks_like_carmen(b"{\"t\": 0.1}\n"));
        assert_eq!(
            front_laser_offset(b"PARAM robot_frontlaser_offset -0.04 0 pippo 0\n"),
            Some(-0.04)
        );
    }
}
