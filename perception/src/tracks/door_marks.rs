//! What the map's walls say of door-frame tracks: one in a doorway they show is an opening in
//! a wall (anchored), as is one seen often in the line of one of them (held); one at a corner
//! of them that only Method B has seen is the end of a wall seen end-on (not reported while
//! so).

use crate::class::ObjectClass;
use crate::geometry::Point2;
use crate::wall_map::WallMap;

use super::{CORNER_DOOR_M, Track, TrackConfig, Tracks, class_radius};

impl Track {
    /// A door frame only Method B has seen, not in a doorway of the map's walls, at a corner
    /// of them: the end of a wall seen end-on looks like a jamb to Method B (an L-shaped
    /// room's inner corner). Not reported while so.
    pub fn door_at_corner(&self) -> bool {
        self.class() == ObjectClass::DoorFrame && self.at_corner && !self.seen_a && !self.anchored
    }

    /// A door frame judged as a doorway by what the rays show of it: the map's walls showed it
    /// ([`Track::anchored`]), or the methods saw it in [`TrackConfig::door_hold_hits`]
    /// frames.
    pub fn held_door(&self, cfg: &TrackConfig) -> bool {
        self.class() == ObjectClass::DoorFrame
            && (self.anchored
                || (cfg.door_hold_hits > 0 && self.hits >= cfg.door_hold_hits && self.in_wall_line))
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
    /// [`Track::door_at_corner`]; one reported is reported no more. Also notes which stand
    /// in a wall's line ([`Track::held_door`]).
    pub fn mark_corner_doors(&mut self, walls: &WallMap) {
        for t in self.tracks.iter_mut() {
            if t.class() == ObjectClass::DoorFrame {
                t.at_corner = walls.corner_near(t.centre, CORNER_DOOR_M);
                t.in_wall_line = walls.in_wall_line(t.centre);
                if t.door_at_corner() {
                    t.confirmed = false;
                }
            }
        }
    }
}
