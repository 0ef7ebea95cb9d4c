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
    let local = footprint.map(|c| inv.transform(c));
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
/// (`perception::seam`: column `c` is bearing `c + seam`), appended to `out`.
pub fn yolo_boxes(
    world: &World,
    frames: [&Frame; 3],
    cfg: &RasterConfig,
    seam: usize,
    out: &mut Vec<PixelBox>,
) {
    let lidar = turned(&frames[1].pose_mid.compose(&LIDAR_MOUNT), seam);
    for (n, o) in world.objects.iter().enumerate() {
        if returns_of(frames, Surface::Object(n as u16)) >= MIN_RETURNS
            && let Some(b) = footprint_box(o.class, &o.footprint, &lidar, cfg)
        {
            out.push(b);
        }
    }
    for (n, d) in world.doors.iter().enumerate() {
        if returns_of(frames, Surface::DoorFrame(n as u16)) >= MIN_RETURNS
            && let Some(b) = footprint_box(ObjectClass::DoorFrame, &d.footprint, &lidar, cfg)
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
