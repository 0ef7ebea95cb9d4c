//! What became of each piece of furniture the final map is scored on (visible, there at the
//! end): found, or why not. A miss is the world model's when the methods found the piece and
//! the map dropped it, gave it the wrong class or never confirmed it, and the detectors' when
//! they did not find it or found it but seldom as its class. The split says which side of
//! umbra the next change belongs to.

use perception::class::ObjectClass;

use super::score::{Line, MATCH_M};
use crate::run_truth::{Furniture, RunTruth};

/// What became of one piece, in [`FATES`] order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// An object of its class on it in the last line.
    Found,
    /// An object of its class on it in some line, not the last.
    Dropped,
    /// Never reported as its class, but as another furniture class (an object of that class on
    /// it in some line).
    ReportedOther,
    /// Never reported, though detected as its class at least [`DETECTED_MIN`] times.
    NeverReported,
    /// Detected at least [`DETECTED_MIN`] times, but as its class fewer times than that: taken
    /// for another class as often as not.
    OtherClass,
    /// Detected fewer than [`DETECTED_MIN`] times.
    Undetected,
}

/// How many fates there are.
pub const FATE_COUNT: usize = 6;

/// The fates' names, as the report prints them.
pub const FATES: [&str; FATE_COUNT] = [
    "found",
    "reported for a while, not at the end",
    "reported, but only as another class",
    "detected as its class, never reported",
    "detected, as its class under 10 times",
    "not detected",
];

/// A detection within this distance of a piece's footprint is taken for a detection of it, m.
pub const NEAR_M: f32 = 0.5;

/// Detections that make a piece detected.
pub const DETECTED_MIN: u32 = 10;

impl Fate {
    /// Its place in [`FATES`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The fate of `piece`, found or not in the final map (`found`), from the run's `lines`: its
/// reports and detections (a line without `detections` counts its `objects`) over the frames
/// it is there.
pub fn fate(truth: &RunTruth, lines: &[Line], piece: &Furniture, found: bool) -> Fate {
    if found {
        return Fate::Found;
    }
    let (mut reported, mut as_other) = (false, false);
    let (mut own, mut all) = (0u32, 0u32);
    for line in lines {
        if !truth.frame_at(line.t).is_some_and(|fi| piece.alive(fi)) {
            continue;
        }
        for o in line
            .objects
            .iter()
            .filter(|o| piece.distance(o.at) <= MATCH_M)
        {
            reported |= o.class == Some(piece.class);
            as_other |= o
                .class
                .is_some_and(|c| c != piece.class && c != ObjectClass::DoorFrame);
        }
        for d in line.detections.as_deref().unwrap_or(&line.objects) {
            if d.class.is_some() && piece.distance(d.at) <= NEAR_M {
                all += 1;
                own += u32::from(d.class == Some(piece.class));
            }
        }
    }
    if reported {
        Fate::Dropped
    } else if as_other {
        Fate::ReportedOther
    } else if own >= DETECTED_MIN {
        Fate::NeverReported
    } else if all >= DETECTED_MIN {
        Fate::OtherClass
    } else {
        Fate::Undetected
    }
}

/// Sums a tally's fates (class × fate) into another's.
pub fn add(into: &mut [[u32; FATE_COUNT]; 3], from: &[[u32; FATE_COUNT]; 3]) {
    for (a, b) in into.iter_mut().flatten().zip(from.iter().flatten()) {
        *a += b;
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::world_eval::score::Reported;
    use perception::geometry::Point2;

    fn piece() -> Furniture {
        Furniture {
            what: "chair".into(),
            ..Furniture::square(0, ObjectClass::Chair, Point2::new(0.2, 0.2), 0.2)
        }
    }

    fn truth(frames: usize) -> RunTruth {
        let mut t = RunTruth::default();
        t.frames = (0..frames)
            .map(|i| crate::run_truth::FrameTruth {
                t: i as f64 * 0.2,
                ..Default::default()
            })
            .collect();
        t
    }

    fn rep(class: ObjectClass, x: f32) -> Reported {
        Reported {
            id: 1,
            class: Some(class),
            at: Point2::new(x, 0.2),
            source: 1,
            score: 0.5,
        }
    }

    fn line(i: usize, objects: Vec<Reported>, detections: Vec<Reported>) -> Line {
        Line {
            frame: None,
            t: i as f64 * 0.2,
            objects,
            detections: Some(detections),
            ..Default::default()
        }
    }

    #[test]
    fn each_fate_from_what_the_lines_show() {
        let (t, p) = (truth(20), piece());
        let chair = |x| rep(ObjectClass::Chair, x);
        let desk = |x| rep(ObjectClass::Desk, x);
        // Found in the last line: found, whatever came before.
        assert_eq!(fate(&t, &[], &p, true), Fate::Found);
        // Reported once, not at the end.
        let mut lines: Vec<Line> = (0..20).map(|i| line(i, vec![], vec![])).collect();
        lines[3].objects.push(chair(0.2));
        assert_eq!(fate(&t, &lines, &p, false), Fate::Dropped);
        // A report of another class is a report as another class; 0.35 m off, no report.
        lines[3].objects = vec![desk(0.2), chair(0.75)];
        assert_eq!(fate(&t, &lines, &p, false), Fate::ReportedOther);
        lines[3].objects = vec![chair(0.75), rep(ObjectClass::DoorFrame, 0.2)];
        assert_eq!(fate(&t, &lines, &p, false), Fate::Undetected);
        // Ten detections of its class within 0.5 m (0.45 m off the footprint counts).
        for l in lines.iter_mut().take(10) {
            l.detections = Some(vec![chair(0.85)]);
        }
        assert_eq!(fate(&t, &lines, &p, false), Fate::NeverReported);
        // Nine of its class and five of another: detected fourteen times, as its class nine.
        lines[0].detections = Some(vec![desk(0.2)]);
        for l in lines.iter_mut().skip(10).take(4) {
            l.detections = Some(vec![desk(0.2)]);
        }
        assert_eq!(fate(&t, &lines, &p, false), Fate::OtherClass);
        // Detections beyond 0.5 m are not of it.
        for l in lines.iter_mut() {
            l.detections = Some(vec![chair(1.0)]);
        }
        assert_eq!(fate(&t, &lines, &p, false), Fate::Undetected);
    }

    #[test]
    fn frames_before_a_piece_is_there_do_not_count() {
        let t = truth(20);
        let p = Furniture {
            from_frame: 15,
            ..piece()
        };
        let lines: Vec<Line> = (0..20)
            .map(|i| line(i, vec![rep(ObjectClass::Chair, 0.2)], vec![]))
            .collect();
        // Reported in frames 15–19 (the last line is not `found` here by construction).
        assert_eq!(fate(&t, &lines, &p, false), Fate::Dropped);
        assert_eq!(fate(&t, &lines[..15], &p, false), Fate::Undetected);
    }
}
