//! Walls: which clusters are walls, line segments fitted to them, and corners.
//!
//! **Wall test** (on the cluster's principal-axes box): area > `wall_area_m2` (2.0 m²) or
//! aspect > `wall_aspect` (4.0). The aspect rule only counts for a box at least
//! `wall_min_length_m` (0.8 m) long: a box seen on one face is a thin 0.3–0.7 m line with an
//! aspect of 20 or more, and the study's rule alone calls it a wall.
//!
//! **Segments.** A wall cluster (often a whole room outline joined at its corners) is ordered
//! by bearing from the sensor: its points are averaged into [`BEARING_BINS`] bins of 0.5°, and
//! the bin means, in bearing order starting after the widest empty arc, form polylines (broken
//! where consecutive means are over `chain_break_m` apart). Each polyline is split recursively
//! at its farthest vertex from the chord while that is over `split_tol_m` (iterative end-point
//! fit), and each run of at least [`MIN_RUN_VERTICES`] vertices and `min_segment_m` length gets
//! a total-least-squares line; its ends are the projections of the run's first and last vertex.
//! Consecutive runs on one line (split apart by an outlier) are merged back into one segment;
//! without that step a wall with a few ghost returns breaks into pieces whose gaps look like
//! doorways.
//!
//! **Corners**: consecutive segments of one polyline whose directions differ by more than
//! `corner_min_deg` (35°) meet at a corner, placed at their lines' intersection when that lies
//! within `corner_reach_m` of both facing ends.

use crate::geometry::Point2;
use heapless::Vec;

/// Bearing bins per cluster (0.5° each).
pub const BEARING_BINS: usize = 720;
/// Wall segments kept per frame at most.
pub const MAX_SEGMENTS: usize = 64;
/// Corners kept per frame at most.
pub const MAX_CORNERS: usize = 64;
/// Vertices a run needs to become a segment.
pub const MIN_RUN_VERTICES: usize = 4;
/// Pending ranges of the split stack (depth of the recursion it replaces).
const SPLIT_STACK: usize = 64;

/// Wall settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WallConfig {
    /// A cluster whose box is larger is a wall, m².
    pub wall_area_m2: f32,
    /// A cluster whose box is more elongated is a wall...
    pub wall_aspect: f32,
    /// ...if it is at least this long, metres.
    pub wall_min_length_m: f32,
    /// Polylines break where bin means are farther apart, metres.
    pub chain_break_m: f32,
    /// Split tolerance of the end-point fit, metres.
    pub split_tol_m: f32,
    /// Shortest segment kept, metres.
    pub min_segment_m: f32,
    /// Turn that makes a corner, degrees.
    pub corner_min_deg: f32,
    /// Largest distance from a segment end to its corner, metres.
    pub corner_reach_m: f32,
}

impl Default for WallConfig {
    fn default() -> Self {
        WallConfig {
            wall_area_m2: 2.0,
            wall_aspect: 4.0,
            wall_min_length_m: 0.8,
            chain_break_m: 0.5,
            split_tol_m: 0.06,
            min_segment_m: 0.25,
            corner_min_deg: 35.0,
            corner_reach_m: 0.4,
        }
    }
}

/// A wall segment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Segment {
    /// One end (first in bearing order).
    pub a: Point2,
    /// The other end.
    pub b: Point2,
    /// Points (bin means) behind it.
    pub support: u16,
}

impl Segment {
    /// Length, metres.
    pub fn length(&self) -> f32 {
        self.a.distance(self.b)
    }

    /// Direction of `a → b`, radians.
    pub fn angle(&self) -> f32 {
        libm::atan2f(self.b.y - self.a.y, self.b.x - self.a.x)
    }

    /// Distance from `p` to the segment's infinite line.
    pub fn line_distance(&self, p: Point2) -> f32 {
        let d = self.b - self.a;
        let l = d.norm();
        if l < 1e-6 {
            return p.distance(self.a);
        }
        ((p.x - self.a.x) * d.y - (p.y - self.a.y) * d.x).abs() / l
    }
}

/// Bearing-binning scratch, allocated once.
#[derive(Clone)]
pub struct WallScratch {
    sx: [f32; BEARING_BINS],
    sy: [f32; BEARING_BINS],
    n: [u16; BEARING_BINS],
    verts: [Point2; BEARING_BINS],
    weight: [u16; BEARING_BINS],
}

impl Default for WallScratch {
    fn default() -> Self {
        Self::new()
    }
}

impl core::fmt::Debug for WallScratch {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("WallScratch")
    }
}

impl WallScratch {
    /// Zeroed scratch.
    pub const fn new() -> Self {
        WallScratch {
            sx: [0.0; BEARING_BINS],
            sy: [0.0; BEARING_BINS],
            n: [0; BEARING_BINS],
            verts: [Point2::new(0.0, 0.0); BEARING_BINS],
            weight: [0; BEARING_BINS],
        }
    }
}

/// `true` if a cluster with this principal-axes box is a wall.
pub fn is_wall(b: &crate::shape::OrientedBox, cfg: &WallConfig) -> bool {
    b.area() > cfg.wall_area_m2
        || (b.aspect() > cfg.wall_aspect && b.length >= cfg.wall_min_length_m)
}

/// Fits segments to one wall cluster seen from `sensor`; appends them to `out` (up to its
/// capacity; returns how many did not fit) and the corners between them to `corners`.
pub fn fit_segments(
    points: &[Point2],
    sensor: Point2,
    cfg: &WallConfig,
    scratch: &mut WallScratch,
    out: &mut Segments,
    corners: &mut Corners,
) -> u32 {
    let s = scratch;
    s.sx.fill(0.0);
    s.sy.fill(0.0);
    s.n.fill(0);
    let bin_w = core::f32::consts::TAU / BEARING_BINS as f32;
    for p in points {
        let a = libm::atan2f(p.y - sensor.y, p.x - sensor.x) + core::f32::consts::PI;
        let k = ((a / bin_w) as usize).min(BEARING_BINS - 1);
        s.sx[k] += p.x;
        s.sy[k] += p.y;
        s.n[k] = s.n[k].saturating_add(1);
    }
    // Start after the widest empty arc.
    let (mut best_len, mut best_end, mut run) = (0usize, 0usize, 0usize);
    for k in 0..2 * BEARING_BINS {
        if s.n[k % BEARING_BINS] == 0 {
            run += 1;
            if run > best_len {
                best_len = run;
                best_end = k % BEARING_BINS;
            }
        } else {
            run = 0;
        }
    }
    let first = if best_len == 0 {
        0
    } else {
        (best_end + 1) % BEARING_BINS
    };
    let mut nv = 0;
    for i in 0..BEARING_BINS {
        let k = (first + i) % BEARING_BINS;
        if s.n[k] > 0 {
            let n = f32::from(s.n[k]);
            s.verts[nv] = Point2::new(s.sx[k] / n, s.sy[k] / n);
            s.weight[nv] = s.n[k];
            nv += 1;
        }
    }
    let closed = best_len == 0;
    let mut dropped = 0;
    // Chains.
    let mut start = 0;
    while start < nv {
        let mut end = start + 1;
        while end < nv && s.verts[end].distance(s.verts[end - 1]) <= cfg.chain_break_m {
            end += 1;
        }
        dropped += split_chain(
            &s.verts[start..end],
            &s.weight[start..end],
            cfg,
            out,
            corners,
            closed && start == 0 && end == nv,
        );
        start = end;
    }
    dropped
}

fn split_chain(
    v: &[Point2],
    w: &[u16],
    cfg: &WallConfig,
    out: &mut Segments,
    corners: &mut Corners,
    closed: bool,
) -> u32 {
    if v.len() < MIN_RUN_VERTICES {
        return 0;
    }
    // Iterative end-point fit; runs are emitted in order by always splitting the leftmost.
    let mut stack = [(0u16, 0u16); SPLIT_STACK];
    let mut top = 1;
    stack[0] = (0, (v.len() - 1) as u16);
    let first_seg = out.len();
    let mut dropped = 0;
    while top > 0 {
        top -= 1;
        let (i, j) = (stack[top].0 as usize, stack[top].1 as usize);
        let seg = Segment {
            a: v[i],
            b: v[j],
            support: 0,
        };
        let mut far = (0.0f32, i);
        for (k, p) in v.iter().enumerate().take(j).skip(i + 1) {
            let d = seg.line_distance(*p);
            if d > far.0 {
                far = (d, k);
            }
        }
        if far.0 > cfg.split_tol_m && top + 2 <= SPLIT_STACK && far.1 > i && far.1 < j {
            // Push the right half first so the left one is processed next.
            stack[top] = (far.1 as u16, j as u16);
            stack[top + 1] = (i as u16, far.1 as u16);
            top += 2;
            continue;
        }
        if j + 1 - i < MIN_RUN_VERTICES {
            continue;
        }
        if let Some(seg) = fit_line(&v[i..=j], &w[i..=j])
            && seg.length() >= cfg.min_segment_m
        {
            let prev = out.last().copied().filter(|_| out.len() > first_seg);
            match prev {
                // The merge step of split-and-merge: a run split off by an outlier (a
                // ghost return, a mixed pixel) and its neighbour on the same line are one
                // wall again. Consecutive runs of one chain have no gap over
                // `chain_break_m` between their vertices, so a doorway never merges.
                Some(p) if collinear(&p, &seg, cfg) => {
                    let last = out.len() - 1;
                    out[last] = Segment {
                        a: p.a,
                        b: seg.b,
                        support: p.support.saturating_add(seg.support),
                    };
                }
                _ => {
                    if let Some(p) = prev {
                        corner_between(&p, &seg, cfg, corners);
                    }
                    if out.push(seg).is_err() {
                        dropped += 1;
                    }
                }
            }
        }
    }
    let mut joined = false;
    if closed && out.len() >= first_seg + 2 {
        // A closed outline starts mid-wall: join its last and first runs if they are one line.
        let (last, first) = (out[out.len() - 1], out[first_seg]);
        let turn = crate::geometry::wrap_angle(first.angle() - last.angle()).abs();
        if turn.to_degrees() < 5.0 && last.b.distance(first.a) <= cfg.chain_break_m {
            out[first_seg] = Segment {
                a: last.a,
                b: first.b,
                support: last.support.saturating_add(first.support),
            };
            out.pop();
            // The corner found between the last two runs is the joined segment's start.
            joined = true;
        }
    }
    if closed && !joined && out.len() >= first_seg + 3 {
        let (a, b) = (out[out.len() - 1], out[first_seg]);
        corner_between(&a, &b, cfg, corners);
    }
    dropped
}

/// `true` when `b` continues `a`'s line: under 5° apart and `b`'s ends within twice the split
/// tolerance of `a`'s line.
fn collinear(a: &Segment, b: &Segment, cfg: &WallConfig) -> bool {
    let turn = crate::geometry::wrap_angle(b.angle() - a.angle()).abs();
    turn.to_degrees() < 5.0
        && a.line_distance(b.a) <= 2.0 * cfg.split_tol_m
        && a.line_distance(b.b) <= 2.0 * cfg.split_tol_m
}

fn corner_between(a: &Segment, b: &Segment, cfg: &WallConfig, corners: &mut Corners) {
    let turn = crate::geometry::wrap_angle(b.angle() - a.angle()).abs();
    let turn = turn.min(core::f32::consts::PI - turn);
    if turn.to_degrees() <= cfg.corner_min_deg {
        return;
    }
    let (d1, d2) = (a.b - a.a, b.b - b.a);
    let den = d1.x * d2.y - d1.y * d2.x;
    if den.abs() < 1e-9 {
        return;
    }
    let r = b.a - a.a;
    let t = (r.x * d2.y - r.y * d2.x) / den;
    let p = Point2::new(a.a.x + d1.x * t, a.a.y + d1.y * t);
    if p.distance(a.b) <= cfg.corner_reach_m && p.distance(b.a) <= cfg.corner_reach_m {
        let _ = corners.push(p);
    }
}

/// Weighted total-least-squares line through `v`, trimmed to the first and last vertex.
///
/// Hand-rolled on purpose: the 2 × 2 scatter's principal axis has a closed form (one `atan2`);
/// nalgebra's iterative symmetric eigen-solver would add nothing but a dependency here.
fn fit_line(v: &[Point2], w: &[u16]) -> Option<Segment> {
    let (mut sw, mut sx, mut sy) = (0.0f32, 0.0f32, 0.0f32);
    for (p, &k) in v.iter().zip(w) {
        let k = f32::from(k);
        sw += k;
        sx += k * p.x;
        sy += k * p.y;
    }
    if sw <= 0.0 {
        return None;
    }
    let c = Point2::new(sx / sw, sy / sw);
    let (mut xx, mut xy, mut yy) = (0.0f32, 0.0f32, 0.0f32);
    for (p, &k) in v.iter().zip(w) {
        let d = *p - c;
        let k = f32::from(k);
        xx += k * d.x * d.x;
        xy += k * d.x * d.y;
        yy += k * d.y * d.y;
    }
    let ang = 0.5 * libm::atan2f(2.0 * xy, xx - yy);
    let (s, co) = (libm::sinf(ang), libm::cosf(ang));
    let proj = |p: Point2| {
        let t = (p.x - c.x) * co + (p.y - c.y) * s;
        Point2::new(c.x + co * t, c.y + s * t)
    };
    Some(Segment {
        a: proj(v[0]),
        b: proj(v[v.len() - 1]),
        support: v.len().min(u16::MAX as usize) as u16,
    })
}

/// Wall segments of a frame.
pub type Segments = Vec<Segment, MAX_SEGMENTS>;
/// Corners of a frame.
pub type Corners = Vec<Point2, MAX_CORNERS>;

/// A segment from (ax, ay) to (bx, by) with 30 points behind it: the wall piece of the tests of
/// every module that reads segments.
#[cfg(test)]
pub(crate) fn test_seg(ax: f32, ay: f32, bx: f32, by: f32) -> Segment {
    Segment {
        a: Point2::new(ax, ay),
        b: Point2::new(bx, by),
        support: 30,
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn room(w: f32, h: f32, step: f32) -> std::vec::Vec<Point2> {
        let mut pts = std::vec::Vec::new();
        let corners = [
            Point2::new(0.0, 0.0),
            Point2::new(w, 0.0),
            Point2::new(w, h),
            Point2::new(0.0, h),
        ];
        for i in 0..4 {
            let (a, b) = (corners[i], corners[(i + 1) % 4]);
            let n = (a.distance(b) / step) as usize;
            for k in 0..n {
                let t = k as f32 / n as f32;
                pts.push(Point2::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t));
            }
        }
        pts
    }

    #[test]
    fn rectangular_room_gives_four_segments_and_corners() {
        let pts = room(4.0, 3.0, 0.01);
        let mut s = WallScratch::new();
        let (mut segs, mut corners) = (Segments::default(), Corners::default());
        let dropped = fit_segments(
            &pts,
            Point2::new(1.5, 1.2),
            &WallConfig::default(),
            &mut s,
            &mut segs,
            &mut corners,
        );
        assert_eq!(dropped, 0);
        assert_eq!(segs.len(), 4, "{segs:?}");
        let mut lens: std::vec::Vec<f32> = segs.iter().map(|s| s.length()).collect();
        lens.sort_by(f32::total_cmp);
        assert!(
            (lens[0] - 3.0).abs() < 0.1 && (lens[3] - 4.0).abs() < 0.1,
            "{lens:?}"
        );
        assert_eq!(corners.len(), 4, "{corners:?}");
        for c in corners.iter() {
            let near = [(0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 3.0)]
                .iter()
                .any(|&(x, y)| c.distance(Point2::new(x, y)) < 0.1);
            assert!(near, "{c:?}");
        }
    }

    #[test]
    fn wall_test_excludes_a_box_face() {
        use crate::shape::OrientedBox;
        let cfg = WallConfig::default();
        let face = OrientedBox {
            length: 0.6,
            width: 0.02,
            ..Default::default()
        };
        assert!(!is_wall(&face, &cfg));
        let wall = OrientedBox {
            length: 1.5,
            width: 0.05,
            ..Default::default()
        };
        assert!(is_wall(&wall, &cfg));
        let big = OrientedBox {
            length: 1.6,
            width: 1.5,
            ..Default::default()
        };
        assert!(is_wall(&big, &cfg));
    }

    #[test]
    fn empty_and_tiny_inputs() {
        let mut s = WallScratch::new();
        let (mut segs, mut corners) = (Segments::default(), Corners::default());
        let cfg = WallConfig::default();
        fit_segments(
            &[],
            Point2::default(),
            &cfg,
            &mut s,
            &mut segs,
            &mut corners,
        );
        let same = [Point2::new(1.0, 1.0); 100];
        fit_segments(
            &same,
            Point2::default(),
            &cfg,
            &mut s,
            &mut segs,
            &mut corners,
        );
        fit_segments(
            &same,
            Point2::new(1.0, 1.0),
            &cfg,
            &mut s,
            &mut segs,
            &mut corners,
        );
        assert!(segs.is_empty() && corners.is_empty());
    }
}
