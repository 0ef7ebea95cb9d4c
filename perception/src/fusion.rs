//! One frame's objects from both methods: Method A's objects (and its doors, as door frames)
//! first, then each Method B box either joins the nearest Method A object of its class within
//! [`AGREE_M`] (which becomes `AB`, keeping the higher score and taking B's box) or is added
//! as a `B` object. Pure and allocation-free: the frame loop calls it once a frame.
//!
//! This is the per-frame merge; the world model that tracks objects over frames grows from it.

use heapless::Vec;

use crate::class::ObjectClass;
use crate::geometry::Point2;

/// A Method B box this close (m) to a Method A object of the same class is the same object.
pub const AGREE_M: f32 = 0.3;

/// Objects one frame can carry: every Method A candidate, every door, every B box.
pub const MAX_FRAME_OBJECTS: usize =
    crate::method_a::MAX_CANDIDATES + crate::doors::MAX_DOORS + crate::yolo::MAX_DETECTIONS;

/// Which methods saw an object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Evidence {
    /// Method A alone.
    A,
    /// Method B alone.
    B,
    /// Both.
    AB,
}

impl Evidence {
    /// The name in the output line.
    pub const fn as_str(self) -> &'static str {
        match self {
            Evidence::A => "A",
            Evidence::B => "B",
            Evidence::AB => "AB",
        }
    }
}

/// One object of a frame, in the map frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameObject {
    /// Class.
    pub class: ObjectClass,
    /// Centre, m.
    pub centre: Point2,
    /// Confidence in [0, 1].
    pub score: f32,
    /// Which methods saw it.
    pub evidence: Evidence,
    /// Method B's box `[cx, cy, w, h]` in pixels of the 384 × 64 input (B and AB only).
    pub bbox: Option<[f32; 4]>,
    /// Width across, m, where known (a door's clear width: Method A's, or from Method B's
    /// box); 0 = unknown.
    pub width_m: f32,
}

/// A Method B box placed in the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacedBox {
    /// Class.
    pub class: ObjectClass,
    /// Centre, m.
    pub centre: Point2,
    /// Score in [0, 1].
    pub score: f32,
    /// `[cx, cy, w, h]`, px.
    pub bbox: [f32; 4],
    /// Width across in the map, m (the box's bearing span at its range; 0 = unknown).
    pub width_m: f32,
}

/// Width in metres across a box `w_deg` degrees wide at `range_m` (one raster column is one
/// degree of bearing).
pub fn width_across(w_deg: f32, range_m: f32) -> f32 {
    2.0 * range_m * libm::tanf((w_deg * 0.5).clamp(0.0, 80.0).to_radians())
}

/// The frame's objects, in output order.
pub type FrameObjects = Vec<FrameObject, MAX_FRAME_OBJECTS>;

/// Adds a Method A object; `false` when the frame is full (it is dropped).
pub fn push_a(objects: &mut FrameObjects, class: ObjectClass, centre: Point2, score: f32) -> bool {
    objects
        .push(FrameObject {
            class,
            centre,
            score,
            evidence: Evidence::A,
            bbox: None,
            width_m: 0.0,
        })
        .is_ok()
}

/// Merges one Method B box into the frame's objects; `false` when it had to be added and the
/// frame is full (it is dropped).
pub fn merge_b(objects: &mut FrameObjects, b: &PlacedBox) -> bool {
    // Distances in f64, as the output line's coordinates are.
    let (bx, by) = (f64::from(b.centre.x), f64::from(b.centre.y));
    let agreed = objects
        .iter_mut()
        .filter(|o| o.evidence == Evidence::A && o.class == b.class)
        .map(|o| {
            let dx = f64::from(o.centre.x) - bx;
            let dy = f64::from(o.centre.y) - by;
            (libm::sqrt(dx * dx + dy * dy), o)
        })
        .filter(|(dist, _)| *dist <= f64::from(AGREE_M))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    match agreed {
        Some((_, o)) => {
            o.evidence = Evidence::AB;
            o.score = o.score.max(b.score);
            o.bbox = Some(b.bbox);
            if o.width_m <= 0.0 {
                o.width_m = b.width_m;
            }
            true
        }
        None => objects
            .push(FrameObject {
                class: b.class,
                centre: b.centre,
                score: b.score,
                evidence: Evidence::B,
                bbox: Some(b.bbox),
                width_m: b.width_m,
            })
            .is_ok(),
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn placed(class: ObjectClass, x: f32, y: f32, score: f32) -> PlacedBox {
        PlacedBox {
            class,
            centre: Point2::new(x, y),
            score,
            bbox: [10.0, 20.0, 4.0, 6.0],
            width_m: 0.0,
        }
    }

    #[test]
    fn a_box_near_an_object_of_its_class_agrees_with_the_nearest() {
        let mut o = FrameObjects::new();
        assert!(push_a(
            &mut o,
            ObjectClass::Chair,
            Point2::new(1.0, 0.0),
            0.6
        ));
        assert!(push_a(
            &mut o,
            ObjectClass::Chair,
            Point2::new(1.2, 0.0),
            0.5
        ));
        assert!(merge_b(&mut o, &placed(ObjectClass::Chair, 1.15, 0.0, 0.9)));
        assert_eq!(o.len(), 2);
        assert_eq!(o[0].evidence, Evidence::A);
        assert_eq!(o[1].evidence, Evidence::AB);
        assert_eq!(o[1].score, 0.9);
        assert_eq!(o[1].bbox, Some([10.0, 20.0, 4.0, 6.0]));
        // The A object's centre is kept.
        assert_eq!(o[1].centre, Point2::new(1.2, 0.0));
    }

    #[test]
    fn other_class_or_too_far_is_a_new_b_object() {
        let mut o = FrameObjects::new();
        push_a(&mut o, ObjectClass::Desk, Point2::new(0.0, 0.0), 0.8);
        merge_b(&mut o, &placed(ObjectClass::Chair, 0.0, 0.0, 0.7));
        merge_b(&mut o, &placed(ObjectClass::Desk, 0.31, 0.0, 0.4));
        assert_eq!(o.len(), 3);
        assert_eq!(o[0].evidence, Evidence::A);
        assert_eq!(
            (o[1].class, o[1].evidence),
            (ObjectClass::Chair, Evidence::B)
        );
        assert_eq!(
            (o[2].class, o[2].evidence),
            (ObjectClass::Desk, Evidence::B)
        );
        // An agreed object keeps the higher of the two scores.
        merge_b(&mut o, &placed(ObjectClass::Desk, 0.1, 0.0, 0.3));
        assert_eq!((o[0].evidence, o[0].score), (Evidence::AB, 0.8));
    }

    #[test]
    fn b_objects_never_absorb_later_boxes() {
        let mut o = FrameObjects::new();
        merge_b(&mut o, &placed(ObjectClass::Box, 2.0, 2.0, 0.5));
        merge_b(&mut o, &placed(ObjectClass::Box, 2.0, 2.0, 0.6));
        assert_eq!(o.len(), 2);
        assert!(o.iter().all(|x| x.evidence == Evidence::B));
    }

    #[test]
    fn a_full_frame_drops_and_says_so() {
        let mut o = FrameObjects::new();
        for _ in 0..MAX_FRAME_OBJECTS {
            assert!(push_a(&mut o, ObjectClass::Box, Point2::new(9.0, 9.0), 0.5));
        }
        assert!(!push_a(
            &mut o,
            ObjectClass::Box,
            Point2::new(9.0, 9.0),
            0.5
        ));
        assert!(!merge_b(&mut o, &placed(ObjectClass::Chair, 0.0, 0.0, 0.5)));
        // Agreement needs no room.
        assert!(merge_b(&mut o, &placed(ObjectClass::Box, 9.0, 9.0, 0.7)));
    }
}
