//! `umbra calibrate-compass`: the hard-iron offset from magnetometer readings taken while the
//! robot turns in place, by a least-squares circle fit (`perception::pose::HardIronFit`), and
//! writing it to the configuration.
//!
//! The readings must cover at least [`MIN_COVERAGE_DEG`] of heading around the fitted centre;
//! less is an error (a short arc fits a circle poorly). Readings come from a recording (the
//! `mag_ut` samples of an `--odom` JSON Lines file) or, with no input, from the simulated
//! robot's compass during a simulated two-turn spin.

use std::path::Path;

use perception::pose::{HardIron, HardIronFit};

use crate::cli::{CalibrateArgs, EXIT_FAULT, EXIT_USAGE, Failure};
use crate::odom::OdomRecord;
use crate::reader::open_compass;

/// Least heading coverage accepted, degrees.
pub const MIN_COVERAGE_DEG: f32 = 270.0;

/// A calibration result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    /// The fit.
    pub hard_iron: HardIron,
    /// Readings used.
    pub samples: usize,
    /// Heading coverage around the centre, degrees.
    pub coverage_deg: f32,
    /// Mean vertical reading (hard iron included), µT: with the fitted horizontal strength, the
    /// clean-field reference that screens disturbed readings.
    pub vertical_ut: f32,
}

/// Fits the readings `xy` (µT, x y z; the fit uses x and y).
pub fn fit(xy: &[[f32; 3]]) -> Result<Calibration, String> {
    let mut f = HardIronFit::default();
    for p in xy {
        f.add(p[0], p[1]);
    }
    let h = f.solve().ok_or_else(|| {
        format!(
            "{} readings do not span a circle: turn the robot in place",
            xy.len()
        )
    })?;
    let mut angles: Vec<f32> = xy
        .iter()
        .map(|p| {
            (p[1] - h.y_ut)
                .atan2(p[0] - h.x_ut)
                .to_degrees()
                .rem_euclid(360.0)
        })
        .collect();
    angles.sort_by(f32::total_cmp);
    let mut gap = angles
        .first()
        .map_or(360.0, |a0| a0 + 360.0 - angles[angles.len() - 1]);
    for w in angles.windows(2) {
        gap = gap.max(w[1] - w[0]);
    }
    let coverage_deg = 360.0 - gap;
    if coverage_deg < MIN_COVERAGE_DEG {
        return Err(format!(
            "readings cover {coverage_deg:.0}° of heading, at least {MIN_COVERAGE_DEG:.0}° needed: turn the robot a full turn in place"
        ));
    }
    Ok(Calibration {
        hard_iron: h,
        samples: xy.len(),
        coverage_deg,
        vertical_ut: xy.iter().map(|p| p[2]).sum::<f32>() / xy.len() as f32,
    })
}

/// The `mag_ut` readings of an odometry JSON Lines file (other lines skipped, bad ones counted).
pub fn readings_from_file(path: &Path) -> Result<(Vec<[f32; 3]>, usize), String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("--odom {}: cannot read: {e}", path.display()))?;
    let mut out = Vec::new();
    let mut bad = 0;
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        match serde_json::from_str::<OdomRecord>(line) {
            Ok(OdomRecord {
                mag_ut: Some(m), ..
            }) if m.iter().all(|v| v.is_finite()) => out.push(m),
            Ok(_) => {}
            Err(_) => bad += 1,
        }
    }
    Ok((out, bad))
}

/// Writes `hard_iron_ut` and `field_reference_ut` into the `[compass]` table of the TOML file
/// at `path` (created if absent; other settings kept, comments not).
pub fn write_config(path: &Path, c: &Calibration) -> Result<(), String> {
    let h = &c.hard_iron;
    let mut table: toml::Table = match std::fs::read_to_string(path) {
        Ok(text) => toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => toml::Table::new(),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let compass = table
        .entry("compass")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let Some(compass) = compass.as_table_mut() else {
        return Err(format!("{}: `compass` is not a table", path.display()));
    };
    let round = |v: f32| (f64::from(v) * 100.0).round() / 100.0;
    compass.insert(
        "hard_iron_ut".into(),
        toml::Value::Array(vec![
            toml::Value::Float(round(h.x_ut)),
            toml::Value::Float(round(h.y_ut)),
        ]),
    );
    compass.insert(
        "field_reference_ut".into(),
        toml::Value::Array(vec![
            toml::Value::Float(round(h.field_ut)),
            toml::Value::Float(round(c.vertical_ut)),
        ]),
    );
    let text = toml::to_string(&table).map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// `umbra calibrate-compass`: readings from a live compass (`--compass BUS`, turn the robot),
/// a recorded spin (`--odom`), or the simulated robot's two-turn spin; the fit printed and,
/// with `--write`, written into a configuration file.
pub fn command(args: &CalibrateArgs) -> Result<(), Failure> {
    let (xy, bad, source) = match (&args.odom, &args.compass) {
        (_, Some(bus)) => {
            let mut read = open_compass(bus).ok_or((
                EXIT_FAULT,
                format!("calibrate-compass: no compass on {bus}"),
            ))?;
            println!(
                "umbra: turn the robot slowly in place, at least one full turn, for {} s…",
                args.seconds
            );
            let mut xy = Vec::new();
            let mut bad = 0;
            let end = std::time::Instant::now() + std::time::Duration::from_secs_f64(args.seconds);
            while std::time::Instant::now() < end {
                match read() {
                    Ok(m) => xy.push(m),
                    Err(_) => bad += 1,
                }
                std::thread::sleep(std::time::Duration::from_millis(50));
            }
            (xy, bad, format!("{bus} (live, {} s)", args.seconds))
        }
        (Some(path), None) => {
            let (xy, bad) = readings_from_file(path).map_err(|m| (EXIT_USAGE, m))?;
            (xy, bad, path.display().to_string())
        }
        (None, None) => simulated_spin(args.seed)?,
    };
    let c = fit(&xy).map_err(|m| (EXIT_FAULT, format!("calibrate-compass: {m}")))?;
    println!(
        "umbra: compass calibration from {source}: {} readings ({bad} unreadable lines), {:.0}° covered; hard iron ({:.2}, {:.2}) µT, horizontal field {:.1} µT",
        c.samples, c.coverage_deg, c.hard_iron.x_ut, c.hard_iron.y_ut, c.hard_iron.field_ut
    );
    match &args.write {
        Some(path) => {
            write_config(path, &c).map_err(|m| (EXIT_FAULT, m))?;
            println!(
                "umbra: wrote [compass] hard_iron_ut and field_reference_ut to {}",
                path.display()
            );
        }
        None => println!(
            "[compass]\nhard_iron_ut = [{:.2}, {:.2}]\nfield_reference_ut = [{:.2}, {:.2}]",
            c.hard_iron.x_ut, c.hard_iron.y_ut, c.hard_iron.field_ut, c.vertical_ut
        ),
    }
    Ok(())
}

/// Compass readings of the simulated robot's two-turn spin, for `calibrate-compass` without a
/// source.
#[cfg(feature = "sim")]
fn simulated_spin(seed: u64) -> Result<(Vec<[f32; 3]>, usize, String), Failure> {
    let xy = sim::scenario::Scenario::new(seed, &sim::scenario::ScenarioConfig::standard())
        .compass_spin_readings();
    Ok((
        xy,
        0,
        format!("the simulated robot (seed {seed}), two turns in place"),
    ))
}

/// Built without the simulated robot: a source must be named.
#[cfg(not(feature = "sim"))]
fn simulated_spin(_seed: u64) -> Result<(Vec<[f32; 3]>, usize, String), Failure> {
    Err((
        EXIT_USAGE,
        "calibrate-compass: name --odom or --compass (this umbra was built without the simulated robot, feature sim)".into(),
    ))
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn full_turn_fits_half_turn_refused() {
        let circle = |from: f32, to: f32| -> Vec<[f32; 3]> {
            (0..100)
                .map(|i| {
                    let a = (from + (to - from) * i as f32 / 99.0).to_radians();
                    [8.0 + 20.0 * a.cos(), -5.0 + 20.0 * a.sin(), -40.0]
                })
                .collect()
        };
        let c = fit(&circle(0.0, 355.0)).unwrap();
        assert!((c.hard_iron.x_ut - 8.0).abs() < 1e-2 && (c.hard_iron.y_ut + 5.0).abs() < 1e-2);
        assert!(c.coverage_deg > 350.0);
        let err = fit(&circle(0.0, 180.0)).unwrap_err();
        assert!(err.contains("180°"), "{err}");
    }

    #[test]
    fn writes_into_existing_config() {
        let p = std::env::temp_dir().join(format!("umbra-cal-{}.toml", std::process::id()));
        std::fs::write(&p, "[lidar]\nchecksum = \"count\"\n").unwrap();
        let c = Calibration {
            hard_iron: HardIron {
                x_ut: 1.234,
                y_ut: -5.678,
                field_ut: 20.0,
            },
            samples: 100,
            coverage_deg: 360.0,
            vertical_ut: -41.26,
        };
        write_config(&p, &c).unwrap();
        let cfg = crate::config::Config::load(&p).unwrap();
        assert_eq!(cfg.compass.hard_iron_ut, Some([1.23, -5.68]));
        assert_eq!(cfg.compass.field_reference_ut, Some([20.0, -41.26]));
        assert_eq!(cfg.lidar.checksum, crate::config::ChecksumSetting::Count);
        let _ = std::fs::remove_file(p);
    }
}
