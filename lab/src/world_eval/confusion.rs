//! What each method calls each piece: the frame's detections that stand on a piece of
//! furniture, counted by source (A, B, AB), the piece's class and the class they gave it
//! (`Tally::confusion`). A detector that takes one class for another shows here, where the
//! final map only shows the piece missing or reported as another class.

use std::fmt::Write as _;

use perception::class::ObjectClass;
use perception::geometry::Point2;

use crate::run_truth::Furniture;

/// The classes a detection may give: chair, box, desk, door frame.
pub const GIVEN: usize = 4;

/// Counts by source (A, B, AB), piece class (chair, box, desk) and given class
/// ([`GIVEN`]).
pub type Confusion = [[[u32; GIVEN]; 3]; 3];

/// Counts a detection of `source` giving `class` at `at` on the piece nearest to it among
/// `alive` within `reach` m; a detection on no piece, or on a piece that is not furniture,
/// is not counted.
pub fn count(
    c: &mut Confusion,
    alive: &[&Furniture],
    source: usize,
    class: ObjectClass,
    at: Point2,
    reach: f32,
) {
    let nearest = alive
        .iter()
        .map(|f| (f.distance(at), f.class))
        .filter(|&(d, _)| d <= reach)
        .min_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((_, piece)) = nearest
        && (piece as usize) < 3
        && (class as usize) < GIVEN
    {
        c[source.min(2)][piece as usize][class as usize] += 1;
    }
}

/// Adds `o` into `c`.
pub fn add(c: &mut Confusion, o: &Confusion) {
    for (a, b) in c
        .iter_mut()
        .flatten()
        .flatten()
        .zip(o.iter().flatten().flatten())
    {
        *a += b;
    }
}

/// The report's lines: for each source and piece class with any detections, the share of
/// them that gave each class.
pub fn lines(s: &mut String, c: &Confusion) {
    if c.iter().flatten().flatten().all(|&n| n == 0) {
        return;
    }
    let _ = writeln!(
        s,
        "  what the detections on a piece called it (share of them: chair / box / desk / door frame):"
    );
    for (src, name) in ["A", "B", "AB"].iter().enumerate() {
        for (piece, class) in ["chair", "box", "desk"].iter().enumerate() {
            let row = &c[src][piece];
            let n: u32 = row.iter().sum();
            if n == 0 {
                continue;
            }
            let share = |k: usize| f64::from(row[k]) / f64::from(n);
            let _ = writeln!(
                s,
                "    {name:2} on a {class:5} {:.2} / {:.2} / {:.2} / {:.2} of {n}",
                share(0),
                share(1),
                share(2),
                share(3)
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(class: ObjectClass, x: f32) -> Furniture {
        Furniture::square(0, class, Point2::new(x, 0.0), 0.2)
    }

    #[test]
    fn a_detection_counts_on_the_nearest_piece_within_reach_only() {
        let (chair, desk) = (
            piece(ObjectClass::Chair, 0.0),
            piece(ObjectClass::Desk, 0.6),
        );
        let alive = [&chair, &desk];
        let mut c = Confusion::default();
        let mut at = |source, class, x, y| {
            count(&mut c, &alive, source, class, Point2::new(x, y), 0.3);
        };
        // Nearer the chair's footprint (0.05 m) than the desk's (0.15 m): the chair's.
        at(1, ObjectClass::Desk, 0.25, 0.0);
        // On the desk.
        at(0, ObjectClass::Box, 0.6, 0.0);
        // 0.5 m from anything: not counted.
        at(1, ObjectClass::Chair, 0.0, 0.7);
        assert_eq!(c[1][0], [0, 0, 1, 0]);
        assert_eq!(c[0][2], [0, 1, 0, 0]);
        assert_eq!(c.iter().flatten().flatten().sum::<u32>(), 2);
        let mut sum = c;
        add(&mut sum, &c);
        assert_eq!(sum[1][0][2], 2);
        let mut s = String::new();
        lines(&mut s, &c);
        assert!(
            s.contains("B  on a chair 0.00 / 0.00 / 1.00 / 0.00 of 1"),
            "{s}"
        );
        assert!(
            s.contains("A  on a desk  0.00 / 1.00 / 0.00 / 0.00 of 1"),
            "{s}"
        );
        assert!(!s.contains("AB"), "{s}");
    }
}
