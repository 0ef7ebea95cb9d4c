//! Finding out which LiDAR is on a port (`--lidar-model auto`, std): try the candidate baud
//! rates, wake whatever may be there, and let [`crate::lidar::detect::Detector`] recognise the
//! bytes. The report says what was found at which rate, or, per rate, why nothing was:
//! no bytes at all (power, cable, wrong device), bytes but no valid frame (wrong rate, not a
//! LiDAR), frames with a high error rate (noise, a Pi mini-UART whose clock drifts).
//!
//! At each rate the prober sends the LDS-01's motor-start byte `b` and the RPLIDAR's start
//! sequence (DTR released, `SCAN`); both are ignored by the other models (the LDROBOT ones have
//! no receive line). The port that found the LiDAR is handed back open, so no data is lost
//! to a reopen and an RPLIDAR keeps scanning.

use std::fmt;
use std::time::{Duration, Instant};

use embedded_io::Read as _;

use crate::lidar::LidarModel;
use crate::lidar::detect::{Detector, MIN_UNITS, Verdict};
use crate::serial::{LinkError, Port, SerialConfig, open_port};

/// Baud rates tried, in order: LDS-01 / LD06 / LD19, then LDS-02 / RPLIDAR A1, then A2M12.
pub const PROBE_BAUDS: [u32; 3] = [230_400, 115_200, 256_000];

/// One rate tried.
#[derive(Debug, Clone, PartialEq)]
pub struct Attempt {
    /// Baud rate.
    pub baud: u32,
    /// What the bytes said.
    pub verdict: Verdict,
}

/// The outcome of a probe.
pub struct Probe {
    /// Device path.
    pub path: String,
    /// Rates tried, in order.
    pub attempts: Vec<Attempt>,
    /// The model found, at which rate, with the open port.
    pub found: Option<(LidarModel, u32, Port)>,
}

impl fmt::Debug for Probe {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Probe")
            .field("path", &self.path)
            .field("attempts", &self.attempts)
            .field("found", &self.found.as_ref().map(|(m, b, _)| (m, b)))
            .finish()
    }
}

/// A verdict in words.
pub fn describe(v: &Verdict) -> String {
    match *v {
        Verdict::NoBytes => "no bytes at all".into(),
        Verdict::NoFrames { bytes } => {
            format!("{bytes} bytes but no valid frame of any model (wrong rate, or not a LiDAR)")
        }
        Verdict::HighErrorRate {
            model,
            units,
            error_rate,
        } => format!(
            "{model}-like frames ({units}) but {:.0} % errors (noise, cable, or a drifting UART clock)",
            error_rate * 100.0
        ),
        Verdict::Found {
            model,
            units,
            error_rate,
        } => format!(
            "{model}: {units} valid frames, {:.1} % errors",
            error_rate * 100.0
        ),
    }
}

impl Probe {
    /// One line: what was found, or why nothing was at each rate.
    pub fn summary(&self) -> String {
        match &self.found {
            Some((model, baud, _)) => {
                let mut s = format!("{model} found on {} at {baud} baud", self.path);
                if let Some(a) = self.attempts.last() {
                    s += &format!(" ({})", describe(&a.verdict));
                }
                if *baud != model.baud() {
                    s += &format!(
                        "; its native rate is {} baud (a pseudo-terminal reads at any rate)",
                        model.baud()
                    );
                }
                if let Some(twin) = model.same_bytes_as() {
                    s += &format!("; a {twin} sends the same bytes");
                }
                s
            }
            None => {
                let tried: Vec<String> = self
                    .attempts
                    .iter()
                    .map(|a| format!("{} baud: {}", a.baud, describe(&a.verdict)))
                    .collect();
                format!("no LiDAR recognised on {}: {}", self.path, tried.join("; "))
            }
        }
    }
}

/// Probes `path` at each of `bauds`, listening up to `listen` at each.
pub fn probe(path: &str, bauds: &[u32], listen: Duration) -> Result<Probe, LinkError> {
    let mut attempts = Vec::new();
    let mut buf = [0u8; 1024];
    for &baud in bauds {
        let cfg = SerialConfig {
            baud,
            read_timeout: Duration::from_millis(20),
            on_open: &[crate::lds01::link::START_MOTOR],
            rplidar_motor: true,
            ..SerialConfig::lds01()
        };
        let mut port = open_port(path, &cfg)?;
        crate::serial::run_on_open(&mut port, &cfg).map_err(|kind| LinkError::Io {
            path: path.to_owned(),
            kind,
        })?;
        let mut det = Detector::new();
        let t0 = Instant::now();
        while t0.elapsed() < listen {
            match port.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => det.feed(&buf[..n]),
                Err(e)
                    if matches!(
                        embedded_io::Error::kind(&e),
                        embedded_io::ErrorKind::TimedOut | embedded_io::ErrorKind::Interrupted
                    ) => {}
                Err(_) => break,
            }
            if let Verdict::Found { units, .. } = det.verdict()
                && units >= 4 * MIN_UNITS
            {
                break;
            }
        }
        let verdict = det.verdict();
        attempts.push(Attempt { baud, verdict });
        if let Verdict::Found { model, .. } = verdict {
            // An RPLIDAR at 256000 is an A2M12 (hardware ≥ 6).
            let model = if model == LidarModel::RplidarA1 && baud == 256_000 {
                LidarModel::RplidarA2
            } else {
                model
            };
            return Ok(Probe {
                path: path.to_owned(),
                attempts,
                found: Some((model, baud, port)),
            });
        }
        // Not this rate: stop an RPLIDAR that may have understood, before the next rate.
        let _ = crate::serial::run_on_close(&mut port, &cfg);
    }
    Ok(Probe {
        path: path.to_owned(),
        attempts,
        found: None,
    })
}
