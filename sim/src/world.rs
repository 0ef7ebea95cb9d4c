//! A seeded 2D world as seen at LiDAR height: a rectangular room (walls as inner faces) with
//! square boxes, and ray casting against its segments.

use perception::geometry::Point2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A line segment, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// One end.
    pub a: Point2,
    /// The other end.
    pub b: Point2,
}

/// A room: segments in the world frame, and a free spot for the robot.
#[derive(Debug, Clone)]
pub struct World {
    /// Room width (x) and depth (y), metres; the room spans [0, w] × [0, h].
    pub size: (f32, f32),
    /// Every surface a ray can hit.
    pub segments: Vec<Segment>,
    /// Box centres and half sizes (for tests and labels).
    pub boxes: Vec<(Point2, f32)>,
    /// A spot at least 0.7 m from every surface.
    pub robot_start: Point2,
}

impl World {
    /// A random room 3–8 m a side with 2–5 boxes 0.3–0.6 m wide, from `seed`.
    pub fn random_room(seed: u64) -> World {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let w = rng.random_range(3.0..8.0f32);
        let h = rng.random_range(3.0..8.0f32);
        let mut world = World {
            size: (w, h),
            segments: Vec::new(),
            boxes: Vec::new(),
            robot_start: Point2::new(w / 2.0, h / 2.0),
        };
        let corners = [
            Point2::new(0.0, 0.0),
            Point2::new(w, 0.0),
            Point2::new(w, h),
            Point2::new(0.0, h),
        ];
        for i in 0..4 {
            world.segments.push(Segment {
                a: corners[i],
                b: corners[(i + 1) % 4],
            });
        }
        let n_boxes = rng.random_range(2..=5);
        let mut tries = 0;
        while world.boxes.len() < n_boxes && tries < 200 {
            tries += 1;
            let half = rng.random_range(0.15..0.3f32);
            let c = Point2::new(
                rng.random_range(half + 0.2..w - half - 0.2),
                rng.random_range(half + 0.2..h - half - 0.2),
            );
            let clear_of_robot = c.distance(world.robot_start) > half * 1.5 + 0.7;
            let clear_of_boxes = world
                .boxes
                .iter()
                .all(|(o, oh)| c.distance(*o) > (half + oh) * 1.5 + 0.7);
            if clear_of_robot && clear_of_boxes {
                world.add_box(c, half);
            }
        }
        world
    }

    fn add_box(&mut self, c: Point2, half: f32) {
        let p = [
            Point2::new(c.x - half, c.y - half),
            Point2::new(c.x + half, c.y - half),
            Point2::new(c.x + half, c.y + half),
            Point2::new(c.x - half, c.y + half),
        ];
        for i in 0..4 {
            self.segments.push(Segment {
                a: p[i],
                b: p[(i + 1) % 4],
            });
        }
        self.boxes.push((c, half));
    }

    /// Distance from `origin` along the unit direction at `angle` (world frame, radians) to the
    /// nearest surface, or `None` if nothing is hit.
    pub fn raycast(&self, origin: Point2, angle: f32) -> Option<f32> {
        let d = Point2::new(angle.cos(), angle.sin());
        self.segments
            .iter()
            .filter_map(|s| ray_segment(origin, d, s))
            .min_by(f32::total_cmp)
    }
}

/// Ray (origin, unit direction) against a segment: the distance along the ray, if it hits.
fn ray_segment(o: Point2, d: Point2, s: &Segment) -> Option<f32> {
    let e = s.b - s.a;
    let denom = d.x * e.y - d.y * e.x;
    if denom.abs() < 1e-9 {
        return None;
    }
    let w = s.a - o;
    let t = (w.x * e.y - w.y * e.x) / denom;
    let u = (w.x * d.y - w.y * d.x) / denom;
    (t > 1e-6 && (0.0..=1.0).contains(&u)).then_some(t)
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn seeded_and_reproducible() {
        let a = World::random_room(7);
        let b = World::random_room(7);
        assert_eq!(a.segments, b.segments);
        assert_ne!(a.segments, World::random_room(8).segments);
        assert!(a.boxes.len() >= 2);
    }

    #[test]
    fn ray_hits_walls_of_empty_room() {
        let mut w = World::random_room(1);
        w.segments.truncate(4);
        let (sx, sy) = w.size;
        let o = Point2::new(1.0, 1.0);
        assert!((w.raycast(o, 0.0).unwrap() - (sx - 1.0)).abs() < 1e-4);
        assert!((w.raycast(o, core::f32::consts::FRAC_PI_2).unwrap() - (sy - 1.0)).abs() < 1e-4);
        assert!((w.raycast(o, core::f32::consts::PI).unwrap() - 1.0).abs() < 1e-4);
    }
}
