//! `--track-log`: every frame's tracks that earned a report, with what the report model
//! reads of them (`perception::tracks::Track::report_features`), one text line each — what
//! `training/fit_report_model.py` fits the report model on. Off unless asked for; with it on
//! the frame loop writes through one buffer made at start-up, and a write that fails ends the
//! log with a warning, not the run.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use perception::tracks::{FEATURE_NAMES, Track};

/// The log's buffer, bytes.
const BUFFER_BYTES: usize = 1 << 16;

/// Where the tracks go; `None` inside: no log.
#[derive(Default)]
pub struct TrackLog {
    out: Option<BufWriter<File>>,
}

impl TrackLog {
    /// Opens `path` (none: no log) and writes the header line.
    pub fn create(path: Option<&Path>) -> io::Result<Self> {
        let Some(path) = path else {
            return Ok(TrackLog::default());
        };
        let named =
            |e: io::Error| io::Error::new(e.kind(), format!("--track-log {}: {e}", path.display()));
        let mut out = BufWriter::with_capacity(BUFFER_BYTES, File::create(path).map_err(named)?);
        let header = |out: &mut BufWriter<File>| -> io::Result<()> {
            write!(out, "# frame id class x y source")?;
            for n in FEATURE_NAMES {
                write!(out, " {n}")?;
            }
            writeln!(out)
        };
        header(&mut out).map_err(named)?;
        Ok(TrackLog { out: Some(out) })
    }

    /// One line for `t` in `frame`.
    pub(super) fn write(&mut self, frame: u64, t: &Track) {
        let Some(out) = self.out.as_mut() else {
            return;
        };
        let mut line = || -> io::Result<()> {
            write!(
                out,
                "{frame} {} {} {:.3} {:.3} {}",
                t.id,
                t.class().as_str(),
                t.centre.x,
                t.centre.y,
                t.evidence().as_str()
            )?;
            for f in t.report_features(frame) {
                write!(out, " {f:.4}")?;
            }
            writeln!(out)
        };
        if let Err(e) = line() {
            log::warn!("track log: {e}; no more lines are written");
            self.out = None;
        }
    }
}

impl Drop for TrackLog {
    fn drop(&mut self) {
        if let Some(out) = self.out.as_mut()
            && let Err(e) = out.flush()
        {
            log::warn!("track log: {e}");
        }
    }
}
