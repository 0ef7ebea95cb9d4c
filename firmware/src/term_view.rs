//! `umbra run --view` / `umbra replay --view`: a live map in the terminal, for a person at a
//! shell on the robot (over SSH) without Foxglove — the current scan, the robot and its
//! heading, the objects labelled with class and id, the doors and the people walking, beside a
//! list of the same with their places, redrawn in place a few times a second (ratatui over
//! crossterm).
//!
//! The frame loop never draws and never allocates for this: it copies the frame into a box
//! taken from a pool made at start-up and hands it to the view thread through a bounded
//! channel; the thread keeps the newest, draws at most [`REDRAW_HZ`] times a second and
//! returns the boxes. When the thread falls behind, frames are dropped and counted, never
//! queued. The map's extent only grows (everything seen so far stays in the picture), so the
//! scale does not jump from frame to frame.

use std::io::{self, IsTerminal};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use perception::class::ObjectClass;
use perception::geometry::{Point2, Pose2};
use perception::raster::SCAN_COLUMNS;
use ratatui::Terminal;
use ratatui::backend::{Backend, CrosstermBackend};
use ratatui::layout::{Constraint, Direction, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Line as Stroke, Points};
use ratatui::widgets::{Block, Borders, Paragraph};

use crate::output::{DoorOut, ObjectOut, PersonOut};
use crate::sink::{FrameSink, FrameView, RunEnd};

/// Objects a frame carries to the view.
pub const VIEW_OBJECTS: usize = 64;
/// Doors a frame carries.
pub const VIEW_DOORS: usize = perception::doors::MAX_DOORS;
/// People a frame carries.
pub const VIEW_PEOPLE: usize = 16;
/// Frames in flight between the loop and the view thread.
pub const VIEW_POOL: usize = 3;
/// Most redraws a second.
pub const REDRAW_HZ: f64 = 5.0;
/// Width of the list beside the map, columns.
const PANEL_COLS: u16 = 38;

/// One frame as the view draws it.
#[derive(Clone)]
pub struct ViewFrame {
    /// Frame number.
    pub frame: u64,
    /// Sensor time, s.
    pub t: f64,
    /// The robot's pose in the map.
    pub robot: Pose2,
    /// This revolution's returns in the map frame.
    pub scan: heapless::Vec<Point2, SCAN_COLUMNS>,
    /// The line's objects.
    pub objects: heapless::Vec<ObjectOut, VIEW_OBJECTS>,
    /// The line's doors.
    pub doors: heapless::Vec<DoorOut, VIEW_DOORS>,
    /// The line's walking people.
    pub people: heapless::Vec<PersonOut, VIEW_PEOPLE>,
    /// Objects beyond [`VIEW_OBJECTS`] not drawn.
    pub objects_left_out: usize,
    /// The frame's time, ms.
    pub total_ms: f64,
    /// Whether it missed its deadline.
    pub missed: bool,
}

impl ViewFrame {
    fn empty() -> Self {
        ViewFrame {
            frame: 0,
            t: 0.0,
            robot: Pose2::IDENTITY,
            scan: heapless::Vec::new(),
            objects: heapless::Vec::new(),
            doors: heapless::Vec::new(),
            people: heapless::Vec::new(),
            objects_left_out: 0,
            total_ms: 0.0,
            missed: false,
        }
    }

    /// Copies a finished frame (no allocation: every buffer is fixed).
    pub fn fill(&mut self, f: &FrameView<'_>) {
        let l = &f.line;
        self.frame = l.frame;
        self.t = l.t;
        self.robot = f.pose;
        self.total_ms = l.timing_ms.total;
        self.missed = l.deadline_missed;
        let lidar = f.pose.compose(&f.mount);
        self.scan.clear();
        for (d, &r) in f.ranges.iter().enumerate() {
            if r > 0.0 && r.is_finite() {
                let a = (d as f32).to_radians();
                let p = lidar.transform(Point2::new(r * a.cos(), r * a.sin()));
                // Capacity is one point a bin: cannot fail.
                let _ = self.scan.push(p);
            }
        }
        self.objects.clear();
        self.objects_left_out = 0;
        for o in l.objects {
            if self.objects.push(o.clone()).is_err() {
                self.objects_left_out += 1;
            }
        }
        self.doors.clear();
        for d in l.doors.iter().take(VIEW_DOORS) {
            let _ = self.doors.push(d.clone());
        }
        self.people.clear();
        for p in l.people.unwrap_or(&[]).iter().take(VIEW_PEOPLE) {
            let _ = self.people.push(*p);
        }
    }
}

/// The map's extent in metres: grows to take in everything seen, never shrinks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    lo: Point2,
    hi: Point2,
}

impl Extent {
    /// A 4 m square around the origin to start with.
    pub fn new() -> Self {
        Extent {
            lo: Point2::new(-2.0, -2.0),
            hi: Point2::new(2.0, 2.0),
        }
    }

    fn take(&mut self, p: Point2) {
        if p.x.is_finite() && p.y.is_finite() && p.x.abs() < 1e4 && p.y.abs() < 1e4 {
            self.lo = Point2::new(self.lo.x.min(p.x - 0.3), self.lo.y.min(p.y - 0.3));
            self.hi = Point2::new(self.hi.x.max(p.x + 0.3), self.hi.y.max(p.y + 0.3));
        }
    }

    /// Takes in the frame's robot, scan, objects, doors and people.
    pub fn grow(&mut self, v: &ViewFrame) {
        self.take(Point2::new(v.robot.x, v.robot.y));
        for p in &v.scan {
            self.take(*p);
        }
        for o in &v.objects {
            self.take(Point2::new(o.x as f32, o.y as f32));
        }
    }

    /// Bounds `([x0, x1], [y0, y1])` that show the extent at one scale in both directions in
    /// a map of `cols` × `rows` terminal cells (a cell is about twice as tall as it is wide).
    pub fn bounds(&self, cols: u16, rows: u16) -> ([f64; 2], [f64; 2]) {
        let (w, h) = (
            f64::from(self.hi.x - self.lo.x),
            f64::from(self.hi.y - self.lo.y),
        );
        let (cols, rows) = (f64::from(cols.max(1)), f64::from(rows.max(1)) * 2.0);
        let per = (w / cols).max(h / rows);
        let (cx, cy) = (
            f64::from(self.lo.x + self.hi.x) / 2.0,
            f64::from(self.lo.y + self.hi.y) / 2.0,
        );
        let (hw, hh) = (per * cols / 2.0, per * rows / 2.0);
        ([cx - hw, cx + hw], [cy - hh, cy + hh])
    }
}

impl Default for Extent {
    fn default() -> Self {
        Extent::new()
    }
}

fn class_colour(class: ObjectClass) -> Color {
    match class {
        ObjectClass::Chair => Color::Green,
        ObjectClass::Desk => Color::Yellow,
        ObjectClass::Box => Color::Cyan,
        ObjectClass::DoorFrame => Color::Magenta,
    }
}

/// Draws one frame into `area`: the map on the left, the list on the right.
pub fn draw(frame: &mut ratatui::Frame<'_>, area: Rect, v: &ViewFrame, extent: &Extent) {
    let parts = Layout::default()
        .direction(Direction::Horizontal)
        .constraints([Constraint::Min(20), Constraint::Length(PANEL_COLS)])
        .split(area);
    let (map, panel) = (parts[0], parts[1]);
    let (xb, yb) = extent.bounds(map.width.saturating_sub(2), map.height.saturating_sub(2));
    let scan: Vec<(f64, f64)> = v
        .scan
        .iter()
        .map(|p| (f64::from(p.x), f64::from(p.y)))
        .collect();
    let (rx, ry) = (f64::from(v.robot.x), f64::from(v.robot.y));
    let (hs, hc) = (
        f64::from(v.robot.theta).sin(),
        f64::from(v.robot.theta).cos(),
    );
    let canvas = Canvas::default()
        .block(
            Block::default()
                .borders(Borders::ALL)
                .title(" umbra: live map (Ctrl-C stops) "),
        )
        .marker(Marker::Braille)
        .x_bounds(xb)
        .y_bounds(yb)
        .paint(|ctx| {
            ctx.draw(&Points {
                coords: &scan,
                color: Color::Gray,
            });
            ctx.draw(&Stroke::new(
                rx,
                ry,
                rx + 0.35 * hc,
                ry + 0.35 * hs,
                Color::Red,
            ));
            ctx.layer();
            for d in v
                .doors
                .iter()
                .filter(|d| d.x.is_finite() && d.y.is_finite())
            {
                ctx.print(
                    d.x,
                    d.y,
                    Span::styled("[door]", Style::default().fg(Color::Magenta)),
                );
            }
            // A door frame that is also in `doors` is labelled once, as the door.
            let shown = |o: &&ObjectOut| {
                o.x.is_finite()
                    && o.y.is_finite()
                    && !(o.class == ObjectClass::DoorFrame
                        && v.doors.iter().any(|d| (d.x - o.x).hypot(d.y - o.y) < 0.6))
            };
            for o in v.objects.iter().filter(shown) {
                ctx.print(
                    o.x,
                    o.y,
                    Span::styled(
                        format!("{}#{}", class_mark(o.class), o.id),
                        Style::default()
                            .fg(class_colour(o.class))
                            .add_modifier(Modifier::BOLD),
                    ),
                );
            }
            for p in v
                .people
                .iter()
                .filter(|p| p.x.is_finite() && p.y.is_finite())
            {
                ctx.print(
                    p.x,
                    p.y,
                    Span::styled(format!("P#{}", p.id), Style::default().fg(Color::LightRed)),
                );
            }
            ctx.print(
                rx,
                ry,
                Span::styled(
                    "@",
                    Style::default().fg(Color::Red).add_modifier(Modifier::BOLD),
                ),
            );
        });
    frame.render_widget(canvas, map);
    frame.render_widget(
        Paragraph::new(panel_lines(v)).block(
            Block::default()
                .borders(Borders::ALL)
                .title(" what the robot sees "),
        ),
        panel,
    );
}

fn class_mark(class: ObjectClass) -> &'static str {
    match class {
        ObjectClass::Chair => "C",
        ObjectClass::Desk => "D",
        ObjectClass::Box => "B",
        ObjectClass::DoorFrame => "F",
    }
}

/// The list beside the map.
fn panel_lines(v: &ViewFrame) -> Vec<Line<'static>> {
    let mut lines = vec![
        Line::from(format!("frame {}  t {:.1} s", v.frame, v.t)),
        Line::from(format!(
            "robot @ ({:.2}, {:.2}) {:.0}°",
            v.robot.x,
            v.robot.y,
            v.robot.theta.to_degrees()
        )),
        Line::from(Span::styled(
            format!(
                "frame time {:.1} ms{}",
                v.total_ms,
                if v.missed { "  MISSED" } else { "" }
            ),
            Style::default().fg(if v.missed { Color::Red } else { Color::Reset }),
        )),
        Line::from(""),
    ];
    if v.objects.is_empty() {
        lines.push(Line::from("no objects"));
    }
    for class in [ObjectClass::Chair, ObjectClass::Desk, ObjectClass::Box] {
        for o in v.objects.iter().filter(|o| o.class == class) {
            lines.push(Line::from(Span::styled(
                format!(
                    "{}#{} {} ({:.1}, {:.1}) {:.2} {}",
                    class_mark(class),
                    o.id,
                    class.as_str(),
                    o.x,
                    o.y,
                    o.score,
                    o.source.as_str()
                ),
                Style::default().fg(class_colour(class)),
            )));
        }
    }
    if v.objects_left_out > 0 {
        lines.push(Line::from(format!("… {} more", v.objects_left_out)));
    }
    lines.push(Line::from(""));
    if v.doors.is_empty() {
        lines.push(Line::from("no doors"));
    }
    for d in &v.doors {
        lines.push(Line::from(Span::styled(
            format!("door ({:.1}, {:.1}) {:.2} m", d.x, d.y, d.width),
            Style::default().fg(Color::Magenta),
        )));
    }
    for p in &v.people {
        lines.push(Line::from(Span::styled(
            format!(
                "walking P#{} ({:.1}, {:.1}) {:.1} m/s",
                p.id,
                p.x,
                p.y,
                p.vx.hypot(p.vy)
            ),
            Style::default().fg(Color::LightRed),
        )));
    }
    lines
}

/// The loop's end of the view: a pool of frames and the drawing thread.
pub struct ViewSink {
    to_view: Option<SyncSender<Box<ViewFrame>>>,
    pool: Receiver<Box<ViewFrame>>,
    thread: Option<JoinHandle<io::Result<()>>>,
    /// A box the view could not take (its queue was full), used for the next frame.
    spare: Option<Box<ViewFrame>>,
    dropped: u64,
}

impl ViewSink {
    /// Starts the view on this process's terminal; an error if stdout is not a terminal.
    pub fn start() -> Result<ViewSink, String> {
        let out = io::stdout();
        if !out.is_terminal() {
            return Err("--view draws on a terminal, and stdout is not one".into());
        }
        let terminal = Terminal::new(CrosstermBackend::new(out))
            .map_err(|e| format!("--view: cannot use the terminal: {e}"))?;
        Ok(ViewSink::with_terminal(terminal))
    }

    /// Starts the view on any ratatui backend (tests draw into a `TestBackend`).
    pub fn with_terminal<B: Backend + Send + 'static>(terminal: Terminal<B>) -> ViewSink {
        let (to_view, frames) = sync_channel::<Box<ViewFrame>>(VIEW_POOL);
        let (back, pool) = sync_channel::<Box<ViewFrame>>(VIEW_POOL);
        for _ in 0..VIEW_POOL {
            // The pool channel holds VIEW_POOL: cannot be full here.
            let _ = back.try_send(Box::new(ViewFrame::empty()));
        }
        let thread = std::thread::Builder::new()
            .name("umbra-view".into())
            .spawn(move || view_thread(terminal, frames, back))
            .ok();
        ViewSink {
            to_view: Some(to_view),
            pool,
            thread,
            spare: None,
            dropped: 0,
        }
    }
}

/// Draws the newest frame at most [`REDRAW_HZ`] times a second; the last frame always.
fn view_thread<B: Backend>(
    mut terminal: Terminal<B>,
    frames: Receiver<Box<ViewFrame>>,
    back: SyncSender<Box<ViewFrame>>,
) -> io::Result<()> {
    terminal.clear()?;
    terminal.hide_cursor()?;
    let mut extent = Extent::new();
    let mut last: Option<Box<ViewFrame>> = None;
    let mut drawn_at: Option<Instant> = None;
    let period = Duration::from_secs_f64(1.0 / REDRAW_HZ);
    let mut pending = false;
    loop {
        let next = match drawn_at {
            Some(at) if pending => frames.recv_timeout(period.saturating_sub(at.elapsed())),
            _ => frames
                .recv()
                .map_err(|_| std::sync::mpsc::RecvTimeoutError::Disconnected),
        };
        match next {
            Ok(v) => {
                extent.grow(&v);
                if let Some(old) = last.replace(v) {
                    let _ = back.try_send(old);
                }
                pending = true;
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
        }
        if pending && drawn_at.is_none_or(|at| at.elapsed() >= period) {
            if let Some(v) = &last {
                terminal.draw(|f| draw(f, f.area(), v, &extent))?;
            }
            drawn_at = Some(Instant::now());
            pending = false;
        }
    }
    if let Some(v) = &last {
        terminal.draw(|f| draw(f, f.area(), v, &extent))?;
    }
    terminal.show_cursor()?;
    // Leave the final map on the screen; what follows starts below it.
    let rows = terminal.size()?.height;
    terminal.set_cursor_position((0, rows.saturating_sub(1)))?;
    println!();
    Ok(())
}

impl FrameSink for ViewSink {
    fn frame(&mut self, f: &FrameView<'_>) -> io::Result<bool> {
        let Some(mut v) = self.spare.take().or_else(|| self.pool.try_recv().ok()) else {
            self.dropped += 1;
            return Ok(false);
        };
        v.fill(f);
        if let Some(tx) = &self.to_view {
            match tx.try_send(v) {
                Ok(()) => {}
                Err(TrySendError::Full(v)) => {
                    self.spare = Some(v);
                    self.dropped += 1;
                }
                Err(TrySendError::Disconnected(_)) => {
                    return Err(io::Error::other("the view thread stopped"));
                }
            }
        }
        Ok(false)
    }

    fn finish(&mut self, _end: &RunEnd<'_>) -> io::Result<()> {
        self.to_view = None;
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Err(io::Error::other("the view thread panicked")),
            None => Ok(()),
        }
    }

    fn dropped(&self) -> u64 {
        self.dropped
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use perception::fusion::Evidence;
    use ratatui::backend::TestBackend;

    fn frame() -> ViewFrame {
        let mut v = ViewFrame::empty();
        v.frame = 42;
        v.robot = Pose2::new(1.0, 1.0, 0.0);
        for k in 0..40 {
            let _ = v.scan.push(Point2::new(-1.0 + 0.1 * k as f32, 3.0));
        }
        let _ = v.objects.push(ObjectOut {
            id: 7,
            class: ObjectClass::Chair,
            x: 2.0,
            y: 2.0,
            score: 0.9,
            source: Evidence::AB,
            bbox: None,
            hits: Some(9),
            last_seen: Some(42),
        });
        let _ = v.doors.push(DoorOut {
            x: -1.0,
            y: 0.0,
            width: 0.85,
            score: 0.8,
        });
        v
    }

    fn screen(v: &ViewFrame, extent: &Extent) -> String {
        let mut t = Terminal::new(TestBackend::new(100, 30)).unwrap();
        t.draw(|f| draw(f, f.area(), v, extent)).unwrap();
        let buf = t.backend().buffer().clone();
        (0..buf.area.height)
            .map(|y| {
                (0..buf.area.width)
                    .map(|x| buf[(x, y)].symbol().to_string())
                    .collect::<String>()
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    #[test]
    fn the_map_labels_objects_and_the_list_says_where_they_are() {
        let v = frame();
        let mut e = Extent::new();
        e.grow(&v);
        let s = screen(&v, &e);
        assert!(s.contains("C#7"), "{s}");
        assert!(s.contains("[door]"), "{s}");
        assert!(s.contains("C#7 chair (2.0, 2.0) 0.90 AB"), "{s}");
        assert!(s.contains("door (-1.0, 0.0) 0.85 m"), "{s}");
        assert!(s.contains("frame 42"), "{s}");
        // The robot is drawn where it is: left of the chair, below it.
        let rows: Vec<&str> = s.lines().collect();
        // Only in the map, left of the list.
        let map_cols = 100 - usize::from(PANEL_COLS);
        let find = |pat: &str| {
            rows.iter().enumerate().find_map(|(y, r)| {
                let map: String = r.chars().take(map_cols).collect();
                map.find(pat).map(|x| (map[..x].chars().count(), y))
            })
        };
        let (rx, ry) = find("@").unwrap();
        let (cx, cy) = find("C#7").unwrap();
        assert!(rx < cx && ry > cy, "robot {rx},{ry} chair {cx},{cy}\n{s}");
    }

    #[test]
    fn one_scale_both_ways_and_the_extent_only_grows() {
        let mut e = Extent::new();
        let (x, y) = e.bounds(80, 20);
        // 80 columns of one width, 20 rows of two: the same metres per dot both ways.
        assert!(((x[1] - x[0]) / 80.0 - (y[1] - y[0]) / 40.0).abs() < 1e-9);
        let v = frame();
        e.grow(&v);
        let before = e;
        let mut far = ViewFrame::empty();
        far.robot = Pose2::new(f32::NAN, 1e9, 0.0);
        e.grow(&far);
        assert_eq!(e, before, "NaN and absurd places are not taken in");
        let mut small = ViewFrame::empty();
        small.robot = Pose2::new(0.0, 0.0, 0.0);
        e.grow(&small);
        assert_eq!(e, before, "the extent never shrinks");
    }

    #[test]
    fn frames_reach_the_view_thread_and_the_last_is_drawn() {
        let t = Terminal::new(TestBackend::new(90, 24)).unwrap();
        let mut sink = ViewSink::with_terminal(t);
        let v = frame();
        // Through the channel as the loop would hand it (fill is tested by the e2e run).
        let mut b = sink.pool.try_recv().unwrap();
        *b = v;
        sink.to_view.as_ref().unwrap().try_send(b).unwrap();
        sink.to_view = None;
        let r = sink.thread.take().unwrap().join().unwrap();
        assert!(r.is_ok(), "{r:?}");
    }
}
