//! What a box track's own returns say of its shape, revolution after revolution: a "box" never
//! seen as wide as any box is a post or a bin ([`Track::too_narrow`]); one whose returns lie
//! on an arc is a bin or a round pillar ([`Track::looks_round`]). Neither is reported while so.
//! The views are counted by [`Tracks::measure_outlines`] (`crate::outline` measures one
//! revolution; `crate::outline_average` averages a still box's outline over revolutions, in
//! [`OUTLINE_SLOTS`] slots).

use crate::class::ObjectClass;
use crate::geometry::{Point2, Pose2};
use crate::outline_average::{AveragedOutline, TAKE_M};
use crate::sight::BINS;

use super::{Track, Tracks};

/// Box tracks whose outlines are averaged over revolutions at once
/// ([`crate::outline_average`]): a room holds a few boxes and pillars in view.
pub const OUTLINE_SLOTS: usize = 16;
/// Revolutions whose averaged outline was round before a "box" is not reported
/// ([`Track::looks_round`]) ...
pub const AVERAGED_ROUND_VIEWS: u16 = 8;
/// ... when they are at least this many times those in which it was not: one that turns round
/// now and then, where a box's corner is near the noise, is not.
pub const AVERAGED_ROUND_MAJORITY: u16 = 3;

/// Narrow views before a "box" never seen box-wide is not reported ([`Track::too_narrow`]).
pub const NARROW_VIEWS: u16 = 3;

/// Revolutions whose returns could lie on an arc ([`crate::outline::Fits::arc`]) at least
/// before a "box" may be found round ([`Track::looks_round`]).
pub const ROUND_VIEWS: u16 = 3;
/// A round "box": over its arc-shaped revolutions, the circle's variance per degree of freedom
/// at most this share of a right-angled corner's (a box seen across a corner: the corner fits
/// to the noise, a circle worse; a pillar: the reverse). Both have 3 parameters; two free
/// lines (4, and the split) fit a short noisy arc as well as a circle does ...
pub const ROUND_CORNER_RATIO: f32 = 0.65;
/// ... and of one line's.
pub const ROUND_LINE_RATIO: f32 = 0.6;

impl Track {
    /// A "box" whose returns looked narrower than any box in [`NARROW_VIEWS`] revolutions and
    /// never as wide as one: a bin, a round pillar, a post ([`crate::outline::box_wide`]).
    /// Not reported while so. Something in front narrows a box, nothing widens a post: one
    /// box-wide view outweighs any number of narrow ones.
    pub fn too_narrow(&self) -> bool {
        self.class() == ObjectClass::Box
            && self.box_wide_views == 0
            && self.narrow_views >= NARROW_VIEWS
    }

    /// A "box" whose returns lie on an arc: in [`ROUND_VIEWS`] revolutions and more than not
    /// they could, and over those revolutions together a circle fits them better than a
    /// right-angled corner ([`ROUND_CORNER_RATIO`]) and than one line
    /// ([`ROUND_LINE_RATIO`]); or its outline averaged over revolutions was round in
    /// [`AVERAGED_ROUND_VIEWS`] revolutions and [`AVERAGED_ROUND_MAJORITY`] times as many as
    /// not. A bin or a round pillar; not reported while so. One revolution's few returns
    /// cannot tell a pillar's arc from a box's corner under the range noise, and the summed
    /// fits only where the noise is small (each revolution's fits follow its own noise);
    /// averaging the returns themselves takes the noise out of the shape.
    pub fn looks_round(&self) -> bool {
        let [circle, corner, line] = self.arc_fits;
        let summed = self.arc_views >= ROUND_VIEWS
            && self.arc_views > self.flat_views
            && circle <= ROUND_CORNER_RATIO * corner
            && circle <= ROUND_LINE_RATIO * line;
        self.class() == ObjectClass::Box && (summed || averaged_vote(self.averaged_round))
    }
}

/// The vote on the averaged outline ([`Track::averaged_round`]: revolutions round, not
/// round): round in [`AVERAGED_ROUND_VIEWS`] and [`AVERAGED_ROUND_MAJORITY`] times as many as
/// not.
pub fn averaged_vote([yes, no]: [u16; 2]) -> bool {
    yes >= AVERAGED_ROUND_VIEWS
        && u32::from(yes) >= u32::from(AVERAGED_ROUND_MAJORITY) * u32::from(no)
}

impl Tracks {
    /// Box tracks that stand still: whether their returns in this revolution look as wide as
    /// a box ([`crate::outline::box_wide`]), how they fit an arc ([`crate::outline::fits`])
    /// and whether their outline averaged over revolutions is round
    /// ([`crate::outline_average`]); `pts` from [`crate::sight::returns`], `lidar` the LiDAR's
    /// pose in the map. Counted into [`Track::too_narrow`]'s and [`Track::looks_round`]'s
    /// views.
    pub fn measure_outlines(&mut self, lidar: &Pose2, pts: &[Option<Point2>; BINS]) {
        let still_box = |t: &Track| t.class() == ObjectClass::Box && !t.motion.moving;
        // Slots of tracks gone, moving or no longer boxes are free again.
        let tracks = &self.tracks;
        self.outlines
            .retain(|(id, _)| tracks.iter().any(|t| t.id == *id && still_box(t)));
        for t in self.tracks.iter_mut() {
            if !still_box(t) {
                continue;
            }
            match crate::outline::box_wide(t.centre, lidar, pts) {
                Some(true) => t.box_wide_views = t.box_wide_views.saturating_add(1),
                Some(false) => t.narrow_views = t.narrow_views.saturating_add(1),
                None => {}
            }
            match crate::outline::fits(t.centre, lidar, pts) {
                Some(f) if f.arc => {
                    t.arc_views = t.arc_views.saturating_add(1);
                    for (sum, v) in t.arc_fits.iter_mut().zip(f.variances()) {
                        if v.is_finite() {
                            *sum += v;
                        }
                    }
                }
                Some(_) => t.flat_views = t.flat_views.saturating_add(1),
                None => {}
            }
            let Some(run) = crate::outline::run_to_average(t.centre, lidar, pts, TAKE_M) else {
                continue;
            };
            let slot = match self.outlines.iter().position(|(id, _)| *id == t.id) {
                Some(k) => k,
                None if self.outlines.push((t.id, AveragedOutline::EMPTY)).is_ok() => {
                    self.outlines.len() - 1
                }
                None => continue, // every slot taken: this one waits
            };
            let avg = &mut self.outlines[slot].1;
            avg.add(t.centre, lidar, &run);
            if let Some(round) = avg.round() {
                let k = usize::from(!round);
                t.averaged_round[k] = t.averaged_round[k].saturating_add(1);
            }
        }
    }
}
