//! The scan matcher (`perception::scan_match`) on real laser scans: the Intel Research Lab and
//! Freiburg 079 CARMEN logs of `../shared/data/carmen` (SICK LMS, 180°; their poses corrected
//! by a GMapping-style matcher, `../shared/data/README.md` §1). The logs have no raw odometry,
//! so the wheels are made from the corrected poses: each step between two scans, as is
//! ("clean") or with the error of slipping wheels ("slipping": every turn 4 % too large and
//! every distance 2 % too short, the kind of error that turns a map). The matcher is given
//! the scans and those poses as `umbra` gives it a revolution and the odometry's pose, and
//! its pose is scored against the corrected one: the heading error and the position error of
//! each scan relative to the scan `WINDOW` scans before it (relative pose error: the
//! corrected logs are locally accurate; their global frame comes from loop closures no local
//! matcher has). Skipped, with the reason printed, when the shared data is absent.

use std::path::{Path, PathBuf};

use drivers::lidar::points::bin_of;
use firmware::carmen;

use perception::cloud::Scan;
use perception::geometry::{Pose2, wrap_angle};
use perception::scan_match::{BINS, MatchOutcome, MatchStats, ScanMatchConfig, ScanMatcher};

/// Scans between the two poses of a relative error.
const WINDOW: usize = 20;

fn shared_log(name: &str) -> Option<PathBuf> {
    let p = umbra_tests::shared_data()
        .map(|d| d.join("carmen").join(name))
        .filter(|p| p.is_file());
    if p.is_none() {
        println!("skipped: ../shared/data/carmen/{name} is absent beside the repository");
    }
    p
}

/// One scan: ranges binned by degree as the runtime bins them (`firmware::carmen`'s parsing,
/// `drivers`' bins: the closest return wins a bin), and the corrected pose.
struct LogScan {
    ranges: Vec<f32>,
    pose: Pose2,
}

fn read_log(log: &Path) -> Vec<LogScan> {
    let text = carmen::read_log(log).unwrap();
    let mut beams = Vec::new();
    String::from_utf8_lossy(&text)
        .lines()
        .filter_map(|l| {
            let mut tok = l.split_ascii_whitespace();
            if tok.next() != Some("FLASER") {
                return None;
            }
            let ((x, y, theta), _stamp) = carmen::parse_flaser(&mut tok, &mut beams)
                .expect("every FLASER line of the log parses");
            let mut ranges = vec![0.0f32; BINS];
            for (k, &r) in beams.iter().enumerate() {
                let r = carmen::beam_range_m(r);
                let bin = bin_of(carmen::beam_bearing_deg(k, beams.len()));
                if r > 0.0 && (ranges[bin] == 0.0 || r < ranges[bin]) {
                    ranges[bin] = r;
                }
            }
            Some(LogScan {
                ranges,
                pose: Pose2::new(x as f32, y as f32, theta as f32),
            })
        })
        .collect()
}

/// The wheels' step from `a` to `b`, with `turn_gain` on its rotation and `distance_gain` on
/// its translation.
fn odometry_step(a: &Pose2, b: &Pose2, turn_gain: f32, distance_gain: f32) -> Pose2 {
    let d = a.inverse().compose(b);
    Pose2::new(
        d.x * distance_gain,
        d.y * distance_gain,
        wrap_angle(d.theta) * turn_gain,
    )
}

/// Relative pose errors over `WINDOW` scans: (mean heading error, deg; mean position error, m).
fn relative_errors(est: &[Pose2], truth: &[LogScan]) -> (f64, f64) {
    let (mut th, mut pos, mut n) = (0.0f64, 0.0f64, 0usize);
    for k in WINDOW..est.len() {
        let e = est[k - WINDOW].inverse().compose(&est[k]);
        let t = truth[k - WINDOW].pose.inverse().compose(&truth[k].pose);
        let err = t.inverse().compose(&e);
        th += f64::from(wrap_angle(err.theta).abs().to_degrees());
        pos += f64::from(err.x.hypot(err.y));
        n += 1;
    }
    (th / n.max(1) as f64, pos / n.max(1) as f64)
}

struct Run {
    /// Relative errors of the odometry alone, and with the matcher.
    odometry: (f64, f64),
    matched: (f64, f64),
    /// The matcher's counts.
    stats: MatchStats,
}

/// The matcher over a log; `reach_m`: the farthest return it uses (the LiDAR's reach).
fn run(scans: &[LogScan], mount: Pose2, turn_gain: f32, distance_gain: f32, reach_m: f32) -> Run {
    let mut m = ScanMatcher::new(ScanMatchConfig {
        max_range_m: reach_m,
        ..ScanMatchConfig::default()
    });
    let (mut odo, mut est) = (scans[0].pose, scans[0].pose);
    let (mut odo_poses, mut est_poses) = (Vec::new(), Vec::new());
    for (k, s) in scans.iter().enumerate() {
        if k > 0 {
            let step = odometry_step(&scans[k - 1].pose, &s.pose, turn_gain, distance_gain);
            odo = odo.compose(&step);
            est = est.compose(&step);
        }
        // A SICK scan takes 13 ms: the pose barely moves during it (no de-skew, as the replay).
        let scan = Scan {
            ranges: &s.ranges,
            start: est,
            end: est,
            mount,
        };
        if let MatchOutcome::Matched { correction, .. } = m.update(&scan) {
            est = correction.compose(&est);
        }
        odo_poses.push(odo);
        est_poses.push(est);
    }
    Run {
        odometry: relative_errors(&odo_poses, scans),
        matched: relative_errors(&est_poses, scans),
        stats: m.stats(),
    }
}

fn check(name: &str, mount_x_m: f32) {
    let Some(log) = shared_log(name) else {
        return;
    };
    let scans = read_log(&log);
    let mount = Pose2::new(mount_x_m, 0.0, 0.0);
    let mut runs = Vec::new();
    // An LDS-01's reach (3.5 m), and an 8 m one (an LDS-02's, as `umbra` ties the matcher's
    // reach to `[lidar] max_range_m`).
    for (label, turn_gain, distance_gain, reach_m) in [
        ("clean", 1.0, 1.0, 3.5),
        ("slipping", 1.04, 0.98, 3.5),
        ("slipping", 1.04, 0.98, 8.0),
    ] {
        let r = run(&scans, mount, turn_gain, distance_gain, reach_m);
        println!(
            "{name}, {label} wheels, reach {reach_m} m, {} scans: matched {}, refused {} (few pairs, residual, too far, corridor: {:?}), keyframes {}; error over {WINDOW} scans: heading {:.2}° -> {:.2}°, position {:.3} m -> {:.3} m",
            scans.len(),
            r.stats.matched,
            r.stats.refused.iter().sum::<u32>(),
            r.stats.refused,
            r.stats.keyframes,
            r.odometry.0,
            r.matched.0,
            r.odometry.1,
            r.matched.1,
        );
        runs.push(r);
    }
    let (clean, slipping, far) = (&runs[0], &runs[1], &runs[2]);
    // Most scans match (the rest are refused: too few returns within the 3.5 m the matcher
    // uses, or a corridor).
    assert!(
        clean.stats.matched * 10 >= scans.len() as u32 * 7,
        "matched {} of {}",
        clean.stats.matched,
        scans.len()
    );
    // Slipping wheels: the scans take most of the heading error out.
    assert!(
        slipping.matched.0 <= 0.6 * slipping.odometry.0,
        "heading {:.2}° matched, {:.2}° wheels",
        slipping.matched.0,
        slipping.odometry.0
    );
    // The farther returns a longer-reaching LiDAR gives help rather than hurt.
    assert!(
        far.matched.0 <= slipping.matched.0 && far.stats.matched >= slipping.stats.matched,
        "reach 8 m: {:.2}°, {} matched; 3.5 m: {:.2}°, {} matched",
        far.matched.0,
        far.stats.matched,
        slipping.matched.0,
        slipping.stats.matched
    );
    // Clean wheels (the corrected poses themselves): what the matcher adds is bounded — a
    // fraction of a degree a match, not a drift that grows with the tour.
    assert!(
        clean.matched.0 < 2.0 && clean.matched.1 < 0.2,
        "clean wheels matched: {:.2}°, {:.3} m",
        clean.matched.0,
        clean.matched.1
    );
}

#[test]
fn intel_lab_scans_pull_slipping_wheels_back() {
    check("intel-corrected.log.gz", 0.0);
}

#[test]
fn freiburg_079_scans_pull_slipping_wheels_back() {
    check("freiburg-079-corrected.log.gz", -0.04);
}
