//! A run's truth in words (`truth.txt` beside its output lines): furniture with footprints,
//! doors, clutter, wall faces and moves, for reading a run's phantoms by hand; and its
//! walking people frame by frame (`people.txt`), for reading what a report near one came from.

use std::fmt::Write as _;

/// The run's truth in words (written beside each run).
pub fn describe(t: &crate::run_truth::RunTruth) -> String {
    let mut s = format!("{}\n", t.name);
    for (k, f) in t.furniture.iter().enumerate() {
        let c = f.centre();
        let _ = write!(
            s,
            "furniture {k} (piece {}): {} {} at ({:.2}, {:.2}), frames {}..{}, {} returns, footprint",
            f.piece,
            f.class.as_str(),
            f.what,
            c.x,
            c.y,
            f.from_frame,
            if f.to_frame == usize::MAX {
                "end".to_string()
            } else {
                f.to_frame.to_string()
            },
            f.returns
        );
        // The footprint, for reading a run's phantoms against the shape they stand beside.
        for q in &f.footprint {
            let _ = write!(s, " ({:.2}, {:.2})", q.x, q.y);
        }
        s.push('\n');
    }
    for d in &t.doors {
        let _ = writeln!(
            s,
            "door at ({:.2}, {:.2}), {:.2} m, {} returns",
            d.centre.x, d.centre.y, d.width, d.returns
        );
    }
    for (c, w) in &t.clutter {
        let _ = writeln!(s, "clutter: {w} at ({:.2}, {:.2})", c.x, c.y);
    }
    for (a, b) in &t.walls {
        let _ = writeln!(
            s,
            "wall face ({:.2}, {:.2}) to ({:.2}, {:.2})",
            a.x, a.y, b.x, b.y
        );
    }
    for m in &t.moves {
        let _ = writeln!(
            s,
            "move: furniture {} gone from frame {}, seen empty at {:?}",
            m.before, m.frame, m.seen_empty
        );
    }
    s
}

/// The run's walking people frame by frame (written beside each run that has any): one line
/// per person and frame, `frame F t T: person ID at (X, Y), R returns`.
pub fn describe_people(t: &crate::run_truth::RunTruth) -> String {
    let mut s = String::new();
    for (fi, f) in t.frames.iter().enumerate() {
        for p in &f.people {
            let _ = writeln!(
                s,
                "frame {fi} t {:.3}: person {} at ({:.2}, {:.2}), {} returns",
                f.t, p.id, p.at.x, p.at.y, p.returns
            );
        }
    }
    s
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::run_truth::{Door, FrameTruth, Person, RunTruth};
    use perception::geometry::Point2;

    #[test]
    fn the_truth_in_words_names_doors_clutter_and_wall_faces() {
        let t = RunTruth {
            name: "sim 0: rect".into(),
            furniture: vec![],
            doors: vec![Door {
                centre: Point2::new(1.0, 2.0),
                width: 0.9,
                returns: 40,
            }],
            clutter: vec![(Point2::new(-1.0, 0.5), "bin".into())],
            frames: vec![],
            moves: vec![],
            walls: vec![(Point2::new(0.0, 0.0), Point2::new(4.0, 0.0))],
        };
        let s = describe(&t);
        assert_eq!(
            s.lines().collect::<Vec<_>>(),
            [
                "sim 0: rect",
                "door at (1.00, 2.00), 0.90 m, 40 returns",
                "clutter: bin at (-1.00, 0.50)",
                "wall face (0.00, 0.00) to (4.00, 0.00)",
            ]
        );
    }

    #[test]
    fn the_walking_people_are_listed_frame_by_frame() {
        let person = |id, x| Person {
            id,
            at: Point2::new(x, 1.0),
            returns: 4,
        };
        let frame = |t, people| FrameTruth {
            t,
            people,
            robot: None,
        };
        let t = RunTruth {
            name: "sim 0: rect".into(),
            furniture: vec![],
            doors: vec![],
            clutter: vec![],
            frames: vec![
                frame(0.0, vec![]),
                frame(0.2, vec![person(0, 0.5), person(1, -2.0)]),
            ],
            moves: vec![],
            walls: vec![],
        };
        assert_eq!(
            describe_people(&t).lines().collect::<Vec<_>>(),
            [
                "frame 1 t 0.200: person 0 at (0.50, 1.00), 4 returns",
                "frame 1 t 0.200: person 1 at (-2.00, 1.00), 4 returns",
            ]
        );
    }
}
