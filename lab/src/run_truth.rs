//! What a run's scene really held, in the output line's map frame (the robot's pose at the
//! start): furniture with the frames it existed in and how many LiDAR returns it gave, doors,
//! clutter, walking people frame by frame. Both scene families write this; the scorer reads it.

use perception::class::ObjectClass;
use perception::geometry::{Point2, Pose2};

/// Returns a piece of furniture needs over a run before it counts as visible (the issue's
/// bar: "furniture that was visible, ≥ 20 returns during the run").
pub const VISIBLE_RETURNS: u32 = 20;

/// One piece of furniture for a span of frames (a moved piece is two entries: before, after).
#[derive(Debug, Clone, PartialEq)]
pub struct Furniture {
    /// Identity of the physical piece (shared by the before and after entries of a move).
    pub piece: usize,
    /// Class.
    pub class: ObjectClass,
    /// Footprint corners (a convex polygon), map frame.
    pub footprint: Vec<Point2>,
    /// First frame it is there.
    pub from_frame: usize,
    /// One past its last frame (`usize::MAX` = to the end).
    pub to_frame: usize,
    /// Frame at which its returns reached [`VISIBLE_RETURNS`] (None: never visible).
    pub visible_from: Option<usize>,
    /// Returns over the run.
    pub returns: u32,
    /// What it is, in words ("office chair against a wall", …), for the reports.
    pub what: String,
    /// Whether it stands against a wall (within 0.1 m of one).
    pub against_wall: bool,
}

impl Furniture {
    /// Whether it exists at frame `f`.
    pub fn alive(&self, f: usize) -> bool {
        (self.from_frame..self.to_frame).contains(&f)
    }

    /// Centre of the footprint.
    pub fn centre(&self) -> Point2 {
        perception::shape::centroid(&[&self.footprint])
    }

    /// Distance from `p` to the footprint (0 inside).
    pub fn distance(&self, p: Point2) -> f32 {
        polygon_distance(&self.footprint, p)
    }

    /// For tests: piece `piece` of `class`, a square of half-side `half` m centred at `c`,
    /// there and visible from the first frame to the end.
    #[cfg(test)]
    pub fn square(piece: usize, class: ObjectClass, c: Point2, half: f32) -> Furniture {
        Furniture {
            piece,
            class,
            footprint: vec![
                Point2::new(c.x - half, c.y - half),
                Point2::new(c.x + half, c.y - half),
                Point2::new(c.x + half, c.y + half),
                Point2::new(c.x - half, c.y + half),
            ],
            from_frame: 0,
            to_frame: usize::MAX,
            visible_from: Some(0),
            returns: 100,
            what: String::new(),
            against_wall: false,
        }
    }
}

/// A doorway.
#[derive(Debug, Clone, PartialEq)]
pub struct Door {
    /// Centre of the gap, map frame.
    pub centre: Point2,
    /// Clear width, metres.
    pub width: f32,
    /// Returns on its jambs over the run.
    pub returns: u32,
}

/// A walking person's legs at one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Person {
    /// Which person.
    pub id: usize,
    /// Midpoint of the two legs, map frame.
    pub at: Point2,
    /// Clean returns on its legs in this revolution.
    pub returns: u32,
}

/// A person is in view in a revolution that gave its legs at least this many returns.
pub const PERSON_VISIBLE_RETURNS: u32 = 3;

/// One frame's moving truth.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameTruth {
    /// Sensor time of the frame's start, s.
    pub t: f64,
    /// Walking people.
    pub people: Vec<Person>,
    /// The robot's true pose (map frame) at the revolution's first ray, when the generator
    /// knows it: what the line's `pose` (taken at that ray) is scored against.
    pub robot: Option<Pose2>,
}

/// A piece of furniture taken away or moved during the run.
#[derive(Debug, Clone, PartialEq)]
pub struct Move {
    /// Index in [`RunTruth::furniture`] of the entry before the move.
    pub before: usize,
    /// Frame from which the old place is empty.
    pub frame: usize,
    /// First frame in which the LiDAR saw the old place empty (≥ 5 rays through the old
    /// footprint), if it did.
    pub seen_empty: Option<usize>,
}

/// Everything true about one run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunTruth {
    /// Run name (family, index, room kind, motion).
    pub name: String,
    /// Furniture entries.
    pub furniture: Vec<Furniture>,
    /// Doorways.
    pub doors: Vec<Door>,
    /// Clutter (bins, pillars, shelves, standing legs): centre and what.
    pub clutter: Vec<(Point2, String)>,
    /// Frame by frame.
    pub frames: Vec<FrameTruth>,
    /// Moves.
    pub moves: Vec<Move>,
    /// Wall, jamb and door-leaf faces (for pictures).
    pub walls: Vec<(Point2, Point2)>,
}

impl RunTruth {
    /// The truth frame nearest in time to `t`.
    pub fn frame_at(&self, t: f64) -> Option<usize> {
        let i = self.frames.partition_point(|f| f.t < t);
        [i.checked_sub(1), Some(i)]
            .into_iter()
            .flatten()
            .filter(|&k| k < self.frames.len())
            .min_by(|&a, &b| {
                (self.frames[a].t - t)
                    .abs()
                    .total_cmp(&(self.frames[b].t - t).abs())
            })
    }
}

/// Distance from `p` to a convex polygon (0 inside).
pub fn polygon_distance(poly: &[Point2], p: Point2) -> f32 {
    if poly.len() < 3 {
        return poly.first().map_or(f32::INFINITY, |q| q.distance(p));
    }
    let mut inside = true;
    let mut best = f32::INFINITY;
    let mut sign = 0.0f32;
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        best = best.min(p.distance_to_segment(a, b));
        let cross = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
        if cross != 0.0 {
            if sign == 0.0 {
                sign = cross.signum();
            } else if cross.signum() != sign {
                inside = false;
            }
        }
    }
    if inside { 0.0 } else { best }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn polygon_distance_inside_and_out() {
        let sq = [
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.0, 1.0),
        ];
        assert_eq!(polygon_distance(&sq, Point2::new(0.5, 0.5)), 0.0);
        assert!((polygon_distance(&sq, Point2::new(1.5, 0.5)) - 0.5).abs() < 1e-6);
        // Clockwise works too.
        let cw: Vec<_> = sq.iter().rev().copied().collect();
        assert_eq!(polygon_distance(&cw, Point2::new(0.2, 0.9)), 0.0);
    }

    #[test]
    fn frame_at_picks_the_nearest() {
        let t = RunTruth {
            frames: [0.0, 0.2, 0.4]
                .map(|t| FrameTruth {
                    t,
                    ..FrameTruth::default()
                })
                .to_vec(),
            ..RunTruth::default()
        };
        assert_eq!(t.frame_at(0.29), Some(1));
        assert_eq!(t.frame_at(0.31), Some(2));
        assert_eq!(t.frame_at(9.0), Some(2));
        assert_eq!(t.frame_at(-1.0), Some(0));
    }
}
