//! What the map's walls say of door-frame tracks: one in a doorway they show is an opening in
//! a wall (anchored), one at a corner of them that only Method B has seen is the end of a wall
//! seen end-on (not reported while so).

use crate::class::ObjectClass;
use crate::geometry::Point2;
use crate::wall_map::WallMap;

use super::{CORNER_DOOR_M, Track, Tracks, class_radius};

impl Track {
    /// A door frame only Method B has seen, not in a doorway of the map's walls, at a corner
    /// of them: the end of a wall seen end-on looks like a jamb to Method B (an L-shaped
    /// room's inner corner). Not reported while so.
    pub fn door_at_corner(&self) -> bool {
        self.class() == ObjectClass::DoorFrame && self.at_corner && !self.seen_a && !self.anchored
    }
}

impl Tracks {
    /// Door-frame tracks within their footprint of a doorway the map's walls showed this
    /// revolution ([`crate::map_doors::observe`]) are openings in a wall from now on.
    pub fn anchor_doors(&mut self, doorways: &[Point2]) {
        for t in self.tracks.iter_mut() {
            if t.class() == ObjectClass::DoorFrame
                && doorways
                    .iter()
                    .any(|d| d.distance(t.centre) <= class_radius(ObjectClass::DoorFrame))
            {
                t.anchored = true;
            }
        }
    }

    /// Door-frame tracks within [`CORNER_DOOR_M`] of a corner of the map's walls: see
    /// [`Track::door_at_corner`]; one reported is reported no more.
    pub fn mark_corner_doors(&mut self, walls: &WallMap) {
        for t in self.tracks.iter_mut() {
            if t.class() == ObjectClass::DoorFrame {
                t.at_corner = walls.corner_near(t.centre, CORNER_DOOR_M);
                if t.door_at_corner() {
                    t.confirmed = false;
                }
            }
        }
    }
}
