//! Replay of umbra's own MCAP recordings (`docs/interfaces.md` §2): `umbra replay RUN.mcap` reads
//! back what `--record` wrote for it ([`crate::viz`], channels in [`crate::record_format`]): the LiDAR's bytes exactly as read
//! (`/umbra/lidar_raw`) and every encoder/compass sample the pose filter was fed
//! (`/umbra/odometry`, each with the frame at which it became available), then runs them
//! through the same pipeline as the recorded run: the bytes as a capture, each sample made
//! available to the pose at its frame, so frames, poses and objects come out as recorded. The
//! recording is read whole at start-up (an hour of LDS-01 bytes is ~45 MB).

use std::path::{Path, PathBuf};

use drivers::lidar::LidarModel;

use crate::odom::OdomRecord;
use crate::record_format::{ODOM_TOPIC, RAW_TOPIC, RecordedSample};

/// The first bytes of every MCAP file.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// What a recording holds for replay.
#[derive(Debug, Clone)]
pub struct Recording {
    /// The file.
    pub path: PathBuf,
    /// The LiDAR model named in the raw channel's metadata, if it is one umbra knows.
    pub model: Option<LidarModel>,
    /// What the source was, as the recording run described it.
    pub source: Option<String>,
    /// `carmen` when the recorded bytes are a CARMEN log's text, not a LiDAR's.
    pub format: Option<String>,
    /// The simulated compass's calibration (hard iron, field reference), if recorded.
    pub compass_calibration: Option<([f32; 2], [f32; 2])>,
    /// The LiDAR's bytes, in the order read.
    pub bytes: Vec<u8>,
    /// The odometry samples, each with the frame at which it became available.
    pub odometry: Vec<(u64, OdomRecord)>,
    /// Odometry messages that did not parse (counted as encoder errors on replay).
    pub bad_odometry: u64,
}

/// Whether `path` starts like an MCAP file (an unreadable file is not).
pub fn is_mcap(path: &Path) -> bool {
    use std::io::Read as _;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && head == MCAP_MAGIC
}

/// Reads the replay channels of an MCAP file written by `umbra --record`. Errors name the
/// file and say what is wrong (not MCAP, damaged, no raw LiDAR channel).
pub fn read(path: &Path) -> Result<Recording, String> {
    let shown = path.display();
    let data = std::fs::read(path).map_err(|e| format!("recording {shown}: cannot read: {e}"))?;
    let mut rec = Recording {
        path: path.to_owned(),
        model: None,
        source: None,
        format: None,
        compass_calibration: None,
        bytes: Vec::new(),
        odometry: Vec::new(),
        bad_odometry: 0,
    };
    let mut raw_channel = false;
    let stream = mcap::MessageStream::new(&data)
        .map_err(|e| format!("recording {shown}: not a readable MCAP file: {e}"))?;
    for (k, message) in stream.enumerate() {
        let m = match message {
            Ok(m) => m,
            Err(e) if rec.bytes.is_empty() => {
                return Err(format!("recording {shown}: damaged at message {k}: {e}"));
            }
            Err(e) => {
                // A recording cut short (power lost): replay what came before.
                log::warn!(
                    "recording {shown}: damaged after message {k} ({e}); replaying what came before"
                );
                break;
            }
        };
        match m.channel.topic.as_str() {
            RAW_TOPIC => {
                if !raw_channel {
                    raw_channel = true;
                    let meta = &m.channel.metadata;
                    rec.model = meta
                        .get("model")
                        .and_then(|n| LidarModel::ALL.into_iter().find(|m| m.cli_name() == n));
                    rec.source = meta.get("source").cloned();
                    rec.format = meta.get("format").cloned();
                    rec.compass_calibration = meta
                        .get("compass_calibration")
                        .and_then(|s| parse_calibration(s));
                }
                rec.bytes.extend_from_slice(&m.data);
            }
            ODOM_TOPIC => match serde_json::from_slice::<RecordedSample>(&m.data) {
                Ok(s) => rec.odometry.push((s.frame, s.sample)),
                Err(e) => {
                    if rec.bad_odometry == 0 {
                        log::warn!("recording {shown}: odometry message {k} skipped: {e}");
                    }
                    rec.bad_odometry += 1;
                }
            },
            _ => {}
        }
    }
    if !raw_channel {
        return Err(format!(
            "recording {shown}: no {RAW_TOPIC} channel: it was not written by `umbra --record` (or by an umbra before replay was recorded), so there is nothing to replay"
        ));
    }
    Ok(rec)
}

fn parse_calibration(s: &str) -> Option<([f32; 2], [f32; 2])> {
    let v: Vec<f32> = s
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .ok()?;
    match v[..] {
        [hx, hy, f, z] if v.iter().all(|x| x.is_finite()) => Some(([hx, hy], [f, z])),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calibration_metadata_round_trips_and_rejects_junk() {
        assert_eq!(
            parse_calibration("1.5 -2 20.25 40"),
            Some(([1.5, -2.0], [20.25, 40.0]))
        );
        assert_eq!(parse_calibration("1 2 3"), None);
        assert_eq!(parse_calibration("1 2 3 NaN"), None);
        assert_eq!(parse_calibration("a b c d"), None);
    }

    #[test]
    fn files_that_are_not_recordings_are_clear_errors() {
        let dir = std::env::temp_dir().join(format!("umbra-rec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("not.mcap");
        std::fs::write(&p, b"\x89MCAP0\r\nbut then nothing sensible").unwrap();
        assert!(is_mcap(&p));
        let e = read(&p).unwrap_err();
        assert!(e.contains("not.mcap"), "{e}");
        let q = dir.join("capture.bin");
        std::fs::write(&q, [0xFA, 0xA0, 0, 0]).unwrap();
        assert!(!is_mcap(&q));
        assert!(!is_mcap(&dir.join("missing")));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
