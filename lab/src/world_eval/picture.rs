//! A run's final map as a picture: the true walls, furniture (outlined by class; faint where
//! it was never visible), clutter and doors, the robot's path, and what the last output line
//! reported (discs by class with their ids; a red ring marks a phantom; violet squares are
//! `doors`).

use std::path::Path;

use perception::class::ObjectClass;
use perception::geometry::Point2;

use super::score::{DOOR_MATCH_M, Line, MATCH_M};
use crate::canvas::Canvas;
use crate::run_truth::RunTruth;

const PX_PER_M: f32 = 60.0;
const MARGIN: f32 = 40.0;
const TOP: f32 = 40.0;

fn colour(c: Option<ObjectClass>) -> [u8; 3] {
    match c {
        Some(ObjectClass::Chair) => [40, 90, 220],
        Some(ObjectClass::Box) => [230, 130, 20],
        Some(ObjectClass::Desk) => [30, 160, 60],
        Some(ObjectClass::DoorFrame) => [150, 60, 200],
        None => [0, 0, 0],
    }
}

fn faint(c: [u8; 3]) -> [u8; 3] {
    c.map(|v| 255 - (255 - v) / 4)
}

/// Draws `truth` and the last of `lines` to `path`, titled `title`.
pub fn write(path: &Path, title: &str, truth: &RunTruth, lines: &[Line]) -> std::io::Result<()> {
    let pts = truth.walls.iter().flat_map(|(a, b)| [*a, *b]);
    let (mut lo, mut hi) = (
        Point2::new(f32::MAX, f32::MAX),
        Point2::new(f32::MIN, f32::MIN),
    );
    for p in pts {
        lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    if lo.x > hi.x {
        (lo, hi) = (Point2::new(-5.0, -5.0), Point2::new(5.0, 5.0));
    }
    let w = ((hi.x - lo.x) * PX_PER_M + 2.0 * MARGIN) as usize;
    let h = ((hi.y - lo.y) * PX_PER_M + 2.0 * MARGIN + TOP) as usize;
    let mut c = Canvas::new(w.max(Canvas::text_width(title) + 20), h);
    let px = |p: Point2| {
        (
            MARGIN + (p.x - lo.x) * PX_PER_M,
            TOP + MARGIN + (hi.y - p.y) * PX_PER_M,
        )
    };
    c.text(8, 8, title, [0, 0, 0]);
    for (a, b) in &truth.walls {
        c.line(px(*a), px(*b), 3, [110, 110, 110]);
    }
    for (q, what) in &truth.clutter {
        c.circle(px(*q), 0.15 * PX_PER_M, [150, 150, 150], true);
        let (x, y) = px(*q);
        c.text((x + 10.0) as usize, y as usize, what, [120, 120, 120]);
    }
    for d in &truth.doors {
        let (x, y) = px(d.centre);
        c.rect((x - 4.0) as usize, (y - 4.0) as usize, 9, 9, [150, 100, 60]);
    }
    let Some(last) = lines.last() else {
        return c.write_png(path);
    };
    let f_end = truth.frame_at(last.t).unwrap_or(0);
    for f in &truth.furniture {
        let col = if f.visible_from.is_some() && f.alive(f_end) {
            colour(Some(f.class))
        } else {
            faint(colour(Some(f.class)))
        };
        for (i, a) in f.footprint.iter().enumerate() {
            let b = f.footprint[(i + 1) % f.footprint.len()];
            c.line(px(*a), px(b), 2, col);
        }
    }
    for pair in lines.windows(2) {
        if let (Some(a), Some(b)) = (pair[0].pose, pair[1].pose) {
            c.line(
                px(Point2::new(a.x, a.y)),
                px(Point2::new(b.x, b.y)),
                1,
                [200, 40, 160],
            );
        }
    }
    for d in &last.doors {
        let (x, y) = px(*d);
        c.rect(
            (x - 7.0) as usize,
            (y - 7.0) as usize,
            15,
            15,
            [150, 60, 200],
        );
    }
    for o in &last.objects {
        let on_truth = match o.class {
            Some(ObjectClass::DoorFrame) => truth
                .doors
                .iter()
                .any(|d| d.centre.distance(o.at) <= DOOR_MATCH_M),
            _ => truth
                .furniture
                .iter()
                .any(|f| f.alive(f_end) && f.distance(o.at) <= MATCH_M),
        };
        let p = px(o.at);
        c.circle(p, 7.0, colour(o.class), true);
        if !on_truth {
            c.circle(p, 10.0, [230, 0, 0], false);
            c.circle(p, 11.0, [230, 0, 0], false);
        }
        c.text(
            (p.0 + 12.0) as usize,
            (p.1 - 6.0) as usize,
            &format!("#{}", o.id),
            [0, 0, 0],
        );
    }
    c.write_png(path)
}

/// Phantoms per frame among the reported objects, by source (A, B, AB stacked), one bar per
/// family and world setting.
pub fn write_phantom_bars(path: &Path, outcomes: &[super::Outcome]) -> std::io::Result<()> {
    const BAR: usize = 80;
    const GAP: usize = 60;
    const H: f32 = 300.0;
    let per_frame = |p: &[u32; 3], frames: u32| p.map(|x| f64::from(x) / f64::from(frames.max(1)));
    let mut bars: Vec<(String, [f64; 3])> = Vec::new();
    for o in outcomes {
        let fam = o.family.split(' ').next().unwrap_or("");
        let t = &o.tally;
        let on = if o.world { "on" } else { "off" };
        bars.push((format!("{fam} {on}"), per_frame(&t.phantoms, t.frames)));
    }
    let top = bars
        .iter()
        .map(|(_, v)| v.iter().sum::<f64>())
        .fold(0.5, f64::max)
        * 1.1;
    let w = 80 + bars.len() * (BAR + GAP);
    let h = (H as usize) + 120;
    let mut c = Canvas::new(w.max(620), h);
    c.text(
        8,
        8,
        "Phantoms per frame (reported objects on no furniture)",
        [0, 0, 0],
    );
    c.text(
        8,
        30,
        "A blue, B orange, AB green; world model off / on",
        [90, 90, 90],
    );
    let base = 70.0 + H;
    let colours = [[40, 90, 220], [230, 130, 20], [30, 160, 60]];
    for (k, (label, v)) in bars.iter().enumerate() {
        let x = 60 + k * (BAR + GAP);
        let mut y = base;
        for (s, &val) in v.iter().enumerate() {
            let hgt = (val / top) as f32 * H;
            c.rect(x, (y - hgt) as usize, BAR, hgt.ceil() as usize, colours[s]);
            y -= hgt;
        }
        c.text(
            x,
            (y - 20.0).max(50.0) as usize,
            &format!("{:.2}", v.iter().sum::<f64>()),
            [0, 0, 0],
        );
        c.text(x, base as usize + 8, label, [0, 0, 0]);
    }
    c.line((50.0, base), ((w - 10) as f32, base), 1, [0, 0, 0]);
    c.write_png(path)
}
