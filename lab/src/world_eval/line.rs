//! One `umbra` output line as the world evaluation reads it (`Line`, its `Reported` objects):
//! parsed from the JSON, keeping only what the scorer uses.

use perception::class::ObjectClass;
use perception::geometry::{Point2, Pose2};
use serde_json::Value;

/// One reported object.
#[derive(Debug, Clone, PartialEq)]
pub struct Reported {
    /// `id`.
    pub id: u64,
    /// Class (None: a class this scorer does not know).
    pub class: Option<ObjectClass>,
    /// Position, map frame.
    pub at: Point2,
    /// `source`: 0 = A, 1 = B, 2 = AB.
    pub source: usize,
    /// `score` (NaN when the line has none).
    pub score: f32,
}

/// One output line, as far as the scorer reads it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Line {
    /// The line's `frame` number, when it has one.
    pub frame: Option<u64>,
    /// Sensor time, s.
    pub t: f64,
    /// `objects`.
    pub objects: Vec<Reported>,
    /// `doors` centres.
    pub doors: Vec<Point2>,
    /// `detections`, when the line has them.
    pub detections: Option<Vec<Reported>>,
    /// `people` positions, when the line has them.
    pub people: Option<Vec<Point2>>,
    /// The robot's pose.
    pub pose: Option<Pose2>,
}

fn objects(v: Option<&Value>) -> Option<Vec<Reported>> {
    let arr = v?.as_array()?;
    Some(
        arr.iter()
            .filter_map(|o| {
                let x = o.get("x")?.as_f64()? as f32;
                let y = o.get("y")?.as_f64()? as f32;
                Some(Reported {
                    id: o.get("id").and_then(Value::as_u64).unwrap_or(u64::MAX),
                    class: o
                        .get("class")
                        .and_then(Value::as_str)
                        .and_then(ObjectClass::from_name),
                    at: Point2::new(x, y),
                    source: match o.get("source").and_then(Value::as_str) {
                        Some("A") => 0,
                        Some("B") => 1,
                        _ => 2,
                    },
                    score: o.get("score").and_then(Value::as_f64).unwrap_or(f64::NAN) as f32,
                })
            })
            .collect(),
    )
}

fn points(v: Option<&Value>) -> Option<Vec<Point2>> {
    Some(
        v?.as_array()?
            .iter()
            .filter_map(|o| {
                Some(Point2::new(
                    o.get("x")?.as_f64()? as f32,
                    o.get("y")?.as_f64()? as f32,
                ))
            })
            .collect(),
    )
}

impl Line {
    /// Parses one JSON output line (None: not a frame line).
    pub fn parse(s: &str) -> Option<Line> {
        let v: Value = serde_json::from_str(s).ok()?;
        Some(Line {
            frame: v.get("frame").and_then(Value::as_u64),
            t: v.get("t")?.as_f64()?,
            objects: objects(v.get("objects"))?,
            doors: points(v.get("doors")).unwrap_or_default(),
            detections: objects(v.get("detections")),
            people: points(v.get("people")),
            pose: v.get("pose").and_then(|p| {
                Some(Pose2::new(
                    p.get("x")?.as_f64()? as f32,
                    p.get("y")?.as_f64()? as f32,
                    p.get("theta")?.as_f64()? as f32,
                ))
            }),
        })
    }
}
