//! The fused heading against odometry alone and the study's compass overwrite, on the simulator
//! with wheel slip and compass disturbances (shortened runs; `umbra-lab pose-eval` runs the
//! 10-minute table).

use lab::pose_eval::{markdown, table};

#[test]
fn fusion_beats_odometry_and_compass_overwrite_in_every_scenario() {
    let rows = table(1, 3, 180.0);
    println!("{}", markdown(&rows));
    for r in &rows {
        assert!(
            r.fusion.heading_rms_deg < r.odometry.heading_rms_deg
                && r.fusion.heading_rms_deg < r.overwrite.heading_rms_deg,
            "scenario {} {}: fusion {:.2}° vs odometry {:.2}°, overwrite {:.2}°",
            r.scenario,
            r.motion,
            r.fusion.heading_rms_deg,
            r.odometry.heading_rms_deg,
            r.overwrite.heading_rms_deg
        );
        assert!(
            r.hard_iron_error_ut < 0.5,
            "hard-iron fit off by {} µT",
            r.hard_iron_error_ut
        );
    }
}
