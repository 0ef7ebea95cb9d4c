//! Our odometry on real wheel-encoder ticks: the BreezySLAM / CoreSLAM logs in
//! `../shared/data/breezyslam/` (MinesRover: wheel radius 77 mm, track 330 mm, 2,000 ticks a
//! wheel turn; format in `../shared/data/README.md`). Skipped, with a reason, when the data is
//! absent.
//!
//! Plausibility: every step's speed and turn rate within what a wheeled indoor robot does,
//! a path length consistent with the log's duration, and the integrated path printed with its
//! start-to-end gap.

use perception::geometry::{Point2, Pose2};
use perception::pose::{OdometryConfig, TickCounter, integrate};

const MINES_ROVER: OdometryConfig = OdometryConfig {
    wheel_radius_m: 0.077,
    wheel_separation_m: 0.330,
    ticks_per_rev: 2000.0,
};

struct Summary {
    seconds: f64,
    length_m: f64,
    max_speed: f64,
    max_turn_rate: f64,
    net_turn_rad: f64,
    gap_m: f64,
}

fn integrate_log(text: &str) -> Summary {
    let mut ticks = TickCounter::default();
    let mut pose = Pose2::IDENTITY;
    let mut heading = 0.0f64; // unwrapped
    let (mut t0, mut last_t) = (None, 0.0f64);
    let (mut length, mut max_speed, mut max_turn) = (0.0f64, 0.0f64, 0.0f64);
    let (mut win_t, mut win_d, mut win_th) = (0.0f64, 0.0f64, 0.0f64);
    for line in text.lines() {
        let tok: Vec<&str> = line.split_whitespace().collect();
        assert!(tok.len() >= 4, "short line");
        let t = tok[0].parse::<f64>().unwrap() / 1e6;
        let left: i32 = tok[2].parse().unwrap();
        let right: i32 = tok[3].parse().unwrap();
        let step = ticks.step(left, right, &MINES_ROVER);
        if t0.is_none() {
            t0 = Some(t);
            win_t = t;
        }
        // Rates over windows of at least 0.5 s: the tick counters are not sampled at the
        // scan's time stamp, so a 5 ms gap can hold a longer stretch of ticks.
        win_d += f64::from(step.distance());
        win_th += f64::from(step.dtheta(&MINES_ROVER));
        if t - win_t >= 0.5 {
            max_speed = max_speed.max(win_d.abs() / (t - win_t));
            max_turn = max_turn.max(win_th.abs() / (t - win_t));
            (win_t, win_d, win_th) = (t, 0.0, 0.0);
        }
        last_t = t;
        let dth = step.dtheta(&MINES_ROVER);
        heading += f64::from(dth);
        length += f64::from(step.distance().abs());
        pose = integrate(&pose, step.distance(), dth);
    }
    Summary {
        seconds: last_t - t0.unwrap_or(last_t),
        length_m: length,
        max_speed,
        max_turn_rate: max_turn,
        net_turn_rad: heading,
        gap_m: f64::from(Point2::new(pose.x, pose.y).norm()),
    }
}

#[test]
fn breezyslam_wheel_ticks_give_a_plausible_path() {
    let Some(dir) = umbra_tests::shared_data().map(|d| d.join("breezyslam")) else {
        println!("skipping: ../shared/data not found beside the repository");
        return;
    };
    for name in ["exp1.dat", "exp2.dat"] {
        let path = dir.join(name);
        let Ok(text) = std::fs::read_to_string(&path) else {
            println!("skipping {}: not readable", path.display());
            continue;
        };
        let s = integrate_log(&text);
        println!(
            "{name}: {:.1} s, path {:.1} m (mean {:.2} m/s), max speed {:.2} m/s and max turn rate {:.2} rad/s over 0.5 s, net turn {:.1}°, start-to-end gap {:.2} m",
            s.seconds,
            s.length_m,
            s.length_m / s.seconds,
            s.max_speed,
            s.max_turn_rate,
            s.net_turn_rad.to_degrees(),
            s.gap_m
        );
        // README: exp1 lasts 74.6 s, exp2 63.2 s.
        assert!((60.0..80.0).contains(&s.seconds));
        // A wheeled rover: mean speed between a crawl and 1.5 m/s, never faster than 4 m/s or
        // turning faster than 3 rad/s over half a second. (exp2 holds a real 0.8 s stretch at
        // ~2.8 m/s of wheel travel, lines 170–177: a dash or wheel spin; the ticks say so.)
        let mean = s.length_m / s.seconds;
        assert!((0.1..1.5).contains(&mean), "mean speed {mean}");
        assert!(s.max_speed < 4.0, "max speed {}", s.max_speed);
        assert!(s.max_turn_rate < 3.0, "max turn rate {}", s.max_turn_rate);
        assert!(s.gap_m <= s.length_m);
    }
}
