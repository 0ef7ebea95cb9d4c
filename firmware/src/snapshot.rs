//! `--snapshot PATH.svg`: a picture of the run's last frame for a person: the point cloud
//! (the map Method A keeps), walls, doors, the robot and its heading, and labelled objects.
//!
//! Written once, when the run ends (not on the frame's path). Plain SVG written by hand: the
//! picture is a few hundred shapes, and SVG keeps labels as text a browser can search.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use perception::geometry::{Point2, Pose2};

use perception::class::ObjectClass;

use crate::output::{DoorOut, ObjectOut, WallOut};
use crate::sink::{FrameSink, FrameView, RunEnd};

/// What the snapshot draws.
#[derive(Debug, Clone, Copy)]
pub struct Scene<'a> {
    /// Points of the map (metres, map frame).
    pub cloud: &'a [Point2],
    /// The robot.
    pub robot: Pose2,
    /// Walls.
    pub walls: &'a [WallOut],
    /// Doors.
    pub doors: &'a [DoorOut],
    /// Objects.
    pub objects: &'a [ObjectOut],
    /// Caption.
    pub caption: &'a str,
}

/// Pixels a metre.
const SCALE: f64 = 80.0;
/// Margin around the content, m.
const MARGIN_M: f64 = 0.6;

fn class_colour(class: ObjectClass) -> &'static str {
    match class {
        ObjectClass::Chair => "#e69f00",
        ObjectClass::Box => "#56b4e9",
        ObjectClass::Desk => "#009e73",
        ObjectClass::DoorFrame => "#cc79a7",
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The scene as an SVG document (map x to the right, y up, as in ROS REP 103).
pub fn svg(scene: &Scene<'_>) -> String {
    let r = &scene.robot;
    let (mut lo_x, mut lo_y) = (f64::from(r.x) - 1.0, f64::from(r.y) - 1.0);
    let (mut hi_x, mut hi_y) = (f64::from(r.x) + 1.0, f64::from(r.y) + 1.0);
    let mut grow = |x: f64, y: f64| {
        if x.is_finite() && y.is_finite() {
            lo_x = lo_x.min(x);
            lo_y = lo_y.min(y);
            hi_x = hi_x.max(x);
            hi_y = hi_y.max(y);
        }
    };
    for p in scene.cloud {
        grow(f64::from(p.x), f64::from(p.y));
    }
    for w in scene.walls {
        grow(w.x0, w.y0);
        grow(w.x1, w.y1);
    }
    for o in scene.objects {
        grow(o.x, o.y);
    }
    let (x0, y1) = (lo_x - MARGIN_M, hi_y + MARGIN_M);
    let width = (hi_x - lo_x + 2.0 * MARGIN_M) * SCALE;
    let height = (hi_y - lo_y + 2.0 * MARGIN_M) * SCALE + 30.0;
    let px = |x: f64| (x - x0) * SCALE;
    let py = |y: f64| (y1 - y) * SCALE;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.1} {height:.1}" font-family="sans-serif">"##
    );
    let _ = writeln!(s, r##"<rect width="100%" height="100%" fill="#1e1e1e"/>"##);
    // A 1 m grid.
    let _ = writeln!(s, r##"<g stroke="#333" stroke-width="1">"##);
    let mut gx = lo_x.floor() - 1.0;
    while gx <= hi_x + 1.0 {
        let _ = writeln!(
            s,
            r#"<line x1="{0:.1}" y1="0" x2="{0:.1}" y2="{1:.1}"/>"#,
            px(gx),
            height - 30.0
        );
        gx += 1.0;
    }
    let mut gy = lo_y.floor() - 1.0;
    while gy <= hi_y + 1.0 {
        let _ = writeln!(
            s,
            r#"<line x1="0" y1="{0:.1}" x2="{1:.1}" y2="{0:.1}"/>"#,
            py(gy),
            width
        );
        gy += 1.0;
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, r##"<g fill="#bbbbbb" id="cloud">"##);
    for p in scene.cloud {
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="1.2"/>"#,
            px(f64::from(p.x)),
            py(f64::from(p.y))
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(
        s,
        r##"<g stroke="#f0f0f0" stroke-width="3" stroke-linecap="round" id="walls">"##
    );
    for w in scene.walls {
        let _ = writeln!(
            s,
            r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}"/>"#,
            px(w.x0),
            py(w.y0),
            px(w.x1),
            py(w.y1)
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, r#"<g id="doors">"#);
    for d in scene.doors {
        let _ = writeln!(
            s,
            r##"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" fill="none" stroke="#cc79a7" stroke-width="2" stroke-dasharray="4 3"/>"##,
            px(d.x),
            py(d.y),
            d.width / 2.0 * SCALE
        );
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, r#"<g id="objects" font-size="12">"#);
    for o in scene.objects {
        let c = class_colour(o.class);
        let (x, y) = (px(o.x), py(o.y));
        let _ = writeln!(
            s,
            r#"<rect x="{:.1}" y="{:.1}" width="16" height="16" fill="{c}" fill-opacity="0.8"/>"#,
            x - 8.0,
            y - 8.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" fill="{c}">{} {:.2} {}</text>"#,
            x + 10.0,
            y - 10.0,
            o.class,
            o.score,
            o.source.as_str()
        );
    }
    let _ = writeln!(s, "</g>");
    // The robot: a circle of the TurtleBot3 Burger's radius and a heading line.
    let (rx, ry, th) = (f64::from(r.x), f64::from(r.y), f64::from(r.theta));
    let _ = writeln!(
        s,
        r##"<g id="robot" stroke="#ff5555" stroke-width="2" fill="none"><circle cx="{:.1}" cy="{:.1}" r="{:.1}"/><line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}"/></g>"##,
        px(rx),
        py(ry),
        0.105 * SCALE,
        px(rx),
        py(ry),
        px(rx + 0.25 * th.cos()),
        py(ry + 0.25 * th.sin())
    );
    let _ = writeln!(
        s,
        r##"<text x="8" y="{:.1}" fill="#dddddd" font-size="14">{}</text>"##,
        height - 10.0,
        escape(scene.caption)
    );
    let _ = writeln!(s, "</svg>");
    s
}

/// Checks an output path before the run (its folder must exist); the error names it.
pub fn check_path(path: &Path) -> Result<(), String> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => Err(format!(
            "{}: folder {} does not exist",
            path.display(),
            dir.display()
        )),
        _ => Ok(()),
    }
}

/// Writes the scene to `path` (SVG); the error names the file.
pub fn write(path: &Path, scene: &Scene<'_>) -> Result<(), String> {
    std::fs::write(path, svg(scene)).map_err(|e| format!("--snapshot {}: {e}", path.display()))
}

/// Draws the run's last frame when it ends (`--snapshot`); a write error is logged, not fatal.
pub struct SnapshotSink(pub PathBuf);

impl FrameSink for SnapshotSink {
    fn frame(&mut self, _f: &FrameView<'_>) -> std::io::Result<bool> {
        Ok(false)
    }
    fn finish(&mut self, end: &RunEnd<'_>) -> std::io::Result<()> {
        let caption = format!(
            "umbra, frame {}, t {:.1} s: {} objects, {} walls, {} doors",
            end.frames.saturating_sub(1),
            end.sensor_seconds,
            end.objects.len(),
            end.walls.len(),
            end.doors.len()
        );
        let scene = Scene {
            cloud: end.cloud,
            robot: end.robot,
            walls: end.walls,
            doors: end.doors,
            objects: end.objects,
            caption: &caption,
        };
        if let Err(e) = write(&self.0, &scene) {
            log::error!("{e}");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svg_has_every_layer_and_the_labels() {
        let cloud = [Point2::new(1.0, 0.0), Point2::new(-1.0, 2.0)];
        let walls = [WallOut {
            x0: -2.0,
            y0: 2.0,
            x1: 2.0,
            y1: 2.0,
        }];
        let doors = [DoorOut {
            x: 1.9,
            y: 0.0,
            width: 0.9,
            score: 1.0,
        }];
        let objects = [ObjectOut {
            id: 0,
            class: ObjectClass::Chair,
            x: 1.5,
            y: 0.4,
            score: 0.97,
            source: perception::fusion::Evidence::A,
            bbox: None,
            hits: Some(4),
            last_seen: Some(7),
        }];
        let s = svg(&Scene {
            cloud: &cloud,
            robot: Pose2::new(0.0, 0.0, 0.5),
            walls: &walls,
            doors: &doors,
            objects: &objects,
            caption: "frame 7 <sim>",
        });
        for id in ["cloud", "walls", "doors", "objects", "robot"] {
            assert!(s.contains(&format!("id=\"{id}\"")), "{id}");
        }
        assert!(s.contains(">chair 0.97 A</text>"));
        assert!(s.contains("frame 7 &lt;sim&gt;"));
        assert_eq!(s.matches("<circle").count(), 2 + 1 + 1);
        assert!(s.starts_with("<svg") && s.trim_end().ends_with("</svg>"));
    }
}
