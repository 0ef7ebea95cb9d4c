//! The global point cloud of Method A: a fixed-capacity ring (`heapless::Deque`) of map-frame
//! points that every
//! revolution feeds and ages.
//!
//! Each revolution first drops the oldest [`CloudConfig::drop_fraction`] of the points (5 % by
//! default, rounded down), then appends its own returns transformed by the pose. With `n`
//! returns a revolution the cloud settles where the drop equals the inflow, `n / fraction`
//! points: 7,200 at 360 returns and 5 %. [`CLOUD_CAPACITY`] leaves room above that (7,200 +
//! the 360 of the newest revolution, and a lower drop fraction); when the ring is full anyway,
//! a new point overwrites the oldest and [`GlobalCloud::overwritten`] counts it, so the cloud
//! degrades into a shorter memory, never into an error.
//!
//! Points that are not finite are refused and counted ([`GlobalCloud::rejected`]): NaN and
//! infinite ranges must be filtered upstream, and this is the guard if they are not.
//!
//! **Seen through.** Aging alone keeps a thing that was taken away in the cloud for seconds
//! (half the points of a box are still there 13 revolutions later, enough for DBSCAN), so
//! Method A would go on reporting it. Before aging, a revolution forgets every point its rays
//! have passed through ([`GlobalCloud::clear_seen_through`]): the rays on both sides of the
//! point's bearing, and the one beyond each, all returned from farther than the point by a
//! margin. Any surface through the point, however grazing, would have stopped one of the two
//! rays that bracket it short of that, so a wall seen at a glancing angle keeps its points; a
//! bin with no return says nothing (dark surfaces drop out) unless
//! [`CloudConfig::clear_beyond_rays`] is set below 4.

use heapless::Deque;

use crate::geometry::{Point2, Pose2};

/// Points the cloud holds at most (see the module docs for the sizing).
pub const CLOUD_CAPACITY: usize = 8192;

/// Cloud settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CloudConfig {
    /// Fraction of the points dropped (oldest first) at the start of every revolution.
    pub drop_fraction: f32,
    /// Shortest range kept, metres (the LDS-01's blind zone is 0.12 m).
    pub range_min_m: f32,
    /// Longest range kept, metres (the LDS-01 is specified to 3.5 m).
    pub range_max_m: f32,
    /// A point is forgotten when the rays around its bearing all return from farther than
    /// it by this plus 3 % of its range, metres ([`GlobalCloud::clear_seen_through`]); 0: never.
    pub clear_margin_m: f32,
    /// Of the four rays around a point's bearing, how many must have returned from beyond it
    /// for it to be forgotten ([`GlobalCloud::clear_seen_through`]); the others may have
    /// returned nothing. 4: a ray that returned nothing says nothing. Below 4, a walking
    /// person's legs seen in front of a doorway or of open space past the range are
    /// forgotten once the person has gone (otherwise they are only aged, and leave a trail
    /// Method A clusters into furniture), but so are the returns a legged chair far off
    /// gathers over many revolutions where its legs drop out: 4 by default (`docs/world.md`,
    /// 44th session, measured 1–3).
    pub clear_beyond_rays: u8,
}

impl Default for CloudConfig {
    fn default() -> Self {
        CloudConfig {
            drop_fraction: 0.05,
            range_min_m: 0.12,
            range_max_m: 3.5,
            clear_margin_m: 0.15,
            clear_beyond_rays: 4,
        }
    }
}

/// One revolution to add: ranges by 1° bin (bin `d` at `d`° counter-clockwise from the
/// sensor's forward axis, 0 = no return), with the robot's pose at the first and last ray.
///
/// The LDS-01 sweeps clockwise: raw reading `i` is bin `359 − i`, taken at fraction `i / 360`
/// of the revolution, so bin `d` is placed with the pose interpolated at `(359 − d) / 360`
/// between `start` and `end`. A turning robot's scan is de-skewed this way.
#[derive(Debug, Clone, Copy)]
pub struct Scan<'a> {
    /// Ranges by bin, metres.
    pub ranges: &'a [f32],
    /// Robot pose (map frame) at the first ray.
    pub start: Pose2,
    /// Robot pose (map frame) at the last ray.
    pub end: Pose2,
    /// The LiDAR's pose on the robot.
    pub mount: Pose2,
}

impl Scan<'_> {
    /// The LiDAR's pose (map frame) when bin `d` was read.
    pub fn lidar_at(&self, d: usize) -> Pose2 {
        let n = self.ranges.len().max(1);
        let u = (n - 1 - d.min(n - 1)) as f32 / n as f32;
        crate::sweep::Sweep {
            start: self.start,
            end: self.end,
            mount: self.mount,
        }
        .lidar_at_fraction(u)
    }
}

/// The cloud: a `heapless::Deque` (the bound is in the type), oldest point at the front.
#[derive(Clone)]
pub struct GlobalCloud {
    pts: Deque<Point2, CLOUD_CAPACITY>,
    overwritten: u64,
    rejected: u64,
    cleared: u64,
}

/// Share of a point's range added to [`CloudConfig::clear_margin_m`] (the LDS-01's range
/// noise is 1–3.5 % of the range).
const CLEAR_MARGIN_FRACTION: f32 = 0.03;

impl Default for GlobalCloud {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Debug for GlobalCloud {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("GlobalCloud")
            .field("len", &self.pts.len())
            .field("overwritten", &self.overwritten)
            .field("rejected", &self.rejected)
            .field("cleared", &self.cleared)
            .finish()
    }
}

impl GlobalCloud {
    /// An empty cloud.
    pub const fn new() -> Self {
        GlobalCloud {
            pts: Deque::new(),
            overwritten: 0,
            rejected: 0,
            cleared: 0,
        }
    }

    /// Points held.
    pub fn len(&self) -> usize {
        self.pts.len()
    }

    /// `true` when empty.
    pub fn is_empty(&self) -> bool {
        self.pts.is_empty()
    }

    /// Points overwritten because the ring was full.
    pub fn overwritten(&self) -> u64 {
        self.overwritten
    }

    /// Points refused because a coordinate was not finite.
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Points forgotten because a revolution's rays passed through them.
    pub fn cleared(&self) -> u64 {
        self.cleared
    }

    /// Forgets every point (counters are kept).
    pub fn clear(&mut self) {
        self.pts.clear();
    }

    /// Drops the oldest `floor(len · fraction)` points; returns how many went.
    pub fn age(&mut self, fraction: f32) -> usize {
        let f = if fraction.is_finite() {
            fraction.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let len = self.pts.len();
        let n = ((len as f32 * f) as usize).min(len);
        for _ in 0..n {
            self.pts.pop_front();
        }
        n
    }

    /// Appends a point, overwriting the oldest when full. Returns `false` (and counts it) if
    /// the point is not finite.
    pub fn push(&mut self, p: Point2) -> bool {
        if !(p.x.is_finite() && p.y.is_finite()) {
            self.rejected += 1;
            return false;
        }
        if self.pts.is_full() {
            self.pts.pop_front();
            self.overwritten += 1;
        }
        // Room was just made: the push cannot fail.
        let _ = self.pts.push_back(p);
        true
    }

    /// Forgets the points `scan`'s rays passed through (module docs), with `margin_m` the
    /// fixed part of the margin; returns how many went. Each point is looked at from the
    /// LiDAR's pose at the instant its bin was read, found in two steps: the bin from the
    /// revolution's middle, then from that bin's own instant. The second step moves the view
    /// by the LiDAR's motion between the two instants, taken as linear in time within one
    /// revolution (as `add_scan` de-skews), so each point costs two `atan2`, one `sincos` of
    /// that small turn and one square root, not a pose composition.
    ///
    /// At least `beyond_rays` of the four (clamped to 1–4) must have returned from beyond the
    /// point, and the others nothing: open space past the range (a doorway, a large room)
    /// returns nothing, and a surface at the point, however dark, would have stopped the rays
    /// that returned from beyond.
    pub fn clear_seen_through(&mut self, scan: &Scan<'_>, margin_m: f32, beyond_rays: u8) -> usize {
        let beyond_rays = usize::from(beyond_rays.clamp(1, 4));
        let n = scan.ranges.len();
        if n < 4 || margin_m.is_nan() || margin_m <= 0.0 {
            return 0;
        }
        let step = core::f32::consts::TAU / n as f32;
        // Bin `d` is read at u = (n − 1 − d) / n of the revolution.
        let u_of = |d: usize| (n - 1 - d.min(n - 1)) as f32 / n as f32;
        let (d_mid, d_first, d_last) = (n / 2, n - 1, 0);
        let mid = scan.lidar_at(d_mid).inverse();
        // The LiDAR's position at the revolution's first and last ray, in the middle's frame.
        let xy = |q: Pose2| Point2::new(q.x, q.y);
        let first = mid.transform(xy(scan.lidar_at(d_first)));
        let last = mid.transform(xy(scan.lidar_at(d_last)));
        let (u_mid, u_last) = (u_of(d_mid), u_of(d_last));
        let dtheta = crate::geometry::wrap_angle(scan.end.theta - scan.start.theta);
        let bins_of = |x: f32, y: f32| {
            let a = libm::atan2f(y, x);
            let a = if a < 0.0 {
                a + core::f32::consts::TAU
            } else {
                a
            };
            a / step
        };
        let seen_through = |p: Point2| {
            let l = mid.transform(p);
            let d = bins_of(l.x, l.y);
            if !d.is_finite() {
                return false;
            }
            // Where the LiDAR was, and how far it had turned, when bin `d` was read.
            let u = u_of(d as usize);
            let k = u / u_last;
            let at = Point2::new(
                first.x + (last.x - first.x) * k,
                first.y + (last.y - first.y) * k,
            );
            let turn = dtheta * (u - u_mid);
            let (s, c) = (libm::sinf(turn), libm::cosf(turn));
            let (vx, vy) = (l.x - at.x, l.y - at.y);
            let (x, y) = (c * vx + s * vy, c * vy - s * vx);
            let bins = bins_of(x, y);
            let rho = libm::sqrtf(x * x + y * y);
            if !(bins.is_finite() && rho.is_finite()) {
                return false;
            }
            let beyond = rho + margin_m + CLEAR_MARGIN_FRACTION * rho;
            let first_bin = libm::floorf(bins) as usize + n - 1;
            let mut past = 0;
            let all = (first_bin..first_bin + 4).all(|d| {
                let r = scan.ranges[d % n];
                let past_it = r.is_finite() && r > beyond;
                past += usize::from(past_it);
                past_it || r == 0.0
            });
            all && past >= beyond_rays
        };
        let len = self.pts.len();
        let mut cleared = 0;
        for _ in 0..len {
            let Some(p) = self.pts.pop_front() else {
                break;
            };
            if seen_through(p) {
                cleared += 1;
            } else {
                // One was just popped: room for it.
                let _ = self.pts.push_back(p);
            }
        }
        self.cleared += cleared as u64;
        cleared
    }

    /// Forgets what `scan` saw through (if [`CloudConfig::clear_margin_m`] is above 0), ages
    /// the cloud by one revolution and adds `scan`'s returns within the configured range
    /// window; returns how many were added. Non-finite ranges are refused and counted.
    pub fn add_scan(&mut self, scan: &Scan<'_>, cfg: &CloudConfig) -> usize {
        self.clear_seen_through(scan, cfg.clear_margin_m, cfg.clear_beyond_rays);
        self.age(cfg.drop_fraction);
        let n = scan.ranges.len();
        if n == 0 {
            return 0;
        }
        let step = core::f32::consts::TAU / n as f32;
        let mut added = 0;
        for (d, &r) in scan.ranges.iter().enumerate() {
            if !r.is_finite() {
                self.rejected += 1;
                continue;
            }
            if r < cfg.range_min_m || r > cfg.range_max_m {
                continue;
            }
            let lidar = scan.lidar_at(d);
            let local = Point2::from_polar(r, d as f32 * step);
            if self.push(lidar.transform(local)) {
                added += 1;
            }
        }
        added
    }

    /// The points, oldest first, as two slices (the ring's two halves).
    pub fn as_slices(&self) -> (&[Point2], &[Point2]) {
        self.pts.as_slices()
    }

    /// Every point, oldest first.
    pub fn iter(&self) -> impl Iterator<Item = &Point2> + '_ {
        let (a, b) = self.as_slices();
        a.iter().chain(b.iter())
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn scan_of(r: f32) -> [f32; 360] {
        [r; 360]
    }

    #[test]
    fn settles_near_inflow_over_fraction() {
        let mut c = GlobalCloud::new();
        let ranges = scan_of(2.0);
        let scan = Scan {
            ranges: &ranges,
            start: Pose2::IDENTITY,
            end: Pose2::IDENTITY,
            mount: Pose2::IDENTITY,
        };
        for _ in 0..400 {
            c.add_scan(&scan, &CloudConfig::default());
        }
        // Equilibrium: after the drop 6,840–7,200 remain, plus 360 new.
        assert!((7_100..=7_560).contains(&c.len()), "{}", c.len());
        assert_eq!(c.overwritten(), 0);
    }

    #[test]
    fn full_ring_overwrites_oldest() {
        let mut c = GlobalCloud::new();
        for i in 0..CLOUD_CAPACITY + 10 {
            assert!(c.push(Point2::new(i as f32, 0.0)));
        }
        assert_eq!(c.len(), CLOUD_CAPACITY);
        assert_eq!(c.overwritten(), 10);
        assert_eq!(c.iter().next().unwrap().x, 10.0);
        assert_eq!(c.iter().last().unwrap().x, (CLOUD_CAPACITY + 9) as f32);
    }

    #[test]
    fn non_finite_refused() {
        let mut c = GlobalCloud::new();
        assert!(!c.push(Point2::new(f32::NAN, 0.0)));
        assert!(!c.push(Point2::new(0.0, f32::INFINITY)));
        let mut ranges = scan_of(0.0);
        ranges[10] = f32::NAN;
        ranges[11] = f32::INFINITY;
        ranges[12] = 1.0;
        let added = c.add_scan(
            &Scan {
                ranges: &ranges,
                start: Pose2::IDENTITY,
                end: Pose2::IDENTITY,
                mount: Pose2::IDENTITY,
            },
            &CloudConfig::default(),
        );
        assert_eq!(added, 1);
        assert_eq!(c.rejected(), 4);
        assert!(c.age(f32::NAN) == 0 && c.len() == 1);
    }

    fn still(ranges: &[f32], at: Pose2) -> Scan<'_> {
        Scan {
            ranges,
            start: at,
            end: at,
            mount: Pose2::IDENTITY,
        }
    }

    /// A box 1 m ahead (bins 355..=5) in a room whose walls are 3 m away.
    fn with_box() -> [f32; 360] {
        let mut r = scan_of(3.0);
        for d in (355..360).chain(0..6) {
            r[d] = 1.0;
        }
        r
    }

    #[test]
    fn a_thing_taken_away_is_forgotten_at_once() {
        let mut c = GlobalCloud::new();
        let cfg = CloudConfig::default();
        let boxed = with_box();
        for _ in 0..20 {
            c.add_scan(&still(&boxed, Pose2::IDENTITY), &cfg);
        }
        let near = |c: &GlobalCloud| c.iter().filter(|p| p.norm() < 1.5).count();
        assert!(near(&c) > 100);
        // Taken away: the rays now reach the wall behind.
        let empty = scan_of(3.0);
        c.add_scan(&still(&empty, Pose2::IDENTITY), &cfg);
        assert_eq!(near(&c), 0);
        assert!(c.cleared() > 100);
        // Aging alone (clearing off) keeps most of them.
        let mut aged = GlobalCloud::new();
        let off = CloudConfig {
            clear_margin_m: 0.0,
            ..cfg
        };
        for _ in 0..20 {
            aged.add_scan(&still(&boxed, Pose2::IDENTITY), &off);
        }
        aged.add_scan(&still(&empty, Pose2::IDENTITY), &off);
        assert!(near(&aged) > 100);
    }

    #[test]
    fn a_turning_robot_clears_only_what_is_gone() {
        // The robot turns 0.6 rad and drifts 5 cm during each revolution: a box 1 m ahead (in
        // the map) and walls 3 m away, scanned de-skewed.
        let cfg = CloudConfig::default();
        let mount = Pose2::new(-0.032, 0.0, 0.0);
        let rev = |k: usize| {
            let a = 0.6 * k as f32;
            (
                Pose2::new(0.05 * k as f32, 0.0, a),
                Pose2::new(0.05 * (k + 1) as f32, 0.0, a + 0.6),
            )
        };
        // Ranges of a revolution from `start` to `end`: the box (a disc of 0.15 m at (1, 0))
        // if `with_box`, else the walls.
        let scan_at = |start: Pose2, end: Pose2, with_box: bool| {
            let mut r = [3.0f32; 360];
            for (d, slot) in r.iter_mut().enumerate() {
                let lidar = Scan {
                    ranges: &[0.0; 360],
                    start,
                    end,
                    mount,
                }
                .lidar_at(d);
                let a = lidar.theta + (d as f32).to_radians();
                let (dx, dy) = (1.0 - lidar.x, -lidar.y);
                let along = dx * libm::cosf(a) + dy * libm::sinf(a);
                let off = (dx * libm::sinf(a) - dy * libm::cosf(a)).abs();
                if with_box && along > 0.0 && off < 0.15 {
                    *slot = along - libm::sqrtf(0.15 * 0.15 - off * off);
                }
            }
            r
        };
        let mut c = GlobalCloud::new();
        for k in 0..8 {
            let (s, e) = rev(k);
            let r = scan_at(s, e, true);
            c.add_scan(
                &Scan {
                    ranges: &r,
                    start: s,
                    end: e,
                    mount,
                },
                &cfg,
            );
        }
        let near = |c: &GlobalCloud| {
            c.iter()
                .filter(|p| p.distance(Point2::new(1.0, 0.0)) < 0.3)
                .count()
        };
        let before = near(&c);
        assert!(before > 20, "{before}");
        // Still there: nothing of it goes, however the robot turns.
        let (s, e) = rev(8);
        // Clears `cloud` with the ninth revolution, the box there or not.
        let clear = |cloud: &mut GlobalCloud, with_box: bool| {
            let r = scan_at(s, e, with_box);
            let scan = Scan {
                ranges: &r,
                start: s,
                end: e,
                mount,
            };
            cloud.clear_seen_through(&scan, cfg.clear_margin_m, cfg.clear_beyond_rays)
        };
        let mut kept = c.clone();
        clear(&mut kept, true);
        assert_eq!(near(&kept), before);
        // Gone: all of it goes in one revolution.
        clear(&mut c, false);
        assert_eq!(near(&c), 0);
    }

    #[test]
    fn no_return_alone_says_nothing() {
        let cfg = CloudConfig::default();
        let mut boxed = GlobalCloud::new();
        boxed.add_scan(&still(&with_box(), Pose2::IDENTITY), &cfg);
        // A dark box: its bins return nothing. The wall beside it returns as before.
        let mut dark = scan_of(3.0);
        for d in (355..360).chain(0..6) {
            dark[d] = 0.0;
        }
        let mut c = boxed.clone();
        assert_eq!(
            c.clear_seen_through(&still(&dark, Pose2::IDENTITY), 0.15, 4),
            0
        );
        // When one ray from beyond is enough, only the box's two edge points go (a ray beside
        // each reaches the wall); its inner nine, with nothing but silence around them, stay.
        // When two are, one edge goes (the four rays of a point are its bin, the one before
        // and the two after); when three are, none.
        for (beyond, gone) in [(1, 2), (2, 1), (3, 0)] {
            let mut c = boxed.clone();
            assert_eq!(
                c.clear_seen_through(&still(&dark, Pose2::IDENTITY), 0.15, beyond),
                gone
            );
            assert_eq!(c.iter().filter(|p| p.norm() < 1.5).count(), 11 - gone);
        }
    }

    #[test]
    fn legs_seen_against_open_space_are_forgotten() {
        // Legs 1 m ahead, then gone: beyond them a doorway onto space past the range, whose
        // rays return nothing or, here and there, from far beyond.
        let cfg = CloudConfig::default();
        let mut legs = scan_of(3.0);
        for d in (357..360).chain(0..4) {
            legs[d] = 1.0;
        }
        let mut open = scan_of(3.0);
        for d in (350..360).chain(0..11) {
            open[d] = if d % 2 == 0 { 4.2 } else { 0.0 };
        }
        let near = |c: &GlobalCloud| c.iter().filter(|p| p.norm() < 1.5).count();
        for (beyond, left) in [(4, 7), (3, 7), (2, 0), (1, 0)] {
            let mut c = GlobalCloud::new();
            c.add_scan(&still(&legs, Pose2::IDENTITY), &cfg);
            assert_eq!(near(&c), 7);
            c.clear_seen_through(&still(&open, Pose2::IDENTITY), 0.15, beyond);
            assert_eq!(near(&c), left, "rays from beyond needed: {beyond}");
        }
    }

    /// Ranges from the origin to the line y = `y` (bins whose rays meet it within 3.5 m).
    fn wall_at(y: f32, from: Pose2) -> [f32; 360] {
        let mut r = scan_of(0.0);
        for (d, slot) in r.iter_mut().enumerate() {
            let a = from.theta + (d as f32).to_radians();
            let s = libm::sinf(a);
            if s > 1e-3 {
                let t = (y - from.y) / s;
                if t <= 3.5 {
                    *slot = t;
                }
            }
        }
        r
    }

    #[test]
    fn a_grazing_wall_keeps_its_points() {
        // A wall along the robot's path, 0.3 m to its left: the far rays meet it at 5°.
        let mut c = GlobalCloud::new();
        let cfg = CloudConfig::default();
        let first = Pose2::IDENTITY;
        c.add_scan(&still(&wall_at(0.3, first), first), &cfg);
        let before = c.len();
        assert!(before > 150);
        // A little further on and turned by a fraction of a bin, so that every ray of the
        // next revolution passes between the old points.
        for k in 1..=5 {
            let next = Pose2::new(0.013 * k as f32, 0.0, 0.0031 * k as f32);
            let ranges = wall_at(0.3, next);
            for beyond in 1..=4 {
                assert_eq!(
                    c.clear_seen_through(&still(&ranges, next), 0.15, beyond),
                    0,
                    "step {k}, rays from beyond needed: {beyond}"
                );
            }
        }
    }

    #[test]
    fn bins_follow_rep103_and_deskew() {
        let mut c = GlobalCloud::new();
        let mut ranges = scan_of(0.0);
        ranges[90] = 1.0; // left
        ranges[359] = 1.0; // first ray
        c.add_scan(
            &Scan {
                ranges: &ranges,
                start: Pose2::IDENTITY,
                end: Pose2::new(0.0, 0.0, 0.5),
                mount: Pose2::IDENTITY,
            },
            &CloudConfig::default(),
        );
        let pts: std::vec::Vec<_> = c.iter().copied().collect();
        // Bin 90 is read at 269/360 of the revolution.
        let th = 0.5 * 269.0 / 360.0 + core::f32::consts::FRAC_PI_2;
        assert!(pts[0].distance(Point2::from_polar(1.0, th)) < 1e-5);
        // Bin 359 is the first ray: start pose.
        assert!(pts[1].distance(Point2::from_polar(1.0, 359f32.to_radians())) < 1e-5);
    }
}
