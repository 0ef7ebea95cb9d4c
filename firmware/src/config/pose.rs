//! The pose sources' sections of the file: `[odometry]` (the drive's constants), `[pose]`
//! (scan matching) and `[compass]` (its calibration).

use perception::pose::{HeadingConfig, OdometryConfig};
use serde::Deserialize;

/// `[odometry]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OdometrySettings {
    /// Wheel radius, m.
    pub wheel_radius_m: f32,
    /// Wheel separation, m.
    pub wheel_separation_m: f32,
    /// Encoder ticks per wheel turn.
    pub ticks_per_rev: f32,
}

impl Default for OdometrySettings {
    fn default() -> Self {
        let b = OdometryConfig::BURGER;
        OdometrySettings {
            wheel_radius_m: b.wheel_radius_m,
            wheel_separation_m: b.wheel_separation_m,
            ticks_per_rev: b.ticks_per_rev,
        }
    }
}

/// `[pose]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PoseSettings {
    /// Lay each revolution on a keyframe's (`perception::scan_match`, point-to-line ICP) and
    /// move the pose by what that finds, so that the map does not turn with wheel slip. On by
    /// default (`docs/pose.md` has the figures); `false` keeps the wheels' and compass's pose.
    pub scan_match: bool,
}

impl Default for PoseSettings {
    fn default() -> Self {
        PoseSettings { scan_match: true }
    }
}

/// `[compass]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CompassSettings {
    /// Hard-iron offset (x, y), µT; `None`: the compass is not used.
    pub hard_iron_ut: Option<[f32; 2]>,
    /// Clean-field reference from the calibration (horizontal strength, vertical reading), µT:
    /// readings that differ are disturbed and not used.
    pub field_reference_ut: Option<[f32; 2]>,
    /// Declination plus mount offset, degrees.
    pub offset_deg: f32,
    /// Accepted deviation of the horizontal field strength, fraction.
    pub field_tolerance: f32,
}

impl Default for CompassSettings {
    fn default() -> Self {
        CompassSettings {
            hard_iron_ut: None,
            field_reference_ut: None,
            offset_deg: 0.0,
            field_tolerance: HeadingConfig::default().field_tolerance,
        }
    }
}
