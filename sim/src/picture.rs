//! A PNG picture of a scene, for people: the floor, walls, door frames, furniture coloured by
//! class with its footprint, clutter, the robot's path, and one revolution's returns.
//!
//! Colours: walls black; door frames orange; chairs blue, boxes brown, desks green (footprints
//! outlined, legs filled); clutter grey; robot path red; robot start a red disc; the robot
//! during the revolution shown a purple disc, that revolution's returns magenta. 100 px per
//! metre.

use std::io::Write;

use perception::class::ObjectClass;
use perception::geometry::Point2;

use crate::lds01::LIDAR_MOUNT;
use crate::scenario::Frame;
use crate::world::{Shape, Surface, World};

/// Pixels per metre.
pub const PX_PER_M: f32 = 100.0;

type Rgb = [u8; 3];

struct Canvas {
    w: usize,
    h: usize,
    px: Vec<u8>,
    origin: Point2,
}

impl Canvas {
    fn put(&mut self, x: i64, y: i64, c: Rgb) {
        if x >= 0 && y >= 0 && (x as usize) < self.w && (y as usize) < self.h {
            let i = (y as usize * self.w + x as usize) * 3;
            self.px[i..i + 3].copy_from_slice(&c);
        }
    }

    fn to_px(&self, p: Point2) -> (f32, f32) {
        // y up in the world, down in the image.
        (
            (p.x - self.origin.x) * PX_PER_M,
            self.h as f32 - (p.y - self.origin.y) * PX_PER_M,
        )
    }

    fn line(&mut self, a: Point2, b: Point2, c: Rgb, width: i64) {
        let (ax, ay) = self.to_px(a);
        let (bx, by) = self.to_px(b);
        let n = (bx - ax).abs().max((by - ay).abs()).ceil().max(1.0) as usize;
        for i in 0..=n {
            let t = i as f32 / n as f32;
            let (x, y) = ((ax + (bx - ax) * t) as i64, (ay + (by - ay) * t) as i64);
            for dy in 0..width {
                for dx in 0..width {
                    self.put(x + dx - width / 2, y + dy - width / 2, c);
                }
            }
        }
    }

    fn disc(&mut self, p: Point2, r_m: f32, c: Rgb) {
        let (cx, cy) = self.to_px(p);
        let r = (r_m * PX_PER_M).max(1.0);
        let ri = r.ceil() as i64;
        for dy in -ri..=ri {
            for dx in -ri..=ri {
                if (dx * dx + dy * dy) as f32 <= r * r {
                    self.put(cx as i64 + dx, cy as i64 + dy, c);
                }
            }
        }
    }

    fn fill_rect(&mut self, lo: Point2, hi: Point2, c: Rgb) {
        let (x0, y1) = self.to_px(lo);
        let (x1, y0) = self.to_px(hi);
        for y in y0 as i64..y1 as i64 {
            for x in x0 as i64..x1 as i64 {
                self.put(x, y, c);
            }
        }
    }
}

fn class_colour(c: ObjectClass) -> Rgb {
    match c {
        ObjectClass::Chair => [40, 90, 220],
        ObjectClass::Box => [150, 95, 40],
        ObjectClass::Desk => [30, 150, 60],
        ObjectClass::DoorFrame => [240, 140, 0],
    }
}

/// Draws the scene and writes it as PNG to `out`. `path` is the robot's path (world frame);
/// `frame`, if given, adds that revolution's returns.
pub fn write_png(
    world: &World,
    path: &[Point2],
    frame: Option<&Frame>,
    out: impl Write,
) -> Result<(), png::EncodingError> {
    let (mut lo, mut hi) = (
        Point2::new(f32::MAX, f32::MAX),
        Point2::new(f32::MIN, f32::MIN),
    );
    for p in &world.prims {
        let (a, b) = p.shape.bounds();
        lo = Point2::new(lo.x.min(a.x), lo.y.min(a.y));
        hi = Point2::new(hi.x.max(b.x), hi.y.max(b.y));
    }
    let margin = 0.3;
    let origin = Point2::new(lo.x - margin, lo.y - margin);
    let w = ((hi.x - lo.x + 2.0 * margin) * PX_PER_M).ceil() as usize;
    let h = ((hi.y - lo.y + 2.0 * margin) * PX_PER_M).ceil() as usize;
    let mut cv = Canvas {
        w,
        h,
        px: vec![255; w * h * 3],
        origin,
    };
    for (a, b) in &world.floor {
        cv.fill_rect(*a, *b, [236, 236, 236]);
    }
    for o in &world.objects {
        for i in 0..4 {
            cv.line(
                o.footprint[i],
                o.footprint[(i + 1) % 4],
                class_colour(o.class),
                1,
            );
        }
    }
    for d in &world.doors {
        for i in 0..4 {
            cv.line(
                d.footprint[i],
                d.footprint[(i + 1) % 4],
                class_colour(ObjectClass::DoorFrame),
                1,
            );
        }
    }
    for p in &world.prims {
        let colour = match p.surface {
            Surface::Wall => [0, 0, 0],
            Surface::DoorFrame(_) => class_colour(ObjectClass::DoorFrame),
            Surface::Object(n) => class_colour(world.objects[usize::from(n)].class),
            Surface::Clutter(_) | Surface::Person(_) => [128, 128, 128],
        };
        match p.shape {
            Shape::Segment { a, b } => cv.line(a, b, colour, 3),
            Shape::Circle { c, r } => cv.disc(c, r, colour),
        }
    }
    for s in path.windows(2) {
        cv.line(s[0], s[1], [220, 30, 30], 2);
    }
    if let Some(f) = frame {
        cv.disc(
            Point2::new(f.pose_mid.x, f.pose_mid.y),
            0.105,
            [120, 0, 110],
        );
        let lidar = f.pose_mid.compose(&LIDAR_MOUNT);
        for (d, r) in f.readings.iter().enumerate() {
            if r.raw.range_mm > 0 {
                let a = lidar.theta + (d as f32).to_radians();
                let range = f32::from(r.raw.range_mm) / 1000.0;
                let p = Point2::new(lidar.x + range * a.cos(), lidar.y + range * a.sin());
                cv.disc(p, 0.015, [230, 0, 200]);
            }
        }
    }
    cv.disc(world.robot_start, 0.1, [220, 30, 30]);
    let mut enc = png::Encoder::new(out, w as u32, h as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header()?;
    writer.write_image_data(&cv.px)?;
    writer.finish()
}
