//! What one revolution showed of a footprint in the map: hidden, in plain view, or seen empty
//! (every ray across it returned from beyond, or — for a piece of furniture well within reach
//! — returned nothing); and of a doorway, which rays passing through do not speak against. The
//! world model's negative evidence. `no_std`.

use crate::geometry::{Point2, Pose2};

/// Bins of a revolution (1° each, counter-clockwise from the LiDAR's forward axis).
pub const BINS: usize = 360;

/// A revolution's returns as points in the LiDAR's frame (bin `d` at `d`°), converted once
/// for the checks that look at many detections; `None` where a bin has no return.
pub fn returns(ranges: &[f32; BINS]) -> [Option<Point2>; BINS] {
    let mut out = [None; BINS];
    for (d, (slot, &r)) in out.iter_mut().zip(ranges.iter()).enumerate() {
        if r > 0.0 && r.is_finite() {
            *slot = Some(Point2::from_polar(r, (d as f32).to_radians()));
        }
    }
    out
}

/// What a revolution showed of a footprint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum View {
    /// Out of range, inside the robot's own footprint, or behind something nearer.
    Hidden,
    /// In plain view: the rays reach it (they end inside its footprint); how many did.
    Plain(u32),
    /// Seen empty: no ray ended in it, at least two crossed it and returned from beyond, and
    /// no fewer than ended in front of it (a footprint partly behind something nearer is still
    /// seen through where the rays reach it). [`footprint_view`] also counts rays with no
    /// return across a footprint well within reach.
    Empty,
}

/// The returns of the bins across a disc: how many ended in front of it, in it, beyond it.
#[derive(Debug, Clone, Copy, Default)]
struct Across {
    before: u32,
    inside: u32,
    beyond: u32,
    /// Rays with no return at all.
    none: u32,
    /// Distance from the LiDAR to the disc's centre, m.
    dist: f32,
}

/// The bins of this revolution (`ranges`, from `lidar`) across a disc of radius `r` m at
/// `centre` (map frame), or `None` when it is out of range (beyond `max_range_m`) or the
/// LiDAR is inside it.
fn across(
    centre: Point2,
    r: f32,
    lidar: &Pose2,
    ranges: &[f32; BINS],
    max_range_m: f32,
) -> Option<Across> {
    let local = lidar.inverse().transform(centre);
    let dist = libm::sqrtf(local.x * local.x + local.y * local.y);
    if dist <= r || dist + r > max_range_m {
        return None;
    }
    let bearing = libm::atan2f(local.y, local.x).to_degrees();
    let half = libm::asinf((r / dist).min(1.0)).to_degrees();
    let (lo, hi) = (
        libm::ceilf(bearing - half) as i32,
        libm::floorf(bearing + half) as i32,
    );
    let mut a = Across {
        dist,
        ..Across::default()
    };
    for d in lo..=hi {
        let range = ranges[d.rem_euclid(BINS as i32) as usize];
        if range <= 0.0 || !range.is_finite() {
            // No return: a dark surface that dropped out, or nothing within reach.
            a.none += 1;
            continue;
        }
        if range < dist - r {
            a.before += 1;
        } else if range < dist + r {
            a.inside += 1;
        } else {
            a.beyond += 1;
        }
    }
    Some(a)
}

/// What this revolution (`ranges`, from `lidar`) showed of a footprint of radius `r` m at
/// `centre` (map frame); nothing beyond `max_range_m`.
pub fn view(centre: Point2, r: f32, lidar: &Pose2, ranges: &[f32; BINS], max_range_m: f32) -> View {
    seen(across(centre, r, lidar, ranges, max_range_m), false)
}

/// What the bins across a footprint say; `none_passes`: whether rays with no return crossed it
/// (see [`footprint_view`]).
fn seen(across: Option<Across>, none_passes: bool) -> View {
    match across {
        Some(a) if a.inside == 0 && a.beyond >= 2 && a.beyond >= a.before => View::Empty,
        Some(a)
            if none_passes
                && a.inside == 0
                && a.beyond + a.none >= 3
                && a.beyond + a.none >= a.before =>
        {
            View::Empty
        }
        Some(a) if a.inside > 0 && a.inside >= a.before => View::Plain(a.inside),
        _ => View::Hidden,
    }
}

/// Share of the LiDAR's reach within which a ray with no return across a footprint counts as
/// seen through ([`footprint_view`]): farther, a chair's thin legs can fall between the rays.
pub const NEAR_SHARE: f32 = 0.8;

/// [`view`] of a piece of furniture's footprint, where a ray with no return also crossed it:
/// the footprint is within the LiDAR's reach (`max_range_m`), so a piece standing there would
/// have returned it, unless it is dark; what lies beyond may be out of reach (a far wall). Seen
/// empty needs no ray ending in it and at least three crossing it, no fewer than end in front.
pub fn footprint_view(
    centre: Point2,
    r: f32,
    lidar: &Pose2,
    ranges: &[f32; BINS],
    max_range_m: f32,
) -> View {
    let a = across(centre, r, lidar, ranges, max_range_m);
    let near = a.is_some_and(|a| a.dist + r <= NEAR_SHARE * max_range_m);
    seen(a, near)
}

/// What a revolution showed of a doorway (an opening in a wall between two jambs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DoorView {
    /// Out of range or behind something nearer.
    Hidden,
    /// Rays pass through its middle, or its jambs are in plain view: what a doorway looks like.
    Open,
    /// Rays end in its middle: a shut door, or a wall where no doorway is.
    Closed,
    /// Rays pass through its middle and where its jambs should be: open floor, no doorway.
    NoJambs,
}

/// Half the middle of a doorway looked at for [`DoorView::Closed`], m: inside the narrowest
/// doorway's half-width (0.75 m / 2), so its jambs are never in it.
pub const DOOR_MIDDLE_M: f32 = 0.2;
/// How far past a doorway's half-width its jambs are looked for, m.
pub const DOOR_JAMB_M: f32 = 0.2;

/// What this revolution showed of a doorway centred at `centre` whose jambs stand `half_width`
/// m either side of it.
pub fn doorway_view(
    centre: Point2,
    half_width: f32,
    lidar: &Pose2,
    ranges: &[f32; BINS],
    max_range_m: f32,
) -> DoorView {
    let middle = view(centre, DOOR_MIDDLE_M, lidar, ranges, max_range_m);
    let whole = across(centre, half_width + DOOR_JAMB_M, lidar, ranges, max_range_m);
    // No jambs only where every ray that reached the jambs' places went on: a jamb behind
    // something nearer is not seen missing (unlike a piece of furniture's footprint, which
    // the rays that do reach it show empty).
    let no_jambs = whole.is_some_and(|a| a.inside == 0 && a.before == 0 && a.beyond >= 2);
    let whole_hidden = whole.is_none_or(|a| !(a.inside > 0 && a.inside >= a.before));
    match middle {
        View::Plain(_) => DoorView::Closed,
        _ if no_jambs => DoorView::NoJambs,
        View::Hidden if whole_hidden => DoorView::Hidden,
        _ => DoorView::Open,
    }
}

#[cfg(test)]
mod test {
    use super::*;

    /// A footprint of radius 0.35 m 2 m straight ahead spans bins 350..=359 and 0..=10.
    fn look(ranges: &[f32; BINS]) -> View {
        view(Point2::new(2.0, 0.0), 0.35, &Pose2::IDENTITY, ranges, 3.5)
    }

    #[test]
    fn a_footprint_partly_behind_something_is_seen_through_where_the_rays_reach() {
        let mut r = [3.2; BINS];
        assert_eq!(look(&r), View::Empty);
        // Its right half behind a pillar 1 m away: the left half still shows it empty.
        r[350..BINS].fill(1.0);
        assert_eq!(look(&r), View::Empty);
        // One ray ends in it: something is there (in plain view only with no more rays in
        // front of it than in it).
        r[5] = 2.1;
        assert_eq!(look(&r), View::Hidden);
        r[350..BINS].fill(3.2);
        assert!(matches!(look(&r), View::Plain(_)));
        r[350..BINS].fill(1.0);
        // Mostly behind the pillar: too little seen to call it empty.
        r[5] = 3.2;
        r[..8].fill(1.0);
        assert_eq!(look(&r), View::Hidden);
        // No return at all says nothing.
        assert_eq!(look(&[0.0; BINS]), View::Hidden);
    }

    #[test]
    fn a_footprint_within_reach_is_seen_through_where_the_rays_return_nothing() {
        // The far wall beyond the LiDAR's reach: no ray returns. A piece 2 m ahead would have
        // returned some; it is seen empty — as a footprint is by `view` only when the rays
        // return from beyond it.
        let near =
            |r: &[f32; BINS]| footprint_view(Point2::new(2.0, 0.0), 0.35, &Pose2::IDENTITY, r, 3.5);
        let none = [0.0; BINS];
        assert_eq!(near(&none), View::Empty);
        assert_eq!(look(&none), View::Hidden);
        // Its far edge past 0.8 of the reach (2.6 + 0.35 > 2.8 m): a chair's legs can fall
        // between the rays there, so no return says nothing.
        let far =
            |r: &[f32; BINS]| footprint_view(Point2::new(2.6, 0.0), 0.35, &Pose2::IDENTITY, r, 3.5);
        assert_eq!(far(&none), View::Hidden);
        // A ray that ends in it: in plain view, whatever the others did.
        let mut r = none;
        r[2] = 2.1;
        assert!(matches!(near(&r), View::Plain(_)));
        // Behind something nearer in most of its bins: hidden.
        let mut r = none;
        r[350..BINS].fill(1.0);
        r[..8].fill(1.0);
        assert_eq!(near(&r), View::Hidden);
    }

    #[test]
    fn a_jamb_behind_something_nearer_is_not_seen_missing() {
        // A doorway 0.9 m wide 2 m ahead; the rays through it return from 3.2 m.
        let look =
            |r: &[f32; BINS]| doorway_view(Point2::new(2.0, 0.0), 0.45, &Pose2::IDENTITY, r, 3.5);
        let mut r = [3.2; BINS];
        assert_eq!(look(&r), DoorView::NoJambs, "open floor, no jambs");
        // One jamb's bins behind a chair 1 m away: the doorway is not shown to be open floor.
        r[8..20].fill(1.0);
        assert_eq!(look(&r), DoorView::Open);
        // Something in its middle: shut.
        r[0] = 2.0;
        assert_eq!(look(&r), DoorView::Closed);
    }
}
