//! Method A allocates nothing per frame: a counting global allocator watches this thread while
//! simulated revolutions go through the cloud update, DBSCAN, walls, doors, merge, features and
//! the compiled-in forest.

use perception::cloud::Scan;
use perception::geometry::{Point2, Pose2};
use perception::method_a::{MethodA, MethodAConfig};
use sim::lds01::LIDAR_MOUNT;
use sim::scenario::{Frame, Scenario, ScenarioConfig};
use umbra_tests::counted;

#[global_allocator]
static ALLOC: umbra_tests::Counting = umbra_tests::Counting;

#[test]
fn method_a_frames_allocate_nothing() {
    // Simulate first (the simulator allocates; that is not the frame loop).
    let mut scenario = Scenario::new(7, &ScenarioConfig::standard());
    let start = scenario.robot_start_pose().inverse();
    let mut frame = Box::<Frame>::default();
    let mut odom = Vec::new();
    let revs: Vec<([f32; 360], Pose2, Pose2)> = (0..60)
        .map(|_| {
            scenario.next_frame(&mut frame, &mut odom);
            (
                frame.ranges_m(),
                start.compose(&frame.pose_start),
                start.compose(&frame.pose_end),
            )
        })
        .collect();
    let cfg = MethodAConfig::default();
    let forest = models::forest::forest();
    let mut m = Box::new(MethodA::new());
    // Warm-up: fills the cloud.
    let step = |m: &mut MethodA, (r, a, b): &([f32; 360], Pose2, Pose2)| {
        m.add_scan(
            &Scan {
                ranges: r,
                start: *a,
                end: *b,
                mount: LIDAR_MOUNT,
            },
            &cfg,
        );
        let s = b.compose(&LIDAR_MOUNT);
        m.run(Point2::new(s.x, s.y), &cfg, forest);
    };
    for r in &revs[..30] {
        step(&mut m, r);
    }
    // The counter counts: one allocation while watching is seen.
    assert_eq!(counted(|| drop(std::hint::black_box(vec![0u8; 16]))), 1);
    let n = counted(|| {
        for r in &revs[30..] {
            step(&mut m, r);
        }
    });
    assert!(m.cloud().len() > 5_000, "cloud {}", m.cloud().len());
    assert!(!m.segments().is_empty());
    assert!(m.objects().count() > 0, "{:?}", m.candidates());
    assert_eq!(n, 0, "{n} allocations in 30 Method A frames");
}
