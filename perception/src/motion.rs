//! Motion of one track: an alpha–beta filter on its observed centre (position and velocity in
//! the map frame) and the test that tells a walking person's legs from furniture. Furniture
//! does not walk: a piece that is carried away leaves its place (negative evidence) and shows up
//! elsewhere as a new track, while legs are seen frame after frame along a path. `no_std`.
//!
//! A track is *moving* once it is seen [`MotionConfig::moving_m`] from where it was seen
//! 1.5–2.5 s before, half of that in each half of that time (an observation is marked every
//! [`MARK_S`]), at a filtered speed of at least [`MotionConfig::min_speed`]. A walk keeps going; a
//! piece of furniture whose detected centre jumps once when the view changes (a desk's legs
//! hidden, a chair completed from its other side) does not. The decision is kept: a person who
//! stops is still a person. A track is *settled* — it may
//! be reported as furniture — once it has been seen for [`MotionConfig::settle_s`] and its
//! filtered speed has been below [`MotionConfig::still_speed`] in its last
//! [`MotionConfig::still_frames`] observations: legs are never reported in the frames before
//! their walk is recognised, nor at the first sight of a person who comes back into view (a
//! velocity reset after a gap reads zero; a person crossing a gap between furniture again and
//! again never stays in view the 1.5 s the walk test needs).

use crate::geometry::Point2;

/// Seconds between the marks of the filtered position the moving test looks back at.
pub const MARK_S: f64 = 0.5;

/// Marks kept (the oldest is 1.5–2 s old).
const MARKS: usize = 4;

/// Tuning of the motion filter.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotionConfig {
    /// Share of the innovation taken into the position (0–1).
    pub alpha: f32,
    /// Share of the innovation per second taken into the velocity (0–1).
    pub beta: f32,
    /// Distance gone in the last 1.5–2 s that makes a track moving, m (half of it in the last
    /// 0.5–1 s): more than a centre moves with the view (a chair's ≤ 0.3 m).
    pub moving_m: f32,
    /// Filtered speed a moving track must have, m/s.
    pub min_speed: f32,
    /// Observations before a track may be called moving.
    pub min_hits: u32,
    /// Fastest believable walk, m/s: the velocity is clamped to it.
    pub max_speed: f32,
    /// Longest gap between observations the velocity is carried over, s (beyond: reset).
    pub max_gap_s: f32,
    /// Time from the first observation before a track may be reported as furniture, s.
    pub settle_s: f32,
    /// Filtered speed below which a track may be reported as furniture, m/s.
    pub still_speed: f32,
    /// Observations in a row with a measured speed below [`MotionConfig::still_speed`] that
    /// it takes (the first after a gap has no measured speed).
    pub still_frames: u8,
}

impl Default for MotionConfig {
    fn default() -> Self {
        MotionConfig {
            alpha: 0.6,
            beta: 0.35,
            moving_m: 0.7,
            min_speed: 0.25,
            min_hits: 4,
            max_speed: 2.5,
            max_gap_s: 1.0,
            settle_s: 1.0,
            still_speed: 0.3,
            still_frames: 3,
        }
    }
}

/// The motion state of one track.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Motion {
    /// Filtered position, map frame, m.
    pub pos: Point2,
    /// Filtered velocity, map frame, m/s.
    pub vel: Point2,
    /// An observation every [`MARK_S`], newest first (observations, not the filtered
    /// position: a jump lands between two marks, not smeared across three).
    marks: [Point2; MARKS],
    /// Marks taken (at most [`MARKS`] count).
    n_marks: u8,
    /// Time of the newest mark, s.
    mark_s: f64,
    /// Time of the first observation, s.
    first_s: f64,
    /// Time of the last observation, s.
    stamp_s: f64,
    /// Observations taken.
    hits: u32,
    /// Observations in a row with a measured speed below [`MotionConfig::still_speed`].
    still_run: u8,
    /// Found to move (kept).
    pub moving: bool,
}

impl Motion {
    /// The state after a first observation at `z`, time `stamp_s`.
    pub fn new(z: Point2, stamp_s: f64) -> Self {
        Motion {
            pos: z,
            vel: Point2::new(0.0, 0.0),
            marks: [z; MARKS],
            n_marks: 1,
            mark_s: stamp_s,
            first_s: stamp_s,
            stamp_s,
            hits: 1,
            still_run: 0,
            moving: false,
        }
    }

    /// Where it is expected at `stamp_s` (the velocity carried forward; a gap over
    /// [`MotionConfig::max_gap_s`] or a non-finite time carries nothing).
    pub fn predict(&self, stamp_s: f64, cfg: &MotionConfig) -> Point2 {
        let dt = (stamp_s - self.stamp_s) as f32;
        if !(dt > 0.0 && dt.is_finite()) || dt > cfg.max_gap_s {
            return self.pos;
        }
        Point2::new(self.pos.x + self.vel.x * dt, self.pos.y + self.vel.y * dt)
    }

    /// Takes an observation at `z`, time `stamp_s`; `may_move`: whether what was seen can be
    /// legs (a desk's or a door frame's centre moves with the view; they never walk).
    pub fn observe(&mut self, z: Point2, stamp_s: f64, cfg: &MotionConfig, may_move: bool) {
        let dt = (stamp_s - self.stamp_s) as f32;
        if !(z.x.is_finite() && z.y.is_finite()) {
            return;
        }
        if !(dt > 1e-3 && dt.is_finite()) || dt > cfg.max_gap_s {
            // Same instant, time running backwards, or a long gap: position only.
            let a = cfg.alpha;
            self.pos = Point2::new(
                self.pos.x + a * (z.x - self.pos.x),
                self.pos.y + a * (z.y - self.pos.y),
            );
            self.vel = Point2::new(0.0, 0.0);
            self.still_run = 0;
        } else {
            let p = Point2::new(self.pos.x + self.vel.x * dt, self.pos.y + self.vel.y * dt);
            let r = Point2::new(z.x - p.x, z.y - p.y);
            self.pos = Point2::new(p.x + cfg.alpha * r.x, p.y + cfg.alpha * r.y);
            let k = cfg.beta / dt;
            let v = Point2::new(self.vel.x + k * r.x, self.vel.y + k * r.y);
            let speed = libm::sqrtf(v.x * v.x + v.y * v.y);
            let s = if speed > cfg.max_speed {
                cfg.max_speed / speed
            } else {
                1.0
            };
            self.vel = Point2::new(v.x * s, v.y * s);
            self.still_run = if self.speed() < cfg.still_speed {
                self.still_run.saturating_add(1)
            } else {
                0
            };
        }
        if stamp_s.is_finite() {
            self.stamp_s = stamp_s;
            if !self.first_s.is_finite() {
                self.first_s = stamp_s;
            }
        }
        self.hits = self.hits.saturating_add(1);
        if !(self.mark_s.is_finite() && stamp_s - self.mark_s < MARK_S) && stamp_s.is_finite() {
            self.marks.copy_within(0..MARKS - 1, 1);
            self.marks[0] = z;
            self.n_marks = self.n_marks.saturating_add(1);
            self.mark_s = stamp_s;
        }
        if may_move
            && !self.moving
            && self.hits >= cfg.min_hits
            && usize::from(self.n_marks) >= MARKS
            && z.distance(self.marks[MARKS - 1]) >= cfg.moving_m
            && self.marks[1].distance(self.marks[MARKS - 1]) >= 0.5 * cfg.moving_m
            && z.distance(self.marks[1]) >= 0.5 * cfg.moving_m
            && self.speed() >= cfg.min_speed
        {
            self.moving = true;
        }
    }

    /// Whether it may be reported as furniture: not moving, seen for long enough, still now.
    pub fn settled(&self, cfg: &MotionConfig) -> bool {
        !self.moving
            && self.age_s() >= cfg.settle_s
            && self.speed() < cfg.still_speed
            && self.still_run >= cfg.still_frames
    }

    /// Seconds from the first observation to the last.
    pub fn age_s(&self) -> f32 {
        (self.stamp_s - self.first_s) as f32
    }

    /// Filtered speed, m/s.
    pub fn speed(&self) -> f32 {
        libm::sqrtf(self.vel.x * self.vel.x + self.vel.y * self.vel.y)
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn a_walk_is_moving_with_its_velocity() {
        let cfg = MotionConfig::default();
        // 0.8 m/s along +x, 5 revolutions a second, the legs' midpoint jittering ±0.1 m.
        let mut m = Motion::new(Point2::new(0.0, 0.0), 0.0);
        for k in 1..=10 {
            let t = k as f64 * 0.2;
            let jitter = if k % 2 == 0 { 0.1 } else { -0.1 };
            m.observe(Point2::new(0.8 * t as f32 + jitter, 0.0), t, &cfg, true);
        }
        assert!(m.moving);
        assert!((m.vel.x - 0.8).abs() < 0.3, "vx {}", m.vel.x);
        assert!(m.vel.y.abs() < 0.1);
        let ahead = m.predict(2.2, &cfg);
        assert!(ahead.x > m.pos.x);
    }

    #[test]
    fn furniture_seen_from_changing_sides_is_not_moving() {
        let cfg = MotionConfig::default();
        // A chair whose detected centre wanders ±0.25 m as the view changes, for 30 s.
        let mut m = Motion::new(Point2::new(2.0, 1.0), 0.0);
        for k in 1..150 {
            let t = k as f64 * 0.2;
            let a = k as f32 * 0.7;
            let z = Point2::new(2.0 + 0.25 * libm::sinf(a), 1.0 + 0.25 * libm::cosf(1.3 * a));
            m.observe(z, t, &cfg, true);
        }
        assert!(!m.moving);
        assert!(m.pos.distance(Point2::new(2.0, 1.0)) < 0.3);
    }

    #[test]
    fn a_person_crossing_a_gap_again_and_again_never_settles() {
        let cfg = MotionConfig::default();
        // Legs seen only while crossing a 0.8 m gap between furniture at 0.8 m/s (1 s, five
        // revolutions), back 2 s later the other way: never 1.5 s in view, so never `moving`;
        // and never still either.
        let mut m = Motion::new(Point2::new(0.0, 0.0), 0.0);
        let mut t = 0.0;
        for pass in 0..8 {
            let dir = if pass % 2 == 0 { 1.0 } else { -1.0 };
            for k in 0..5 {
                let x = if dir > 0.0 {
                    0.16 * k as f32
                } else {
                    0.8 - 0.16 * k as f32
                };
                if pass > 0 || k > 0 {
                    m.observe(Point2::new(x, 0.0), t, &cfg, true);
                }
                assert!(!m.settled(&cfg), "pass {pass} step {k}");
                t += 0.2;
            }
            t += 2.0;
        }
        // Furniture seen in the same rhythm (in view 1 s, hidden 2 s) settles.
        let mut m = Motion::new(Point2::new(0.0, 0.0), 0.0);
        let mut t = 0.0;
        for _ in 0..3 {
            for k in 0..5 {
                let jitter = if k % 2 == 0 { 0.03 } else { -0.03 };
                m.observe(Point2::new(jitter, 0.0), t, &cfg, true);
                t += 0.2;
            }
            t += 2.0;
        }
        assert!(m.settled(&cfg));
    }

    #[test]
    fn a_centre_that_jumps_once_is_not_moving() {
        let cfg = MotionConfig::default();
        // A desk-sized jump of 0.9 m when the view changes, then still again.
        let mut m = Motion::new(Point2::new(0.0, 0.0), 0.0);
        for k in 1..40 {
            let x = if k < 12 { 0.0 } else { 0.9 };
            m.observe(Point2::new(x, 0.0), k as f64 * 0.2, &cfg, true);
            assert!(!m.moving, "observation {k}");
        }
    }

    #[test]
    fn bad_times_and_points_change_nothing_wild() {
        let cfg = MotionConfig::default();
        let mut m = Motion::new(Point2::new(0.0, 0.0), 5.0);
        m.observe(Point2::new(f32::NAN, 1.0), 5.2, &cfg, true);
        assert_eq!(m.pos, Point2::new(0.0, 0.0));
        m.observe(Point2::new(0.1, 0.0), f64::NAN, &cfg, true);
        m.observe(Point2::new(0.2, 0.0), 4.0, &cfg, true); // time running backwards
        assert!(m.pos.x.is_finite() && m.vel.x == 0.0);
        // A jump of 100 m in 0.2 s: the velocity is clamped to a walk.
        m.observe(Point2::new(100.0, 0.0), 5.4, &cfg, true);
        assert!(m.speed() <= cfg.max_speed + 1e-3);
        assert_eq!(m.predict(f64::NAN, &cfg), m.pos);
    }
}
