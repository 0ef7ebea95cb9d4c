//! Whether a detection is a piece of a wall, judged from one revolution's own points rather
//! than from the wall segments Method A fitted (which a wall seen at a grazing angle, or broken
//! by what stands in front of it, may lack). A detection is a wall piece when most returns
//! around its centre lie on one line (within the range noise; at a corner: either arm), that
//! line passes through the centre or in front of it (the centre in the wall, or completed
//! behind it), and the same line goes on, unbroken, well beyond any piece of furniture's size
//! ([`CONTINUES_FROM_M`]): a box's face ends with the box, a wall does not. `no_std`,
//! allocation-free: a few passes over the revolution.

use crate::class::ObjectClass;
use crate::fusion::FrameObjects;
use crate::geometry::{Point2, Pose2};
use crate::sight::{BINS, returns};
use heapless::Vec;

/// Returns this close to a detection's centre are its own, m.
pub const NEAR_M: f32 = 0.3;
/// Returns near a centre looked at, at most (a 0.3 m disc 0.5 m away spans ~70 bins).
pub const MAX_NEAR: usize = 64;
/// At least this many of them, half of them on one line.
pub const MIN_POINTS: u32 = 3;
/// A return is on a line within this, m, or twice the range noise where that is more.
pub const THIN_M: f32 = 0.02;
/// Range noise (σ) as a share of range: the LDS-01's spec of ±5 % taken as 2σ, the worst of
/// the LiDARs umbra reads (the simulator draws the same).
pub const NOISE_FRAC: f32 = 0.025;
/// The centre may lie this far in front of the line (towards the LiDAR), m: furniture
/// against a wall has its centre at least half its depth (≥ 0.15 m) in front of the face.
pub const IN_FRONT_M: f32 = 0.1;
/// Or this far behind it, m (a centre completed into the wall or beyond it).
pub const BEHIND_M: f32 = 0.3;
/// The line must go on from this far from the centre, m: beyond the half-diagonal of any
/// piece of furniture a face could belong to (a 0.72 × 0.48 m box: 0.43 m).
pub const CONTINUES_FROM_M: f32 = 0.55;
/// ... up to this far, m.
pub const CONTINUES_TO_M: f32 = 1.5;
/// A return on the line beyond: within this of it, m, or twice the range noise.
pub const ON_LINE_M: f32 = 0.03;
/// Candidate lines tried per detection, at most (each one more pass over the revolution).
pub const MAX_TRIES: usize = 6;
/// Cells along the line in which the continuation is looked for (`CELLS × CELL_M` =
/// 2 × [`CONTINUES_TO_M`]).
const CELLS: u32 = 60;
/// See `CELLS`, m.
const CELL_M: f32 = 2.0 * CONTINUES_TO_M / CELLS as f32;
/// Cells from the centre within which the line's own returns must begin (0.3 m).
const NEAR_CELLS: u32 = 6;
/// A wall's returns may leave a gap this long, m, or 2.5 times their spacing where more.
pub const MAX_GAP_M: f32 = 0.15;
/// Returns on the line beyond, at least.
pub const CONTINUE_POINTS: u32 = 4;

/// Whether the detection centred at `centre` (map frame) is a piece of a wall, given the
/// revolution `ranges` seen from `lidar` (map frame).
pub fn is_wall_piece(centre: Point2, lidar: &Pose2, ranges: &[f32; BINS]) -> bool {
    is_wall_piece_in(centre, lidar, &returns(ranges))
}

/// [`is_wall_piece`] on the revolution's returns already converted ([`returns`]).
fn is_wall_piece_in(centre: Point2, lidar: &Pose2, pts: &[Option<Point2>; BINS]) -> bool {
    if !(centre.x.is_finite() && centre.y.is_finite()) {
        return false;
    }
    // In the LiDAR's frame: the sensor at the origin.
    let c = lidar.inverse().transform(centre);
    let two_sigma = 2.0 * NOISE_FRAC * c.norm();
    let (thin, on_line) = (THIN_M.max(two_sigma), ON_LINE_M.max(two_sigma));
    let points = || pts.iter().flatten().copied();
    // Pass 1: the returns near the centre, in bearing order.
    let mut near: Vec<Point2, MAX_NEAR> = Vec::new();
    for p in points().filter(|p| p.distance(c) <= NEAR_M) {
        if near.push(p).is_err() {
            break;
        }
    }
    let n = near.len();
    if n < MIN_POINTS as usize {
        return false;
    }
    // Lines through pairs a third of the run apart that hold at least half of them within
    // `thin` (at a wall's corner: either arm); each is refined to its inliers' principal axis
    // and tried, the first [`MAX_TRIES`] at most.
    let step = (n / 3).max(1);
    let mut tries = 0;
    for i in 0..n {
        let (a, b) = (near[i], near[(i + step) % n]);
        if a.distance(b) < 0.05 {
            continue;
        }
        let e = b - a;
        let nrm = Point2::new(-e.y / e.norm(), e.x / e.norm());
        let count = near
            .iter()
            .filter(|p| libm::fabsf((**p - a).dot(nrm)) <= thin)
            .count();
        if count < MIN_POINTS as usize || 2 * count < n {
            continue;
        }
        if continues_as_wall(c, &near, a, nrm, thin, on_line, &points) {
            return true;
        }
        tries += 1;
        if tries == MAX_TRIES {
            break;
        }
    }
    false
}

/// Whether the line through `a` with normal `nrm` (refined to the principal axis of the
/// returns `near` within `thin` of it) has the centre `c` on it or behind it and goes on with
/// returns of `points` beyond any furniture's size.
fn continues_as_wall<I: Iterator<Item = Point2>>(
    c: Point2,
    near: &[Point2],
    a: Point2,
    nrm: Point2,
    thin: f32,
    on_line: f32,
    points: &impl Fn() -> I,
) -> bool {
    let inliers = || {
        near.iter()
            .copied()
            .filter(move |p| libm::fabsf((*p - a).dot(nrm)) <= thin)
    };
    let k = inliers().count() as f32;
    let m = inliers().fold(Point2::new(0.0, 0.0), |s, p| s + p);
    let m = Point2::new(m.x / k, m.y / k);
    let (mut cxx, mut cxy, mut cyy) = (0.0f32, 0.0f32, 0.0f32);
    for p in inliers() {
        let d = p - m;
        cxx += d.x * d.x;
        cxy += d.x * d.y;
        cyy += d.y * d.y;
    }
    let angle = 0.5 * libm::atan2f(2.0 * cxy, cxx - cyy);
    let dir = Point2::new(libm::cosf(angle), libm::sinf(angle));
    // The normal towards the LiDAR.
    let mut nrm = Point2::new(-dir.y, dir.x);
    if (Point2::new(0.0, 0.0) - m).dot(nrm) < 0.0 {
        nrm = Point2::new(-nrm.x, -nrm.y);
    }
    let s = (c - m).dot(nrm);
    if !(-BEHIND_M..=IN_FRONT_M).contains(&s) {
        return false;
    }
    // Pass 2: does the line go on beyond any furniture's size, unbroken from the returns
    // near the centre (a tilted fit through a box's face may cross a wall further on, across
    // empty floor)? Returns on it, in cells of CELL_M along it.
    let u0 = (c - m).dot(dir);
    let (mut cells, mut beyond) = (0u64, 0u32);
    for p in points() {
        if libm::fabsf((p - m).dot(nrm)) > on_line {
            continue;
        }
        let u = (p - m).dot(dir) - u0;
        if libm::fabsf(u) >= CONTINUES_TO_M {
            continue;
        }
        cells |= 1 << (((u + CONTINUES_TO_M) / CELL_M) as u32).min(CELLS - 1);
        if p.distance(c) >= CONTINUES_FROM_M {
            beyond += 1;
        }
    }
    if beyond < CONTINUE_POINTS {
        return false;
    }
    // The gap a wall may show: its returns' spacing at this range and incidence, a few times.
    let range = c.norm().max(0.1);
    let cos_inc = (libm::fabsf(c.dot(nrm)) / range).max(0.2);
    let spacing = range * core::f32::consts::PI / 180.0 / cos_inc;
    let gap = (libm::ceilf(MAX_GAP_M.max(2.5 * spacing) / CELL_M) as u32).max(1);
    let mid = CELLS / 2;
    let filled = |k: u32| cells & (1 << k) != 0;
    let from_cells = libm::ceilf(CONTINUES_FROM_M / CELL_M) as u32;
    // Outward from the filled cell nearest the centre, each way, while the gaps stay short.
    let start = (0..=NEAR_CELLS).find_map(|d| {
        [mid.saturating_sub(d), (mid + d).min(CELLS - 1)]
            .into_iter()
            .find(|&k| filled(k))
    });
    let Some(start) = start else {
        return false;
    };
    let mut last = start;
    for k in start + 1..CELLS {
        if filled(k) {
            if k - last - 1 > gap {
                break;
            }
            last = k;
        }
    }
    let mut first = start;
    for k in (0..start).rev() {
        if filled(k) {
            if first - k - 1 > gap {
                break;
            }
            first = k;
        }
    }
    last.saturating_sub(mid) >= from_cells || mid.saturating_sub(first) >= from_cells
}

/// Drops the furniture of `objects` that is a piece of a wall ([`is_wall_piece`]); returns
/// how many. Door frames live in wall lines and are exempt. `pts`: the revolution's returns,
/// converted once a frame ([`returns`]) for this check and the others.
pub fn drop_wall_pieces(
    objects: &mut FrameObjects,
    lidar: &Pose2,
    pts: &[Option<Point2>; BINS],
) -> u32 {
    let before = objects.len();
    objects
        .retain(|o| o.class == ObjectClass::DoorFrame || !is_wall_piece_in(o.centre, lidar, pts));
    (before - objects.len()) as u32
}

#[cfg(test)]
mod test {
    use super::*;

    /// A revolution from the origin: a wall along x = `wall_x`, plus `extra` returns.
    fn scan(wall_x: f32, extra: &[Point2]) -> [f32; BINS] {
        let mut r = [0.0f32; BINS];
        for (d, slot) in r.iter_mut().enumerate() {
            let a = (d as f32).to_radians();
            let c = libm::cosf(a);
            if c > 0.3 {
                *slot = wall_x / c;
            }
        }
        for p in extra {
            let d = (libm::atan2f(p.y, p.x).to_degrees().round() as i32).rem_euclid(360) as usize;
            let range = p.norm();
            if r[d] == 0.0 || range < r[d] {
                r[d] = range;
            }
        }
        r
    }

    /// The four faces of a `w` × `h` box centred at `c` as the returns the LiDAR at the origin
    /// would see (1° bins, nearest face).
    fn box_scan(wall_x: f32, c: Point2, w: f32, h: f32) -> [f32; BINS] {
        let mut r = scan(wall_x, &[]);
        for (d, slot) in r.iter_mut().enumerate() {
            let a = (d as f32).to_radians();
            let (dx, dy) = (libm::cosf(a), libm::sinf(a));
            // Slab intersection of the ray with the axis-aligned box.
            let (x0, x1) = (c.x - w / 2.0, c.x + w / 2.0);
            let (y0, y1) = (c.y - h / 2.0, c.y + h / 2.0);
            let tx = if dx.abs() > 1e-6 {
                ((x0 / dx).min(x1 / dx), (x0 / dx).max(x1 / dx))
            } else {
                (f32::NEG_INFINITY, f32::INFINITY)
            };
            let ty = if dy.abs() > 1e-6 {
                ((y0 / dy).min(y1 / dy), (y0 / dy).max(y1 / dy))
            } else {
                (f32::NEG_INFINITY, f32::INFINITY)
            };
            let (t0, t1) = (tx.0.max(ty.0), tx.1.min(ty.1));
            if t0 > 0.0 && t0 <= t1 && (*slot == 0.0 || t0 < *slot) {
                *slot = t0;
            }
        }
        r
    }

    #[test]
    fn a_piece_of_wall_in_it_or_just_behind_is_wall() {
        let r = scan(2.5, &[]);
        let at = Pose2::IDENTITY;
        assert!(is_wall_piece(Point2::new(2.5, 0.4), &at, &r));
        assert!(is_wall_piece(Point2::new(2.7, -0.6), &at, &r));
        assert!(is_wall_piece(Point2::new(2.45, 1.0), &at, &r));
        // In the room, away from the wall; far behind it; no returns near it.
        assert!(!is_wall_piece(Point2::new(1.5, 0.0), &at, &r));
        assert!(!is_wall_piece(Point2::new(3.2, 0.0), &at, &r));
        assert!(!is_wall_piece(Point2::new(f32::NAN, 0.0), &at, &r));
        // The same seen from a robot elsewhere, turned: the map frame is respected.
        let robot = Pose2::new(1.0, 2.0, 0.7);
        let wall_in_map = robot.transform(Point2::new(2.5, 0.4));
        assert!(is_wall_piece(wall_in_map, &robot, &r));
    }

    /// `r` with the simulator's worst range noise (σ = 2.5 % of range), drawn reproducibly.
    fn noisy(mut r: [f32; BINS], seed: u32) -> [f32; BINS] {
        let mut x = seed;
        let mut uniform = || {
            x = x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (x >> 8) as f32 / (1u32 << 24) as f32
        };
        for v in r.iter_mut().filter(|v| **v > 0.0) {
            // Irwin–Hall: the sum of 12 uniforms less 6 is close to a standard normal.
            let z: f32 = (0..12).map(|_| uniform()).sum::<f32>() - 6.0;
            *v *= 1.0 + NOISE_FRAC * z;
        }
        r
    }

    #[test]
    fn within_the_range_noise_too() {
        let at = Pose2::IDENTITY;
        for seed in 1..6 {
            let r = noisy(scan(2.5, &[]), seed);
            assert!(is_wall_piece(Point2::new(2.5, 0.4), &at, &r), "seed {seed}");
            let c = Point2::new(1.6, -0.5);
            let r = noisy(box_scan(3.0, c, 0.4, 0.6), seed);
            assert!(!is_wall_piece(c, &at, &r), "seed {seed}");
            let c = Point2::new(2.8, 0.3);
            let r = noisy(box_scan(3.0, c, 0.4, 0.6), seed);
            assert!(!is_wall_piece(c, &at, &r), "seed {seed}");
        }
    }

    #[test]
    fn a_piece_at_a_corner_is_wall() {
        // Walls x = 2.5 and y = 1.2 meet at (2.5, 1.2); a phantom just inside the corner.
        let side: std::vec::Vec<Point2> = (0..40)
            .map(|k| Point2::new(0.6 + 0.05 * k as f32, 1.2))
            .collect();
        let mut r = scan(2.5, &side);
        // The wall x = 2.5 ends at the corner.
        for (d, slot) in r.iter_mut().enumerate() {
            let a = (d as f32).to_radians();
            if *slot * libm::sinf(a) > 1.21 {
                *slot = 0.0;
            }
        }
        assert!(is_wall_piece(Point2::new(2.4, 1.05), &Pose2::IDENTITY, &r));
    }

    #[test]
    fn furniture_against_a_wall_and_in_the_open_is_not() {
        let at = Pose2::IDENTITY;
        // A 0.6 × 0.4 box against the wall at x = 3 (its back face on the wall), and one in
        // the open: its front face is thin and straight, but ends with the box.
        let c = Point2::new(2.8, 0.3);
        let r = box_scan(3.0, c, 0.4, 0.6);
        assert!(!is_wall_piece(c, &at, &r));
        let c = Point2::new(1.6, -0.5);
        let r = box_scan(3.0, c, 0.4, 0.6);
        assert!(!is_wall_piece(c, &at, &r));
        // A chair's four legs against the wall.
        let legs = [
            Point2::new(2.4, 0.2),
            Point2::new(2.4, -0.2),
            Point2::new(2.78, 0.2),
            Point2::new(2.78, -0.2),
        ];
        let r = scan(2.8, &legs);
        assert!(!is_wall_piece(Point2::new(2.6, 0.0), &at, &r));
    }
}
