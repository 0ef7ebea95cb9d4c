//! Labels from the ground truth.
//!
//! **Method B boxes** ([`yolo_boxes`]): for a raster of revolutions t, t−1, t−2, each object
//! (furniture or door frame) that returned at least [`MIN_RETURNS`] readings in those three
//! revolutions gets a box computed from its footprint in the LiDAR's pose at the middle of
//! revolution t−1, turned to the image's first column (`perception::seam`):
//!
//! * columns: the smallest arc of bearings (degrees counter-clockwise, our raster's column
//!   convention) containing the footprint's corners, padded by [`PAD_COLS`] each side. An arc
//!   that crosses the 0°/360° seam is cut at the seam and the larger part kept (YOLO boxes
//!   cannot wrap);
//! * rows: from the nearest point of the footprint to its farthest corner, through the raster's
//!   own row mapping, padded by [`PAD_ROWS`] each side; objects whose nearest point is beyond
//!   the raster's max range are left out;
//! * normalised by the real image size, 384 × 64 (the study divided x by 359).
//!
//! **Per-reading labels** ([`hit_code`]): what each reading hit, as an integer code.

use perception::class::ObjectClass;
use perception::geometry::{Point2, Pose2};
use perception::raster::{RASTER_H, RASTER_W, RasterConfig, SCAN_COLUMNS, row_for_range};
use perception::seam::turned;
use perception::sweep::Sweep;

use crate::lds01::LIDAR_MOUNT;
use crate::scenario::Frame;
use crate::world::{Surface, World};

/// Returned readings an object needs across the three revolutions to get a box.
pub const MIN_RETURNS: usize = 3;
/// Column padding each side, pixels (1 px = 1°).
pub const PAD_COLS: f32 = 2.0;
/// Row padding each side, pixels (1 px ≈ 6.3 cm at 4 m max range).
pub const PAD_ROWS: f32 = 1.0;

/// A box in raster pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelBox {
    /// Class.
    pub class: ObjectClass,
    /// Centre column, px.
    pub cx: f32,
    /// Centre row, px.
    pub cy: f32,
    /// Width, px.
    pub w: f32,
    /// Height, px.
    pub h: f32,
}

impl PixelBox {
    /// The Ultralytics label line: `class cx cy w h`, normalised by 384 × 64.
    pub fn yolo_line(&self) -> String {
        format!(
            "{} {:.6} {:.6} {:.6} {:.6}",
            self.class as u8,
            self.cx / RASTER_W as f32,
            self.cy / RASTER_H as f32,
            self.w / RASTER_W as f32,
            self.h / RASTER_H as f32
        )
    }
}

/// Integer code of what a reading hit: −1 nothing returned, 0 wall, `1 + n` furniture `n`,
/// `10_000 + n` door frame `n`, `20_000 + n` clutter `n`, `30_000 + n` walking person `n`. A reading that hit something but did
/// not return (a dropout) is −1: the code says what the sensor *reported*.
pub fn hit_code(frame: &Frame, d: usize) -> i32 {
    let r = &frame.readings[d % SCAN_COLUMNS];
    if r.raw.range_mm == 0 {
        return -1;
    }
    match r.hit {
        None => -1,
        Some(Surface::Wall) => 0,
        Some(Surface::Object(n)) => 1 + i32::from(n),
        Some(Surface::DoorFrame(n)) => 10_000 + i32::from(n),
        Some(Surface::Clutter(n)) => 20_000 + i32::from(n),
        Some(Surface::Person(n)) => 30_000 + i32::from(n),
    }
}

fn returns_of(frames: [&Frame; 3], surface: Surface) -> usize {
    frames
        .iter()
        .flat_map(|f| f.readings.iter())
        .filter(|r| r.raw.range_mm != 0 && r.hit == Some(surface))
        .count()
}

/// The box of a footprint seen from `lidar` (world pose of the LiDAR), if it is in range.
pub fn footprint_box(
    class: ObjectClass,
    footprint: &[Point2; 4],
    lidar: &Pose2,
    cfg: &RasterConfig,
) -> Option<PixelBox> {
    let inv = lidar.inverse();
    local_box(class, footprint.map(|c| inv.transform(c)), cfg)
}

/// The box of a footprint as the sweep read it: each corner at the bearing, and from the
/// LiDAR's place, of the instant its bearing was read (`perception::sweep`), then turned to
/// the image's first column `seam`. In range or `None`, as [`footprint_box`].
pub fn swept_box(
    class: ObjectClass,
    footprint: &[Point2; 4],
    sweep: &Sweep,
    seam: usize,
    cfg: &RasterConfig,
) -> Option<PixelBox> {
    let turn = turned(&Pose2::IDENTITY, seam).inverse();
    local_box(
        class,
        footprint.map(|c| turn.transform(sweep.bearing_of(c).1)),
        cfg,
    )
}

/// The box of footprint corners given in the image's LiDAR frame.
fn local_box(class: ObjectClass, local: [Point2; 4], cfg: &RasterConfig) -> Option<PixelBox> {
    let origin = Point2::default();
    let near = (0..4)
        .map(|i| origin.distance_to_segment(local[i], local[(i + 1) % 4]))
        .fold(f32::INFINITY, f32::min);
    let far = local.iter().map(|p| p.norm()).fold(0.0, f32::max);
    if near > cfg.max_range_m || near < 1e-3 {
        return None; // out of the image, or the LiDAR is inside the footprint
    }
    let mut deg = local.map(|p| p.y.atan2(p.x).to_degrees().rem_euclid(360.0));
    deg.sort_by(f32::total_cmp);
    // The largest gap between consecutive bearings is where the object is not.
    let mut gap_after = 3;
    let mut gap = deg[0] + 360.0 - deg[3];
    for i in 0..3 {
        if deg[i + 1] - deg[i] > gap {
            gap = deg[i + 1] - deg[i];
            gap_after = i;
        }
    }
    let start = deg[(gap_after + 1) % 4];
    let end = deg[gap_after];
    let (c0, c1) = if end >= start {
        (start, end)
    } else if 360.0 - start >= end {
        (start, 360.0)
    } else {
        (0.0, end)
    };
    let c0 = (c0 - PAD_COLS).max(0.0);
    let c1 = (c1 + 1.0 + PAD_COLS).min(SCAN_COLUMNS as f32);
    let r0 = row_for_range(near, cfg)? as f32;
    let r1 = row_for_range(far, cfg).map_or(RASTER_H as f32 - 1.0, |r| r as f32);
    let r0 = (r0 - PAD_ROWS).max(0.0);
    let r1 = (r1 + 1.0 + PAD_ROWS).min(RASTER_H as f32);
    Some(PixelBox {
        class,
        cx: (c0 + c1) / 2.0,
        cy: (r0 + r1) / 2.0,
        w: c1 - c0,
        h: r1 - r0,
    })
}

/// Boxes for the raster of `frames` = [t, t−1, t−2] drawn from bin `seam` on
/// (`perception::seam`: column `c` is bearing `c + seam`), appended to `out`. `deskew`: each
/// footprint as revolution t−1's sweep read it ([`swept_box`]); else from the pose at its
/// middle.
pub fn yolo_boxes(
    world: &World,
    frames: [&Frame; 3],
    cfg: &RasterConfig,
    seam: usize,
    deskew: bool,
    out: &mut Vec<PixelBox>,
) {
    let lidar = turned(&frames[1].pose_mid.compose(&LIDAR_MOUNT), seam);
    let sweep = Sweep {
        start: frames[1].pose_start,
        end: frames[1].pose_end,
        mount: LIDAR_MOUNT,
    };
    let label = |class, footprint: &[Point2; 4]| {
        if deskew {
            swept_box(class, footprint, &sweep, seam, cfg)
        } else {
            footprint_box(class, footprint, &lidar, cfg)
        }
    };
    for (n, o) in world.objects.iter().enumerate() {
        if returns_of(frames, Surface::Object(n as u16)) >= MIN_RETURNS
            && let Some(b) = label(o.class, &o.footprint)
        {
            out.push(b);
        }
    }
    for (n, d) in world.doors.iter().enumerate() {
        if returns_of(frames, Surface::DoorFrame(n as u16)) >= MIN_RETURNS
            && let Some(b) = label(ObjectClass::DoorFrame, &d.footprint)
        {
            out.push(b);
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn square(c: Point2, h: f32) -> [Point2; 4] {
        [
            Point2::new(c.x - h, c.y - h),
            Point2::new(c.x + h, c.y - h),
            Point2::new(c.x + h, c.y + h),
            Point2::new(c.x - h, c.y + h),
        ]
    }

    #[test]
    fn box_left_of_the_robot() {
        // A 0.4 m square 2 m to the left: bearing 90°, rows around 2 m.
        let b = footprint_box(
            ObjectClass::Box,
            &square(Point2::new(0.0, 2.0), 0.2),
            &Pose2::IDENTITY,
            &RasterConfig::default(),
        )
        .unwrap();
        assert!((b.cx - 90.5).abs() < 0.6, "{b:?}");
        // atan(0.2/1.8) ≈ 6.34° each side, plus padding and the 1 px pixel width.
        assert!(
            (b.w - (2.0 * 6.34 + 1.0 + 2.0 * PAD_COLS)).abs() < 0.2,
            "{b:?}"
        );
        // Near 1.8 m → row 28, far corner √(2.2² + 0.2²) = 2.209 → row 34.
        assert_eq!((b.cy - b.h / 2.0, b.cy + b.h / 2.0), (27.0, 36.0));
    }

    #[test]
    fn box_across_the_seam_keeps_the_larger_part() {
        // Straight ahead, a bit to the right: bearings from about −8° to +4°.
        let fp = square(Point2::new(2.0, -0.1), 0.2);
        let b = footprint_box(
            ObjectClass::Chair,
            &fp,
            &Pose2::IDENTITY,
            &RasterConfig::default(),
        )
        .unwrap();
        // The part at 352°..360° is larger than the part at 0°..4°.
        assert!(b.cx > 340.0 && b.cx + b.w / 2.0 <= 360.0, "{b:?}");
        let line = b.yolo_line();
        assert!(line.starts_with("0 "), "{line}");
    }

    /// The bins whose ray, cast from where the sweep stood when it read them, crosses the
    /// footprint: brute force, 1 cm steps.
    fn bins_hit(fp: &[Point2; 4], sweep: &Sweep) -> Vec<usize> {
        let inside = |p: Point2| {
            let mut c = false;
            for i in 0..4 {
                let (a, b) = (fp[i], fp[(i + 1) % 4]);
                if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x
                {
                    c = !c;
                }
            }
            c
        };
        (0..360)
            .filter(|&d| (1..400).any(|k| inside(sweep.point(d as f32, k as f32 * 0.01))))
            .collect()
    }

    #[test]
    fn a_swept_label_covers_the_bins_that_read_it_on_a_turn() {
        // A tour's turn: 1.5 rad/s and 0.05 m forward in one revolution.
        let sweep = Sweep {
            start: Pose2::new(0.0, 0.0, 0.0),
            end: Pose2::new(0.05, 0.0, 0.3),
            mount: LIDAR_MOUNT,
        };
        let cfg = RasterConfig::default();
        for (centre, seam) in [
            (Point2::new(0.0, 2.0), 0),
            (Point2::new(-1.5, -1.0), 0),
            (Point2::new(1.2, -1.6), 0),
            (Point2::new(0.0, 2.0), 37),
            (Point2::new(1.5, 1.3), 0),
        ] {
            let fp = square(centre, 0.25);
            let hit = bins_hit(&fp, &sweep);
            let (first, last) = (*hit.first().unwrap(), *hit.last().unwrap());
            assert_eq!(last - first + 1, hit.len(), "one run of bins: {hit:?}");
            let b = swept_box(ObjectClass::Box, &fp, &sweep, seam, &cfg).unwrap();
            // Columns [b0, b1 + 1) padded by PAD_COLS: the bins read are b0..=b1.
            let (c0, c1) = (
                b.cx - b.w / 2.0 + PAD_COLS,
                b.cx + b.w / 2.0 - 1.0 - PAD_COLS,
            );
            let (f, l) = ((first - seam) as f32, (last - seam) as f32);
            // Within the bin each edge falls in (1°): the footprint's bearings at their read
            // instants.
            assert!(
                f - 1.0 <= c0 && c0 <= f + 0.01,
                "{centre:?}: {c0} vs bins from {f}"
            );
            assert!(
                l - 0.01 <= c1 && c1 <= l + 1.0,
                "{centre:?}: {c1} vs bins to {l}"
            );
            // From the middle's pose the label is off by the turn between the middle and
            // the read instant: 0.3 rad × (fraction − ½), 4–6° for the bins read 0.25 of a
            // revolution or more from the middle.
            let mid = sweep.lidar_at(179.5);
            let m = footprint_box(ObjectClass::Box, &fp, &turned(&mid, seam), &cfg).unwrap();
            let off = (m.cx - b.cx).abs();
            let fraction = (359.0 - (first + last) as f32 / 2.0) / 360.0;
            if (fraction - 0.5).abs() > 0.2 {
                assert!(off > 3.0, "{centre:?}: the middle's label only {off}° off");
            }
        }
    }

    #[test]
    fn out_of_range_is_left_out() {
        let fp = square(Point2::new(5.0, 0.0), 0.2);
        assert!(
            footprint_box(
                ObjectClass::Box,
                &fp,
                &Pose2::IDENTITY,
                &RasterConfig::default()
            )
            .is_none()
        );
    }
}
