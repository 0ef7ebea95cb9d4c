//! Whether a detection can be furniture, given the walls the revolution showed. Furniture
//! stands in the room: a centre within a wall's thickness of a wall line, or behind a wall
//! (the sight line from the LiDAR crosses the wall before reaching it), is a piece of the wall,
//! a mixed pixel or a detection completed into space the LiDAR cannot see — not an object.
//! Door frames live in wall lines and are exempt.
//!
//! The same holds for the walls the map has gathered over revolutions ([`drop_in_map_walls`],
//! [`crate::wall_map`]): a wall broken in this revolution is still whole there.
//!
//! Only long segments vote ([`WALL_MIN_M`]): the face of a box is a short segment, and its own
//! centre lies behind it.

use crate::class::ObjectClass;
use crate::fusion::FrameObjects;
use crate::geometry::Point2;
use crate::wall_map::WallMap;
use crate::walls::Segment;

/// Segments shorter than this are not trusted as walls, m (a box's longest face is ~0.8 m).
pub const WALL_MIN_M: f32 = 1.0;
/// A centre this close to a wall line is inside the wall, m.
pub const IN_WALL_M: f32 = 0.1;

/// Whether `p`, seen from `sensor`, lies in or behind one of `walls`.
pub fn in_or_behind_wall(sensor: Point2, p: Point2, walls: &[Segment]) -> bool {
    walls
        .iter()
        .filter(|w| w.length() >= WALL_MIN_M)
        .any(|w| p.distance_to_segment(w.a, w.b) < IN_WALL_M || crosses(sensor, p, w))
}

/// Whether the sight line `s → p` crosses `w` more than [`IN_WALL_M`] before `p`.
fn crosses(s: Point2, p: Point2, w: &Segment) -> bool {
    let d = p - s;
    let e = w.b - w.a;
    let denom = d.x * e.y - d.y * e.x;
    if denom.abs() < 1e-9 {
        return false;
    }
    let q = w.a - s;
    let t = (q.x * e.y - q.y * e.x) / denom; // along the sight line, 0..1 = s..p
    let u = (q.x * d.y - q.y * d.x) / denom; // along the wall
    let len = s.distance(p);
    (0.0..=1.0).contains(&u) && t > 0.0 && t * len < len - IN_WALL_M
}

/// Drops the furniture of `objects` that lies in or behind a wall; returns how many.
pub fn drop_walled(objects: &mut FrameObjects, sensor: Point2, walls: &[Segment]) -> u32 {
    let before = objects.len();
    objects.retain(|o| {
        o.class == ObjectClass::DoorFrame || !in_or_behind_wall(sensor, o.centre, walls)
    });
    (before - objects.len()) as u32
}

/// Drops the furniture of `objects` whose centre lies in the band of a wall `map` holds;
/// returns how many.
pub fn drop_in_map_walls(objects: &mut FrameObjects, map: &WallMap) -> u32 {
    let before = objects.len();
    objects.retain(|o| o.class == ObjectClass::DoorFrame || !map.holds(o.centre));
    (before - objects.len()) as u32
}

#[cfg(test)]
mod test {
    use super::*;

    fn wall(ax: f32, ay: f32, bx: f32, by: f32) -> Segment {
        Segment {
            a: Point2::new(ax, ay),
            b: Point2::new(bx, by),
            support: 20,
        }
    }

    #[test]
    fn in_the_room_in_the_wall_and_behind_it() {
        let walls = [wall(3.0, -2.0, 3.0, 2.0)];
        let s = Point2::new(0.0, 0.0);
        // A chair 0.25 m in front of the wall: furniture against a wall stays.
        assert!(!in_or_behind_wall(s, Point2::new(2.75, 0.5), &walls));
        // On the wall line, and beyond it.
        assert!(in_or_behind_wall(s, Point2::new(3.05, 0.5), &walls));
        assert!(in_or_behind_wall(s, Point2::new(3.6, 1.0), &walls));
        // Beyond the wall's end (a doorway, or open space): nothing says no.
        assert!(!in_or_behind_wall(s, Point2::new(4.0, 3.5), &walls));
    }

    #[test]
    fn short_segments_do_not_vote() {
        // A box's 0.6 m face: the box's own centre is behind it.
        let face = [wall(2.0, -0.3, 2.0, 0.3)];
        assert!(!in_or_behind_wall(
            Point2::new(0.0, 0.0),
            Point2::new(2.2, 0.0),
            &face
        ));
    }
}
