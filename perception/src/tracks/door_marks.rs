//! What the map's walls say of door-frame tracks: one in a doorway they show is an opening in
//! a wall (anchored), as is one seen often in the line of one of them (held); one at a corner
//! of them that only Method B has seen is the end of a wall seen end-on (not reported while
//! so), as is one beside a wall's end whose other jamb's place the rays show empty.

use crate::class::ObjectClass;
use crate::geometry::{Point2, Pose2};
use crate::sight::{BINS, View, view};
use crate::wall_map::WallMap;

use super::{CORNER_DOOR_M, Track, TrackConfig, Tracks, class_radius};

/// Radius of a jamb's place looked at, m (a wall's end: 0.05–0.25 m thick).
pub const JAMB_M: f32 = 0.15;
/// Revolutions that must show a door frame's other jamb's place empty before it counts as a
/// wall's end ([`Track::lone_jamb`]).
pub const LONE_JAMB_VIEWS: u16 = 3;

impl Track {
    /// A door frame only Method B has seen, not in a doorway of the map's walls, at a wall's
    /// end: at a corner of them, or beside an end with no other jamb ([`Track::lone_jamb`]).
    /// The end of a wall seen end-on looks like a jamb to Method B (an L-shaped room's inner
    /// corner, a partition). Not reported while so.
    pub fn door_at_wall_end(&self) -> bool {
        self.class() == ObjectClass::DoorFrame
            && (self.at_corner || self.lone_jamb())
            && !self.seen_a
            && !self.anchored
    }

    /// Beside a wall's end, the place of the doorway's other jamb was seen empty in
    /// [`LONE_JAMB_VIEWS`] revolutions and more often than not: a wall that ends (a partition,
    /// an L-shaped room's corner seen end-on) with floor beyond it, not a doorway.
    pub fn lone_jamb(&self) -> bool {
        let [empty, there] = self.far_jamb_views;
        empty >= LONE_JAMB_VIEWS && empty > there
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

    /// What the map's walls and this revolution say of the door-frame tracks: at a corner of
    /// the walls ([`Tracks::mark_corner_doors`]), and beside a wall's end with no other jamb
    /// ([`Tracks::look_for_far_jambs`]).
    pub fn mark_wall_doors(
        &mut self,
        walls: &WallMap,
        lidar: &Pose2,
        ranges: &[f32; BINS],
        max_range_m: f32,
    ) {
        self.mark_corner_doors(walls);
        self.look_for_far_jambs(walls, lidar, ranges, max_range_m);
    }

    /// For each door-frame track beside the end of a confirmed line of the map
    /// ([`WallMap::far_jamb`]), what this revolution (`ranges`, from `lidar`) shows of the place
    /// of its other jamb: seen empty, or returning (hidden or out of reach: nothing). See
    /// [`Track::lone_jamb`]; one reported is reported no more.
    pub fn look_for_far_jambs(
        &mut self,
        walls: &WallMap,
        lidar: &Pose2,
        ranges: &[f32; BINS],
        max_range_m: f32,
    ) {
        for t in self.tracks.iter_mut() {
            if t.class() != ObjectClass::DoorFrame || t.anchored {
                continue;
            }
            let Some(jamb) = walls.far_jamb(t.centre) else {
                continue;
            };
            let k = match view(jamb, JAMB_M, lidar, ranges, max_range_m) {
                View::Empty => 0,
                View::Plain(_) => 1,
                View::Hidden => continue,
            };
            t.far_jamb_views[k] = t.far_jamb_views[k].saturating_add(1);
            if t.door_at_wall_end() {
                t.confirmed = false;
            }
        }
    }

    /// Door-frame tracks within [`CORNER_DOOR_M`] of a corner of the map's walls: see
    /// [`Track::door_at_wall_end`]; one reported is reported no more. Also notes which stand
    /// in a wall's line ([`Track::held_door`]).
    pub fn mark_corner_doors(&mut self, walls: &WallMap) {
        for t in self.tracks.iter_mut() {
            if t.class() == ObjectClass::DoorFrame {
                t.at_corner = walls.corner_near(t.centre, CORNER_DOOR_M);
                t.in_wall_line = walls.in_wall_line(t.centre);
                if t.door_at_wall_end() {
                    t.confirmed = false;
                }
            }
        }
    }
}
