//! The map's walls: the long wall segments Method A fits each revolution, gathered in the map
//! frame into lines that persist, so that a wall which comes out broken in one revolution (a
//! piece hidden behind a box, its far end thinned into sparse dashes at a grazing angle) is
//! still known to be there. A detection whose centre lies in a confirmed wall's band — less
//! than [`IN_WALL_M`] in front of its face, or up to [`BEHIND_M`] behind it, along its extent —
//! is a piece of that wall, not furniture ([`WallMap::holds`]).
//!
//! Each segment of at least [`MIN_SEGMENT_M`] joins the line it continues (directions within
//! [`SAME_ANGLE_RAD`], offset within [`SAME_OFFSET_M`], overlapping or a gap under
//! [`JOIN_GAP_M`], narrower than any doorway, so doorways stay gaps) or starts a new one; a
//! line is confirmed once seen in [`CONFIRM_FRAMES`] revolutions. Which side of a line the room
//! is on is voted by where the LiDAR stood when it saw the wall. Fixed capacity
//! ([`MAX_MAP_WALLS`]); when full, the least supported line gives way (counted).

use heapless::Vec;

use crate::geometry::Point2;
use crate::walls::Segment;

/// Lines held at most (a flat of several rooms has a few dozen wall faces).
pub const MAX_MAP_WALLS: usize = 48;
/// Segments shorter than this are not taken as walls, m (a box's longest face is ~0.8 m).
pub const MIN_SEGMENT_M: f32 = 1.0;
/// Largest angle between a segment and the line it continues, rad (5°).
pub const SAME_ANGLE_RAD: f32 = 0.087;
/// Largest offset of a segment's ends from the line it continues, m.
pub const SAME_OFFSET_M: f32 = 0.08;
/// Largest gap along the line between a segment and the line it continues, m (doorways are
/// at least 0.75 m wide and stay gaps).
pub const JOIN_GAP_M: f32 = 0.25;
/// Revolutions a line must be seen in before it holds anything.
pub const CONFIRM_FRAMES: u32 = 3;
/// A centre less than this in front of a wall's face is in the wall, m. Furniture against a
/// wall has its centre at least half its depth (≥ 0.15 m) in front.
pub const IN_WALL_M: f32 = 0.08;
/// A centre up to this far behind a wall's face is in the wall (or a mixed pixel, or a
/// completion into the wall: a box or chair class's centre completion pushes a piece of wall
/// seen at an angle 0.2–0.4 m behind the face), m. Furniture against the wall's other side,
/// in the next room, can have its centre within this too (a wall's thickness plus half its
/// depth, 0.25–0.35 m): it is told from the wall only where the other face is a confirmed
/// line ([`FAR_SIDE_M`]).
pub const BEHIND_M: f32 = 0.4;
/// A centre this far in front of the other face of a thin wall (up to [`IN_WALL_M`] more) is
/// furniture against it in the next room, m.
pub const FAR_SIDE_M: f32 = 0.2;
/// Beyond a line's ends its band still reaches this far, m.
pub const END_MARGIN_M: f32 = 0.05;
/// Two lines meet in a corner where they cross within this of an end of each, m.
pub const CORNER_JOIN_M: f32 = 0.4;
/// Sine of the smallest angle between two lines that meet in a corner (45°).
const CORNER_MIN_SIN: f32 = 0.707;
/// A door frame whose centre is this close to a confirmed line (in front of its face or
/// behind it, within a wall's thickness and a detection's scatter) stands in its line, m.
pub const DOOR_LINE_M: f32 = 0.2;
/// … and no farther beyond the line's end than half the widest doorway (0.7 m) and a jamb's
/// allowance, m.
pub const DOOR_REACH_M: f32 = 0.9;
/// [`WallMap::far_jamb`] looks for the other jamb of a door frame this close to a confirmed
/// line, m: wider than [`DOOR_LINE_M`], since a door frame a method places at a wall's end
/// that is no doorway (an L-shaped room's protruding corner, a partition's free end) sits
/// beside the line as often as in it, and only the other jamb's place seen empty speaks
/// against it (tuning seeds: the varied family's phantoms 0.293 → 0.273 a frame, no door lost;
/// `docs/world.md`, 46th session).
pub const FAR_JAMB_LINE_M: f32 = 0.3;
/// Narrowest doorway [`WallMap::far_jamb`] assumes, m.
pub const MIN_DOOR_M: f32 = 0.75;
/// Widest doorway [`WallMap::far_jamb`] assumes, m.
pub const MAX_DOOR_M: f32 = 1.3;
/// Weight at most of a line's past when a segment joins it (so a line can still settle).
const MAX_WEIGHT: f32 = 20.0;
/// Side votes are kept within ±this.
const MAX_SIDE_VOTES: i16 = 20;

/// One wall line in the map frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MapWall {
    /// A point on the line.
    origin: Point2,
    /// Unit direction.
    dir: Point2,
    /// Extent along `dir` from `origin`, m.
    lo: f32,
    /// See `lo`.
    hi: f32,
    /// Votes for the room being on the left of `dir` (positive) or the right.
    side: i16,
    /// Revolutions it was seen in.
    pub support: u32,
    /// Last frame it was seen in.
    pub last_frame: u64,
}

impl MapWall {
    /// Its two ends.
    pub fn ends(&self) -> (Point2, Point2) {
        (self.at(self.lo), self.at(self.hi))
    }

    /// Length, m.
    pub fn length(&self) -> f32 {
        self.hi - self.lo
    }

    /// Its extent along the line, `(lo, hi)` m from the origin.
    pub(crate) fn extent(&self) -> (f32, f32) {
        (self.lo, self.hi)
    }

    /// Seen often enough to hold anything.
    pub fn confirmed(&self) -> bool {
        self.support >= CONFIRM_FRAMES && self.side != 0
    }

    /// The point `u` m along the line from its origin.
    pub(crate) fn at(&self, u: f32) -> Point2 {
        Point2::new(
            self.origin.x + u * self.dir.x,
            self.origin.y + u * self.dir.y,
        )
    }

    /// Position along the line.
    pub(crate) fn along(&self, p: Point2) -> f32 {
        (p - self.origin).dot(self.dir)
    }

    /// Whether `p` lies along the line within its extent widened by `margin` m at each end.
    fn spans(&self, p: Point2, margin: f32) -> bool {
        let u = self.along(p);
        u >= self.lo - margin && u <= self.hi + margin
    }

    /// Signed distance from the face, positive on the room's side.
    pub(crate) fn in_front(&self, p: Point2) -> f32 {
        (p - self.origin).dot(self.room_normal())
    }

    /// Whether the segment `a`–`b`, whose room lies along `room` (a normal; zero: unknown),
    /// continues this line. The two faces of a thin wall are two lines: their rooms differ.
    fn continued_by(&self, a: Point2, b: Point2, room: Point2) -> bool {
        if self.side != 0 && room.dot(self.room_normal()) < 0.0 {
            return false;
        }
        let d = unit(b - a);
        if libm::fabsf(self.dir.cross(d)) > libm::sinf(SAME_ANGLE_RAD) {
            return false;
        }
        let n = Point2::new(-self.dir.y, self.dir.x);
        if libm::fabsf((a - self.origin).dot(n)) > SAME_OFFSET_M
            || libm::fabsf((b - self.origin).dot(n)) > SAME_OFFSET_M
        {
            return false;
        }
        let (ua, ub) = (self.along(a), self.along(b));
        let (lo, hi) = (ua.min(ub), ua.max(ub));
        lo <= self.hi + JOIN_GAP_M && hi >= self.lo - JOIN_GAP_M
    }

    /// Takes in the segment `a`–`b` with weight `w` (its side is voted apart).
    fn absorb(&mut self, a: Point2, b: Point2, w: f32) {
        let mut d = unit(b - a);
        if d.dot(self.dir) < 0.0 {
            d = Point2::new(-d.x, -d.y);
        }
        let w0 = (self.support as f32).min(MAX_WEIGHT);
        let total = w0 + w;
        let dir = unit(Point2::new(
            self.dir.x * w0 + d.x * w,
            self.dir.y * w0 + d.y * w,
        ));
        // The new line passes through the weighted mean of the old origin and the segment's
        // middle, with the mean direction; the extent is the union of both, re-projected.
        let (old_lo, old_hi) = self.ends();
        let mid = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
        let origin = Point2::new(
            (self.origin.x * w0 + mid.x * w) / total,
            (self.origin.y * w0 + mid.y * w) / total,
        );
        self.origin = origin;
        self.dir = dir;
        let us = [
            self.along(old_lo),
            self.along(old_hi),
            self.along(a),
            self.along(b),
        ];
        self.lo = us.iter().copied().fold(f32::INFINITY, f32::min);
        self.hi = us.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    }

    /// The unit normal on the room's side.
    pub(crate) fn room_normal(&self) -> Point2 {
        let s = if self.side >= 0 { 1.0 } else { -1.0 };
        Point2::new(-self.dir.y * s, self.dir.x * s)
    }

    fn vote(&mut self, sensor: Point2) {
        let n = Point2::new(-self.dir.y, self.dir.x);
        let s = (sensor - self.origin).dot(n);
        if s > 0.0 {
            self.side = (self.side + 1).min(MAX_SIDE_VOTES);
        } else if s < 0.0 {
            self.side = (self.side - 1).max(-MAX_SIDE_VOTES);
        }
    }
}

fn unit(v: Point2) -> Point2 {
    let n = v.norm();
    if n > 0.0 {
        Point2::new(v.x / n, v.y / n)
    } else {
        Point2::new(1.0, 0.0)
    }
}

/// Counts of what the map had to refuse or give up.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WallMapStats {
    /// Segments with non-finite ends, refused.
    pub refused: u64,
    /// Lines given up for a new one when the map was full.
    pub evicted: u64,
}

/// The map's wall lines.
#[derive(Debug, Clone, Default)]
pub struct WallMap {
    walls: Vec<MapWall, MAX_MAP_WALLS>,
    stats: WallMapStats,
}

impl WallMap {
    /// An empty map.
    pub const fn new() -> Self {
        WallMap {
            walls: Vec::new(),
            stats: WallMapStats {
                refused: 0,
                evicted: 0,
            },
        }
    }

    /// Every line, confirmed or not.
    pub fn walls(&self) -> &[MapWall] {
        &self.walls
    }

    /// What was refused or evicted so far.
    pub fn stats(&self) -> &WallMapStats {
        &self.stats
    }

    /// Forgets every line (after a relocalisation the old lines are in a stale frame).
    pub fn clear(&mut self) {
        self.walls.clear();
    }

    /// Takes in one revolution's wall segments (map frame), seen from `sensor`.
    pub fn update(&mut self, frame: u64, segments: &[Segment], sensor: Point2) {
        for s in segments {
            let finite = s.a.x.is_finite()
                && s.a.y.is_finite()
                && s.b.x.is_finite()
                && s.b.y.is_finite()
                && sensor.x.is_finite()
                && sensor.y.is_finite();
            if !finite {
                self.stats.refused += 1;
                continue;
            }
            if s.length() < MIN_SEGMENT_M {
                continue;
            }
            self.add(frame, s.a, s.b, sensor);
        }
    }

    fn add(&mut self, frame: u64, a: Point2, b: Point2, sensor: Point2) {
        // The room is on the side the LiDAR stood.
        let d = unit(b - a);
        let mut room = Point2::new(-d.y, d.x);
        if (sensor - a).dot(room) < 0.0 {
            room = Point2::new(-room.x, -room.y);
        }
        let joined = self.walls.iter().position(|w| w.continued_by(a, b, room));
        let i = match joined {
            Some(i) => {
                let w = &mut self.walls[i];
                w.absorb(a, b, 1.0);
                w.vote(sensor);
                if w.last_frame != frame {
                    w.support = w.support.saturating_add(1);
                    w.last_frame = frame;
                }
                i
            }
            None => {
                let dir = unit(b - a);
                let mut w = MapWall {
                    origin: a,
                    dir,
                    lo: 0.0,
                    hi: a.distance(b),
                    side: 0,
                    support: 1,
                    last_frame: frame,
                };
                w.vote(sensor);
                if self.walls.is_full() {
                    let weakest = self
                        .walls
                        .iter()
                        .enumerate()
                        .min_by_key(|(_, w)| (w.support, w.last_frame))
                        .map(|(k, _)| k);
                    if let Some(k) = weakest {
                        self.walls.swap_remove(k);
                        self.stats.evicted += 1;
                    }
                }
                // Cannot fail: a place was made above when full.
                let _ = self.walls.push(w);
                self.walls.len() - 1
            }
        };
        self.join_others(i);
    }

    /// Lines that grew into each other become one (the first keeps the larger support).
    fn join_others(&mut self, i: usize) {
        let mut i = i;
        let mut k = 0;
        while k < self.walls.len() {
            if k != i {
                let (a, b) = self.walls[k].ends();
                let room = if self.walls[k].side == 0 {
                    Point2::new(0.0, 0.0)
                } else {
                    self.walls[k].room_normal()
                };
                if self.walls[i].continued_by(a, b, room) {
                    let other = self.walls[k];
                    let w = &mut self.walls[i];
                    w.absorb(a, b, (other.support as f32).min(MAX_WEIGHT));
                    // The other line's votes, turned to this line's direction.
                    let votes = if w.dir.dot(other.dir) >= 0.0 {
                        other.side
                    } else {
                        -other.side
                    };
                    w.side = (w.side + votes).clamp(-MAX_SIDE_VOTES, MAX_SIDE_VOTES);
                    w.support = w.support.max(other.support);
                    w.last_frame = w.last_frame.max(other.last_frame);
                    self.walls.swap_remove(k);
                    if i == self.walls.len() {
                        // The line at `i` moved into the gap `k` left.
                        i = k;
                    }
                    continue;
                }
            }
            k += 1;
        }
    }

    /// Whether a corner of the map's walls lies within `r` m of `p`: two confirmed lines at
    /// 45° or more to each other whose lines cross within [`CORNER_JOIN_M`] of an end of each
    /// (an L's corner, inner or outer; not where a wall meets another's middle).
    pub fn corner_near(&self, p: Point2, r: f32) -> bool {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return false;
        }
        let near_end = |w: &MapWall, x: Point2, d: f32| {
            let (a, b) = w.ends();
            a.distance(x) <= d || b.distance(x) <= d
        };
        // Each of the two lines has an end within r + CORNER_JOIN_M of `p`: most pairs are
        // ruled out by that alone (the map holds up to MAX_MAP_WALLS lines).
        let candidate = |w: &MapWall| w.confirmed() && near_end(w, p, r + CORNER_JOIN_M);
        let walls = &self.walls;
        walls.iter().enumerate().any(|(i, a)| {
            candidate(a)
                && walls[i + 1..].iter().any(|b| {
                    let det = a.dir.cross(b.dir);
                    if !candidate(b) || libm::fabsf(det) < CORNER_MIN_SIN {
                        return false;
                    }
                    // origin_a + s dir_a = origin_b + u dir_b
                    let s = (b.origin - a.origin).cross(b.dir) / det;
                    let x = a.at(s);
                    x.distance(p) <= r
                        && near_end(a, x, CORNER_JOIN_M)
                        && near_end(b, x, CORNER_JOIN_M)
                })
        })
    }

    /// Whether `p` stands in the line of a confirmed wall: within [`DOOR_LINE_M`] of it, and
    /// along it no farther than [`DOOR_REACH_M`] past one of its ends. A doorway is a gap in
    /// a wall, so its middle is: a door frame in the open floor, or beside a wall's end but
    /// off its line, is not.
    pub fn in_wall_line(&self, p: Point2) -> bool {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return false;
        }
        self.walls.iter().any(|w| {
            w.confirmed() && libm::fabsf(w.in_front(p)) <= DOOR_LINE_M && w.spans(p, DOOR_REACH_M)
        })
    }

    /// Where a doorway's other jamb would stand if `p` were the middle of a doorway beside the
    /// end of a confirmed line: `p` in or beside that line ([`FAR_JAMB_LINE_M`]) and past the
    /// end by at most [`DOOR_REACH_M`]; the end is one jamb, and the other stands as far again
    /// past `p`, a doorway's width ([`MIN_DOOR_M`]–[`MAX_DOOR_M`]) from the end, in the line.
    /// `None` when `p` stands past no line's end.
    pub fn far_jamb(&self, p: Point2) -> Option<Point2> {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return None;
        }
        self.walls.iter().filter(|w| w.confirmed()).find_map(|w| {
            if libm::fabsf(w.in_front(p)) > FAR_JAMB_LINE_M {
                return None;
            }
            let u = w.along(p);
            let (past, end, out) = if u > w.hi {
                (u - w.hi, w.hi, 1.0)
            } else if u < w.lo {
                (w.lo - u, w.lo, -1.0)
            } else {
                return None;
            };
            (past <= DOOR_REACH_M)
                .then(|| w.at(end + out * (2.0 * past).clamp(MIN_DOOR_M, MAX_DOOR_M)))
        })
    }

    /// Whether `p` lies in a confirmed wall's band: less than [`IN_WALL_M`] in front of its
    /// face or up to [`BEHIND_M`] behind it, within its extent — unless `p` is well in front
    /// of another confirmed line facing the other way there (the far side of a thin wall
    /// between two rooms, where furniture against it stands in the other room).
    pub fn holds(&self, p: Point2) -> bool {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return false;
        }
        let within = |w: &MapWall| w.spans(p, END_MARGIN_M);
        self.walls
            .iter()
            .filter(|w| w.confirmed() && within(w))
            .any(|w| {
                let s = w.in_front(p);
                (-BEHIND_M..IN_WALL_M).contains(&s)
                    && !self.walls.iter().any(|v| {
                        v.confirmed()
                            && within(v)
                            && v.room_normal().dot(w.room_normal()) < -0.9
                            && (IN_WALL_M..FAR_SIDE_M + IN_WALL_M).contains(&v.in_front(p))
                    })
            })
    }
}

#[cfg(test)]
mod test {
    use super::*;

    use crate::walls::test_seg as seg;

    const ROBOT: Point2 = Point2::new(0.0, 0.0);

    /// A wall along y = 2 from x = −2 to 2, seen from the origin in `n` revolutions.
    fn seen(map: &mut WallMap, segs: &[Segment], n: u64) {
        for f in 0..n {
            map.update(f, segs, ROBOT);
        }
    }

    #[test]
    fn a_confirmed_wall_holds_its_band_not_furniture_against_it() {
        let mut map = WallMap::new();
        let wall = [seg(-2.0, 2.0, 2.0, 2.0)];
        seen(&mut map, &wall, 2);
        // Not yet confirmed: holds nothing.
        assert!(!map.holds(Point2::new(0.0, 1.97)));
        seen(&mut map, &wall, 1);
        assert_eq!(map.walls().len(), 1);
        assert!(map.walls()[0].confirmed());
        // On the face, just in front, just behind: pieces of the wall.
        assert!(map.holds(Point2::new(0.0, 2.0)));
        assert!(map.holds(Point2::new(1.0, 1.95)));
        assert!(map.holds(Point2::new(-1.9, 2.15)));
        // A piece of the wall completed into a box's centre, 0.35 m behind the face.
        assert!(map.holds(Point2::new(-1.0, 2.35)));
        // A box against the wall (centre half its depth in front), the room, far beyond it.
        assert!(!map.holds(Point2::new(0.5, 1.8)));
        assert!(!map.holds(Point2::new(0.0, 0.5)));
        assert!(!map.holds(Point2::new(0.0, 2.5)));
        // Beyond the wall's end.
        assert!(!map.holds(Point2::new(2.3, 2.0)));
        assert!(!map.holds(Point2::new(f32::NAN, 2.0)));
    }

    #[test]
    fn a_broken_wall_is_one_line_and_a_doorway_stays_a_gap() {
        let mut map = WallMap::new();
        // Pieces with a 0.2 m gap (a hidden stretch), then a 0.9 m doorway.
        let pieces = [
            seg(-3.0, 2.0, -1.6, 2.0),
            seg(-1.4, 2.01, 0.0, 2.0),
            seg(0.9, 2.0, 3.0, 1.99),
        ];
        seen(&mut map, &pieces, 3);
        assert_eq!(map.walls().len(), 2, "{:?}", map.walls());
        // The hidden stretch is wall; the doorway is not.
        assert!(map.holds(Point2::new(-1.5, 2.0)));
        assert!(!map.holds(Point2::new(0.45, 2.0)));
        // The longer line spans both pieces.
        let long = map.walls().iter().map(MapWall::length).fold(0.0, f32::max);
        assert!((long - 3.0).abs() < 0.05, "{long}");
    }

    #[test]
    fn a_doorways_other_jamb_stands_a_door_width_past_a_walls_end() {
        let mut map = WallMap::new();
        seen(&mut map, &[seg(-3.0, 2.0, 0.0, 2.0)], 3);
        let near = |p: Option<Point2>, x: f32, y: f32| {
            p.is_some_and(|p| p.distance(Point2::new(x, y)) < 0.03)
        };
        // A middle 0.45 m past the end: a 0.9 m doorway, its other jamb at x = 0.9.
        assert!(near(map.far_jamb(Point2::new(0.45, 2.05)), 0.9, 2.0));
        // Closer to the end: the narrowest doorway; at the reach's end: the widest.
        assert!(near(map.far_jamb(Point2::new(0.1, 2.0)), 0.75, 2.0));
        assert!(near(map.far_jamb(Point2::new(0.85, 2.0)), 1.3, 2.0));
        // Past the other end: the jamb lies that way.
        assert!(near(map.far_jamb(Point2::new(-3.4, 1.95)), -3.8, 2.0));
        // Beside the line rather than in it (a door frame placed at an L's protruding corner):
        // the jamb is looked for all the same, along the line.
        assert!(near(map.far_jamb(Point2::new(0.2, 2.25)), 0.75, 2.0));
        assert!(near(map.far_jamb(Point2::new(0.2, 1.75)), 0.75, 2.0));
        // In the wall's extent, off its line, too far past its end, or not a number: none.
        for p in [(-1.0, 2.0), (0.45, 1.6), (1.0, 2.0), (f32::NAN, 2.0)] {
            assert_eq!(map.far_jamb(Point2::new(p.0, p.1)), None, "{p:?}");
        }
    }

    #[test]
    fn a_doorway_stands_in_its_wall_line_open_floor_does_not() {
        let mut map = WallMap::new();
        // One jamb's wall, y = 2 for x ≤ 0; the other side of the doorway never seen.
        let wall = [seg(-3.0, 2.0, 0.0, 2.0)];
        seen(&mut map, &wall, 2);
        assert!(
            !map.in_wall_line(Point2::new(0.5, 2.05)),
            "not yet confirmed"
        );
        seen(&mut map, &wall, 1);
        // A doorway's middle past the line's end, on it or within a wall's thickness.
        assert!(map.in_wall_line(Point2::new(0.5, 2.05)));
        assert!(map.in_wall_line(Point2::new(0.8, 1.85)));
        // In the wall's own extent too (a line the map joined across a doorway).
        assert!(map.in_wall_line(Point2::new(-1.0, 2.1)));
        // Off the line (the open floor in front of it), or farther past its end than half a
        // doorway.
        assert!(!map.in_wall_line(Point2::new(0.5, 1.6)));
        assert!(!map.in_wall_line(Point2::new(1.2, 2.0)));
        assert!(!map.in_wall_line(Point2::new(f32::NAN, 2.0)));
    }

    #[test]
    fn corners_are_where_two_lines_meet_at_an_angle() {
        let mut map = WallMap::new();
        // An L's inner corner at (1, 2) seen from the origin: y = 2 for x ≤ 1, then x = 1
        // for y ≥ 2; and a doorway (0.9 m gap) in the first wall at x = −1.55.
        seen(
            &mut map,
            &[
                seg(-3.0, 2.0, -2.0, 2.0),
                seg(-1.1, 2.0, 1.0, 2.0),
                seg(1.0, 2.0, 1.0, 4.0),
            ],
            3,
        );
        assert!(map.corner_near(Point2::new(0.8, 1.8), 0.45));
        assert!(map.corner_near(Point2::new(1.0, 2.0), 0.05));
        // The doorway's middle is no corner: its jambs' lines are one line.
        assert!(!map.corner_near(Point2::new(-1.55, 2.0), 0.45));
        // Nor is a point along a wall.
        assert!(!map.corner_near(Point2::new(0.0, 2.0), 0.45));
        assert!(!map.corner_near(Point2::new(f32::NAN, 2.0), 0.45));
        // Two lines whose extensions cross far from either's end meet nowhere.
        let mut apart = WallMap::new();
        seen(
            &mut apart,
            &[seg(-3.0, 2.0, -1.0, 2.0), seg(1.0, 3.0, 1.0, 5.0)],
            3,
        );
        assert!(!apart.corner_near(Point2::new(1.0, 2.0), 0.45));
    }

    #[test]
    fn pieces_that_meet_later_become_one_line() {
        let mut map = WallMap::new();
        seen(
            &mut map,
            &[seg(-3.0, 2.0, -1.0, 2.0), seg(0.0, 2.0, 2.0, 2.0)],
            3,
        );
        assert_eq!(map.walls().len(), 2);
        seen(&mut map, &[seg(-1.3, 2.0, 0.3, 2.0)], 1);
        assert_eq!(map.walls().len(), 1, "{:?}", map.walls());
        assert!((map.walls()[0].length() - 5.0).abs() < 0.05);
    }

    #[test]
    fn the_far_side_of_a_thin_wall_is_the_other_room() {
        let mut map = WallMap::new();
        // A 0.02 m wall between two rooms: its face y = 0 seen from y < 0, its face y = 0.02
        // from y > 0. The faces stay two lines.
        for f in 0..3 {
            map.update(f, &[seg(-2.0, 0.0, 2.0, 0.0)], Point2::new(0.0, -2.0));
            map.update(f, &[seg(-2.0, 0.02, 2.0, 0.02)], Point2::new(0.0, 2.0));
        }
        assert_eq!(map.walls().len(), 2);
        // In the wall.
        assert!(map.holds(Point2::new(0.0, 0.01)));
        // A box against the wall in the upper room, 0.15 m in front of its face.
        assert!(!map.holds(Point2::new(0.0, 0.17)));
        assert!(!map.holds(Point2::new(0.0, -0.17)));
    }

    #[test]
    fn bad_and_short_segments_and_a_full_map() {
        let mut map = WallMap::new();
        map.update(0, &[seg(f32::NAN, 0.0, 1.0, 1.0)], ROBOT);
        map.update(0, &[seg(0.0, 2.0, 0.5, 2.0)], ROBOT);
        assert_eq!(map.stats().refused, 1);
        assert!(map.walls().is_empty());
        // Parallel walls 1 m apart: each its own line.
        for k in 0..(MAX_MAP_WALLS + 5) {
            let y = 2.0 + k as f32;
            map.update(k as u64, &[seg(-1.0, y, 1.0, y)], ROBOT);
        }
        assert_eq!(map.walls().len(), MAX_MAP_WALLS);
        assert_eq!(map.stats().evicted, 5);
        map.clear();
        assert!(map.walls().is_empty());
    }
}
