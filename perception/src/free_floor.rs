//! Where the floor has been seen empty: a fixed grid over the map around the robot's start,
//! counting the revolutions whose rays passed a cell well short of their return. The world
//! model asks it where a new track appears: furniture stands where it stood when the robot
//! first looked, while a person walks on to floor the LiDAR has already seen through, and may
//! stand there for a moment. A track born on such floor has to stay for longer before it is
//! reported ([`crate::tracks::TrackConfig::appeared_settle_s`]). `no_std`, allocation-free.
//!
//! Cells are [`CELL_M`] across, [`SIDE`] a side, centred on the map's origin (the robot's start):
//! ±[`HALF_EXTENT_M`] m. Outside it nothing is known, and [`FreeFloor::seen_free`] says no.
//! Only rays that returned mark cells (a ray with no return may have met a dark surface), and
//! only up to [`MARGIN_M`] short of the return and within the LiDAR's useful range, so the face
//! that returned and a pose error of a few centimetres do not mark the object's own cells.
//!
//! A cell is free once rays have crossed it in [`FREE_REVOLUTIONS`] revolutions (a count of
//! two bits a cell). A legged chair or desk is seen through between its legs, so a single look
//! would call its floor free; the methods find it within the first revolutions that show it
//! (Method B needs three), so a piece that was there all along is rarely born on free floor,
//! while the floor where a person walks has been seen through many times.

use crate::geometry::{Point2, Pose2};
use crate::sight::BINS;

/// Cell side, m.
pub const CELL_M: f32 = 0.1;

/// Cells a side.
pub const SIDE: usize = 256;

/// Half the side of the square covered, m.
pub const HALF_EXTENT_M: f32 = CELL_M * (SIDE / 2) as f32;

/// Words of the per-revolution bitmap (one bit a cell).
pub const WORDS: usize = SIDE * SIDE / 32;

/// Words of the counts (two bits a cell).
pub const COUNT_WORDS: usize = SIDE * SIDE / 16;

/// Revolutions whose rays must have crossed a cell before it is free floor (at most 3).
pub const FREE_REVOLUTIONS: u32 = 3;

/// A ray marks cells up to this far short of its return, m.
pub const MARGIN_M: f32 = 0.3;

/// Nearest range a ray marks from, m (the robot's own body).
const FROM_M: f32 = 0.15;

/// Step along a ray, m (half a cell: no cell on the ray's line is skipped).
const STEP_M: f32 = 0.5 * CELL_M;

/// The seen-empty floor.
#[derive(Debug, Clone)]
pub struct FreeFloor {
    /// Revolutions that crossed each cell, saturating at 3 (two bits a cell).
    counts: [u32; COUNT_WORDS],
    /// The cells this revolution's rays crossed (cleared every revolution).
    this_rev: [u32; WORDS],
}

impl Default for FreeFloor {
    fn default() -> Self {
        Self::new()
    }
}

impl FreeFloor {
    /// Nothing seen yet.
    pub const fn new() -> Self {
        FreeFloor {
            counts: [0; COUNT_WORDS],
            this_rev: [0; WORDS],
        }
    }

    /// Forgets everything (a new map).
    pub fn clear(&mut self) {
        self.counts = [0; COUNT_WORDS];
        self.this_rev = [0; WORDS];
    }

    /// The cell of `p` (map frame), if inside the covered square.
    fn cell(p: Point2) -> Option<usize> {
        let cx = libm::floorf((p.x + HALF_EXTENT_M) / CELL_M);
        let cy = libm::floorf((p.y + HALF_EXTENT_M) / CELL_M);
        // Also refuses NaN.
        let inside = |c: f32| c >= 0.0 && c < SIDE as f32;
        (inside(cx) && inside(cy)).then(|| cy as usize * SIDE + cx as usize)
    }

    /// Revolutions whose rays crossed cell `k` (0–3).
    fn count(&self, k: usize) -> u32 {
        (self.counts[k / 16] >> ((k % 16) * 2)) & 3
    }

    /// Whether the floor at `p` has been seen empty, in [`FREE_REVOLUTIONS`] revolutions.
    pub fn seen_free(&self, p: Point2) -> bool {
        Self::cell(p).is_some_and(|k| self.count(k) >= FREE_REVOLUTIONS)
    }

    /// Marks what one revolution saw through: `lidar` is the LiDAR's pose in the map, `ranges`
    /// its bins (bin `d` at `d`° counter-clockwise from its forward axis; 0 or non-finite = no
    /// return), `max_range_m` its useful range. A non-finite pose marks nothing.
    pub fn mark(&mut self, lidar: &Pose2, ranges: &[f32; BINS], max_range_m: f32) {
        if !(lidar.x.is_finite() && lidar.y.is_finite() && lidar.theta.is_finite()) {
            return;
        }
        self.this_rev = [0; WORDS];
        // In cell units from the square's corner, fixed point (16 fractional bits): a step is
        // an integer add, the cell its integer part, and a negative position fails the
        // unsigned bound.
        const ONE: f32 = 65_536.0;
        let inv = 1.0 / CELL_M;
        let (ox, oy) = (
            (lidar.x + HALF_EXTENT_M) * inv,
            (lidar.y + HALF_EXTENT_M) * inv,
        );
        // The square, with a margin for the farthest a ray reaches: beyond it nothing marks.
        let far = (max_range_m.min(2.0 * HALF_EXTENT_M) * inv).max(0.0);
        let side = SIDE as f32;
        if !(ox + far >= 0.0 && oy + far >= 0.0 && ox - far < side && oy - far < side) {
            return;
        }
        let bound = (SIDE as u32) << 16;
        for (d, &r) in ranges.iter().enumerate() {
            if !(r > 0.0 && r.is_finite()) {
                continue;
            }
            let reach = (r - MARGIN_M).min(max_range_m);
            if reach.is_nan() || reach <= FROM_M {
                continue;
            }
            let (s, c) = libm::sincosf(lidar.theta + (d as f32).to_radians());
            let (dx, dy) = (
                (c * STEP_M * inv * ONE) as i32,
                (s * STEP_M * inv * ONE) as i32,
            );
            let mut fx = ((ox + c * FROM_M * inv) * ONE) as i32;
            let mut fy = ((oy + s * FROM_M * inv) * ONE) as i32;
            let steps = ((reach - FROM_M) / STEP_M) as usize + 1;
            for _ in 0..steps {
                let (ux, uy) = (fx as u32, fy as u32);
                if ux < bound && uy < bound {
                    let k = (uy >> 16) as usize * SIDE + (ux >> 16) as usize;
                    self.this_rev[k / 32] |= 1 << (k % 32);
                }
                fx = fx.wrapping_add(dx);
                fy = fy.wrapping_add(dy);
            }
        }
        // Each crossed cell counts once for the revolution, however many rays crossed it.
        for (w, &bits) in self.this_rev.iter().enumerate() {
            let mut rest = bits;
            while rest != 0 {
                let b = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                let k = w * 32 + b;
                if self.count(k) < 3 {
                    self.counts[k / 16] += 1 << ((k % 16) * 2);
                }
            }
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn ring(r: f32) -> [f32; BINS] {
        [r; BINS]
    }

    /// `n` revolutions of the same rays from the same pose.
    fn looked(f: &mut FreeFloor, pose: Pose2, ranges: &[f32; BINS], n: usize) {
        for _ in 0..n {
            f.mark(&pose, ranges, 3.5);
        }
    }

    #[test]
    fn floor_rays_crossed_in_three_revolutions_is_free_and_their_end_is_not() {
        let mut f = FreeFloor::new();
        let mut ranges = [0.0; BINS];
        ranges[0] = 3.0; // forward, +x
        // Every bin around it returns too: one cell is crossed by several rays near the robot,
        // and counts once for the revolution.
        ranges[1] = 3.0;
        ranges[359] = 3.0;
        looked(&mut f, Pose2::new(0.0, 0.0, 0.0), &ranges, 2);
        assert!(
            !f.seen_free(Point2::new(0.5, 0.0)),
            "two revolutions are not enough"
        );
        looked(&mut f, Pose2::new(0.0, 0.0, 0.0), &ranges, 1);
        assert!(f.seen_free(Point2::new(0.5, 0.0)));
        assert!(f.seen_free(Point2::new(2.6, 0.0)));
        // The last MARGIN_M before the return, and the return itself, are not marked.
        assert!(!f.seen_free(Point2::new(2.85, 0.0)));
        assert!(!f.seen_free(Point2::new(3.0, 0.0)));
        // Nor is what no ray crossed.
        assert!(!f.seen_free(Point2::new(0.0, 1.0)));
        // Counts saturate.
        looked(&mut f, Pose2::new(0.0, 0.0, 0.0), &ranges, 5);
        assert!(f.seen_free(Point2::new(0.5, 0.0)));
        assert!(!f.seen_free(Point2::new(0.0, 1.0)));
    }

    #[test]
    fn rays_without_a_return_and_beyond_the_range_mark_nothing() {
        let mut f = FreeFloor::new();
        let mut ranges = ring(0.0);
        ranges[90] = 6.0; // +y, far beyond the useful range
        looked(&mut f, Pose2::new(0.0, 0.0, 0.0), &ranges, 3);
        assert!(f.seen_free(Point2::new(0.0, 3.4)));
        assert!(!f.seen_free(Point2::new(0.0, 3.7)));
        // Bin 0 had no return: nothing forward.
        assert!(!f.seen_free(Point2::new(1.0, 0.0)));
    }

    #[test]
    fn the_pose_places_the_rays_in_the_map() {
        let mut f = FreeFloor::new();
        let mut ranges = ring(0.0);
        ranges[0] = 2.0;
        // At (1, 1) facing +y: bin 0 points along +y.
        let pose = Pose2::new(1.0, 1.0, core::f32::consts::FRAC_PI_2);
        looked(&mut f, pose, &ranges, 3);
        assert!(f.seen_free(Point2::new(1.0, 2.0)));
        assert!(!f.seen_free(Point2::new(2.0, 1.0)));
    }

    #[test]
    fn bad_input_marks_nothing_and_far_points_are_unknown() {
        let mut f = FreeFloor::new();
        looked(&mut f, Pose2::new(f32::NAN, 0.0, 0.0), &ring(2.0), 3);
        looked(&mut f, Pose2::new(0.0, 0.0, 0.0), &ring(f32::INFINITY), 3);
        assert!(f.counts.iter().all(|w| *w == 0));
        assert!(!f.seen_free(Point2::new(f32::NAN, 0.0)));
        // Rays that leave the covered square mark up to its edge, no further, no panic.
        looked(
            &mut f,
            Pose2::new(HALF_EXTENT_M - 0.5, 0.0, 0.0),
            &ring(3.0),
            3,
        );
        assert!(f.seen_free(Point2::new(HALF_EXTENT_M - 0.05, 0.0)));
        assert!(!f.seen_free(Point2::new(HALF_EXTENT_M + 1.0, 0.0)));
        f.clear();
        assert!(!f.seen_free(Point2::new(HALF_EXTENT_M - 0.05, 0.0)));
    }
}
