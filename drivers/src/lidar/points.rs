//! Native-angle points → [`Revolution`]s, for the models whose beams do not fall on whole
//! degrees (LDROBOT, RPLIDAR).
//!
//! A model's decoder hands over each point already in our convention (counter-clockwise
//! degrees, metres, sensor-clock seconds) and says where a new sweep begins (the LDROBOT angle
//! wrap, the RPLIDAR start flag). [`PointAssembler`] then:
//!
//! * bins every point to the **nearest whole degree**, `d = round(φ) mod 360`, so bin `d`
//!   covers [d − 0.5°, d + 0.5°): 360 bins whatever the native count, no duplicate 360°;
//! * lets the **closest valid return win** a bin; a no-return (range 0) or out-of-window
//!   reading is kept only while the bin has nothing better, so "no return" means none of the
//!   beams that fell in the bin returned;
//! * stamps the revolution at its **first point's** sensor time and takes its period from the
//!   next sweep's first point (or from the model's speed field when the sweep is cut short);
//! * marks each 6° sector (sweep order, by the sweep's own angle before any geometry
//!   correction) that got a point; sectors the sweep passed without data are counted missing,
//!   as lost LDS-01 packets are;
//! * hands out a partial revolution after a host-clock silence ([`PointAssembler::poll`]: a
//!   live sensor that stalls), but not the lead-in before the stream's first sweep start nor an
//!   unfinished revolution at the end of a stream ([`PointAssembler::flush`]): both are
//!   dropped and counted ([`PointStats::partial_dropped`]), so no frame reports a made-up rpm.
//!
//! Storage: two [`Revolution`]s, swapped without copying, as in the LDS-01 assembler.

use super::revolution::{BINS, EMPTY_READINGS, Reading, Revolution, SECTORS, bin_angle_rad};

/// Range window and staleness of a point-based model.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointConfig {
    /// Shortest range counted valid, metres.
    pub min_range_m: f32,
    /// Longest range counted valid, metres.
    pub max_range_m: f32,
    /// Host-clock silence after which a partial revolution is handed out, µs.
    pub stale_after_us: u64,
}

/// One point in our convention.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Point {
    /// Counter-clockwise angle from the LiDAR's forward axis, degrees, any value (wrapped).
    pub angle_deg: f32,
    /// Where the sweep was when the point was measured (counter-clockwise degrees, before any
    /// geometry correction of the model, e.g. the LDS-02's triangulation shift): the sector
    /// accounting follows the sweep, so a corrected point moved across a sector boundary does
    /// not leave its sector looking lost. Equal to `angle_deg` for models without correction.
    pub sweep_deg: f32,
    /// Range in metres (0 = no return).
    pub range_m: f32,
    /// Return strength as sent.
    pub intensity: u16,
    /// Sensor-clock time of the point, seconds.
    pub t_s: f64,
}

/// Counters kept by the point assembler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointStats {
    /// Revolutions handed out.
    pub revolutions: u64,
    /// Revolutions handed out with sectors missing.
    pub incomplete_revolutions: u64,
    /// Sectors missing from the revolutions handed out.
    pub missing_sectors: u64,
    /// Points received.
    pub points: u64,
    /// Partial revolutions not handed out: the lead-in before the first sweep start (the
    /// stream began mid-sweep) and an unfinished last one at the end of the stream.
    pub partial_dropped: u64,
}

/// The assembler; see the module docs.
#[derive(Debug, Clone)]
pub struct PointAssembler {
    cfg: PointConfig,
    bufs: [Revolution; 2],
    filling: usize,
    in_progress: bool,
    /// The revolution being filled began mid-sweep at the start of the stream (a lead-in).
    lead_in: bool,
    /// A revolution has been started since the stream began.
    started: bool,
    /// Sensor time of the last point put in.
    t_last: f64,
    last_host_us: Option<u64>,
    next_seq: u32,
    stats: PointStats,
}

/// Bin of a counter-clockwise angle in degrees (nearest whole degree, wrapped).
#[inline]
pub fn bin_of(angle_deg: f32) -> usize {
    let a = libm::roundf(angle_deg);
    let a = if a.is_finite() { a } else { 0.0 };
    (a as i64).rem_euclid(BINS as i64) as usize
}

impl PointAssembler {
    /// A new assembler.
    pub fn new(cfg: PointConfig) -> Self {
        PointAssembler {
            cfg,
            bufs: [Revolution::empty(), Revolution::empty()],
            filling: 0,
            in_progress: false,
            lead_in: false,
            started: false,
            t_last: 0.0,
            last_host_us: None,
            next_seq: 0,
            stats: PointStats::default(),
        }
    }

    /// Settings in force.
    pub fn config(&self) -> &PointConfig {
        &self.cfg
    }

    /// Counters.
    pub fn stats(&self) -> &PointStats {
        &self.stats
    }

    /// The last revolution handed out.
    pub fn last(&self) -> Option<&Revolution> {
        (self.stats.revolutions > 0).then(|| &self.bufs[1 - self.filling])
    }

    /// Sensor time of the latest point, seconds.
    pub fn sensor_time_s(&self) -> f64 {
        self.t_last
    }

    /// Adds one point. `new_sweep` says the sensor started a new revolution with this point.
    /// `nominal_period_s` is the period the model's own speed says (used when a revolution
    /// is cut short). Returns `true` if a revolution was finished (read it with
    /// [`PointAssembler::last`]); the point then starts the next one.
    pub fn push(
        &mut self,
        p: &Point,
        new_sweep: bool,
        nominal_period_s: f32,
        host_us: Option<u64>,
    ) -> bool {
        let mut finished = false;
        if self.in_progress {
            let stale = match (host_us, self.last_host_us) {
                (Some(now), Some(last)) => now.saturating_sub(last) > self.cfg.stale_after_us,
                _ => false,
            };
            if new_sweep && !stale && self.lead_in && !self.bufs[self.filling].is_complete() {
                // The stream began mid-sweep: the part before the first sweep start is no
                // revolution (its rpm would be made up); dropped and counted. (A stream that
                // began at a sweep start without saying so has a whole first sweep: kept.)
                self.stats.partial_dropped += 1;
                self.in_progress = false;
            } else if new_sweep || stale {
                let period = if new_sweep && !stale {
                    (p.t_s - self.bufs[self.filling].t_start_s) as f32
                } else {
                    nominal_period_s
                };
                self.finish(period);
                finished = true;
            }
        }
        if !self.in_progress {
            self.lead_in = !self.started && !new_sweep;
            self.started = true;
            self.start(p, host_us);
        }
        self.put(p);
        self.t_last = p.t_s;
        self.last_host_us = host_us.or(self.last_host_us);
        self.stats.points += 1;
        finished
    }

    /// Hands out the revolution being filled if the host clock shows it went stale.
    pub fn poll(&mut self, now_us: u64, nominal_period_s: f32) -> Option<&Revolution> {
        let stale = self.in_progress
            && self
                .last_host_us
                .is_some_and(|last| now_us.saturating_sub(last) > self.cfg.stale_after_us);
        if stale {
            self.finish(nominal_period_s);
            self.last()
        } else {
            None
        }
    }

    /// Hands out the revolution being filled, whatever its coverage: for a source whose scans
    /// are whole as they come (a log's 180° scan), not for a cut-off sweep.
    pub fn hand_out(&mut self, period_s: f32) -> Option<&Revolution> {
        if self.in_progress {
            self.finish(period_s);
            self.last()
        } else {
            None
        }
    }

    /// End of stream: hands out the revolution being filled if the sweep got all round
    /// (every sector has data); an unfinished one is dropped and counted
    /// ([`PointStats::partial_dropped`]), not made into a frame.
    pub fn flush(&mut self, nominal_period_s: f32) -> Option<&Revolution> {
        if !self.in_progress {
            return None;
        }
        if self.bufs[self.filling].is_complete() {
            self.finish(nominal_period_s);
            self.last()
        } else {
            self.stats.partial_dropped += 1;
            self.in_progress = false;
            None
        }
    }

    fn start(&mut self, p: &Point, host_us: Option<u64>) {
        let rev = &mut self.bufs[self.filling];
        rev.readings = EMPTY_READINGS;
        rev.seq = self.next_seq;
        rev.t_start_s = p.t_s;
        rev.host_time_us = host_us;
        rev.packets = 0;
        rev.present = 0;
        rev.bad_checksum_packets = 0;
        rev.sweep_start_bin = bin_of(p.sweep_deg) as u16;
        self.next_seq = self.next_seq.wrapping_add(1);
        self.in_progress = true;
    }

    fn put(&mut self, p: &Point) {
        let d = bin_of(p.angle_deg);
        let (min, max) = (self.cfg.min_range_m, self.cfg.max_range_m);
        let rev = &mut self.bufs[self.filling];
        let valid = p.range_m > 0.0 && p.range_m >= min && p.range_m <= max;
        let old = rev.readings[d];
        let old_seen = old.range_m > 0.0 || old.intensity > 0 || old.valid;
        let wins = match (valid, old.valid) {
            (true, true) => p.range_m < old.range_m,
            (true, false) => true,
            (false, true) => false,
            // Neither valid: keep a measured (out-of-window) range over a no-return.
            (false, false) => !old_seen || (p.range_m > 0.0 && old.range_m == 0.0),
        };
        if wins {
            rev.readings[d] = Reading {
                angle_rad: bin_angle_rad(d),
                range_m: p.range_m,
                intensity: p.intensity,
                valid,
            };
        }
        let k = rev.sector_of(bin_of(p.sweep_deg));
        if rev.present & (1 << k) == 0 {
            rev.present |= 1 << k;
            rev.packets += 1;
        }
    }

    fn finish(&mut self, period_s: f32) {
        let rev = &mut self.bufs[self.filling];
        let period = if period_s.is_finite() && period_s > 0.0 {
            period_s
        } else {
            0.2
        };
        rev.period_s = period;
        rev.rpm = 60.0 / period;
        self.stats.revolutions += 1;
        if !rev.is_complete() {
            self.stats.incomplete_revolutions += 1;
            self.stats.missing_sectors += u64::from(SECTORS as u8 - rev.packets);
        }
        self.in_progress = false;
        self.filling = 1 - self.filling;
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn cfg() -> PointConfig {
        PointConfig {
            min_range_m: 0.1,
            max_range_m: 10.0,
            stale_after_us: 500_000,
        }
    }

    fn sweep(a: &mut PointAssembler, n: usize, t0: f64, range: impl Fn(usize) -> f32) -> bool {
        let mut done = false;
        for i in 0..n {
            // Clockwise from 0°: φ = 360 − 360·i/n.
            let p = Point {
                angle_deg: 360.0 - 360.0 * i as f32 / n as f32,
                sweep_deg: 360.0 - 360.0 * i as f32 / n as f32,
                range_m: range(i),
                intensity: 10,
                t_s: t0 + 0.2 * i as f64 / n as f64,
            };
            done |= a.push(&p, i == 0, 0.2, None);
        }
        done
    }

    #[test]
    fn any_native_count_gives_360_bins_and_a_full_revolution() {
        for n in [400usize, 455, 460, 900] {
            let mut a = PointAssembler::new(cfg());
            assert!(!sweep(&mut a, n, 0.0, |_| 1.0));
            assert!(sweep(&mut a, n, 0.2, |_| 1.0));
            let rev = a.last().unwrap();
            assert_eq!(rev.readings.len(), 360);
            assert_eq!(rev.valid_count(), 360, "n = {n}");
            assert!(rev.is_complete());
            assert!((rev.period_s - 0.2).abs() < 1e-4);
            assert_eq!(rev.sweep_start_bin, 0);
            assert_eq!(rev.t_start_s, 0.0);
        }
    }

    #[test]
    fn closest_return_wins_and_no_return_never_beats_a_return() {
        let mut a = PointAssembler::new(cfg());
        let mut push = |deg: f32, r: f32, new_sweep: bool| {
            a.push(
                &Point {
                    angle_deg: deg,
                    sweep_deg: deg,
                    range_m: r,
                    intensity: 1,
                    t_s: 0.0,
                },
                new_sweep,
                0.2,
                None,
            )
        };
        push(10.2, 2.0, true);
        push(9.8, 1.5, false);
        push(10.4, 0.0, false);
        push(10.1, 3.0, false);
        // The next sweep's first point hands the revolution out.
        assert!(push(0.0, 1.0, true));
        let rev = a.last().unwrap();
        assert_eq!(rev.readings[10].range_m, 1.5);
        assert!(rev.readings[10].valid);
    }

    #[test]
    fn a_gap_in_the_sweep_is_counted_missing() {
        let mut a = PointAssembler::new(cfg());
        sweep(&mut a, 460, 0.0, |_| 1.0);
        // Second sweep loses points 100..160 (about 47°, 7 or 8 sectors).
        for i in 0..460usize {
            if (100..160).contains(&i) {
                continue;
            }
            let p = Point {
                angle_deg: 360.0 - 360.0 * i as f32 / 460.0,
                sweep_deg: 360.0 - 360.0 * i as f32 / 460.0,
                range_m: 1.0,
                intensity: 1,
                t_s: 0.2 + 0.2 * i as f64 / 460.0,
            };
            a.push(&p, i == 0, 0.2, None);
        }
        // The third sweep's first point hands the second revolution out.
        let p = Point {
            angle_deg: 0.0,
            sweep_deg: 0.0,
            range_m: 1.0,
            intensity: 1,
            t_s: 0.4,
        };
        assert!(a.push(&p, true, 0.2, None));
        let rev = a.last().unwrap();
        assert!(!rev.is_complete());
        let missing = rev.missing_packets();
        assert!((6..=8).contains(&missing), "{missing}");
        assert_eq!(a.stats().missing_sectors, u64::from(missing));
    }

    #[test]
    fn a_lead_in_and_an_unfinished_end_are_not_frames() {
        let mut a = PointAssembler::new(cfg());
        // The stream starts a third of the way round: no sweep start yet.
        for i in 150..460usize {
            let deg = 360.0 - 360.0 * i as f32 / 460.0;
            let p = Point {
                angle_deg: deg,
                sweep_deg: deg,
                range_m: 1.0,
                intensity: 1,
                t_s: 0.2 * i as f64 / 460.0,
            };
            assert!(!a.push(&p, false, 0.2, None));
        }
        // One whole sweep, then half of the next: one frame, both partial ends dropped.
        assert!(!sweep(&mut a, 460, 0.2, |_| 1.0), "the lead-in is no frame");
        assert_eq!(a.stats().partial_dropped, 1);
        let mut frames = 0;
        for i in 0..230usize {
            let deg = 360.0 - 360.0 * i as f32 / 460.0;
            let p = Point {
                angle_deg: deg,
                sweep_deg: deg,
                range_m: 1.0,
                intensity: 1,
                t_s: 0.4 + 0.2 * i as f64 / 460.0,
            };
            frames += usize::from(a.push(&p, i == 0, 0.2, None));
        }
        assert_eq!(frames, 1, "the whole sweep is handed out");
        let rev = a.last().unwrap();
        assert!(rev.is_complete());
        assert!((rev.rpm - 300.0).abs() < 1.0, "{}", rev.rpm);
        assert!(
            a.flush(0.2).is_none(),
            "half a sweep at the end is no frame"
        );
        assert_eq!(a.stats().partial_dropped, 2);
        assert_eq!(a.stats().revolutions, 1);
        assert_eq!(a.stats().missing_sectors, 0);
    }

    #[test]
    fn corrected_points_keep_their_sweep_sector() {
        // A geometry correction (the LDS-02's) moves returns up to ~7° against the sweep while
        // no-returns stay: the sectors follow the sweep, so nothing looks lost.
        let mut a = PointAssembler::new(cfg());
        let mut frames = 0;
        for rev in 0..3usize {
            for i in 0..460usize {
                let sweep_deg = 360.0 - 360.0 * i as f32 / 460.0;
                let returned = (i / 40) % 2 == 0;
                let p = Point {
                    angle_deg: if returned { sweep_deg + 6.8 } else { sweep_deg },
                    sweep_deg,
                    range_m: if returned { 2.0 } else { 0.0 },
                    intensity: 1,
                    t_s: 0.2 * (rev as f64 + i as f64 / 460.0),
                };
                frames += usize::from(a.push(&p, i == 0, 0.2, None));
            }
        }
        assert_eq!(frames, 2);
        assert_eq!(a.stats().missing_sectors, 0);
        assert_eq!(a.stats().incomplete_revolutions, 0);
    }

    #[test]
    fn bin_of_wraps_and_survives_nan() {
        assert_eq!(bin_of(359.6), 0);
        assert_eq!(bin_of(-0.4), 0);
        assert_eq!(bin_of(-1.0), 359);
        assert_eq!(bin_of(720.0), 0);
        assert_eq!(bin_of(f32::NAN), 0);
        assert_eq!(bin_of(f32::INFINITY), 0);
    }
}
