//! The human-readable line of a frame: what the robot sees — its pose, the objects by class
//! with their ids and places, the doors, the people walking by, and the frame's time. (The LiDAR's own statistics
//! are `--verbose`'s line.)

use core::fmt;

use perception::class::ObjectClass;

use crate::output::OutputLine;

/// `-0.0` (and a negative value that rounds to zero) printed as `0.00`, not `-0.00`.
fn z(v: f64) -> f64 {
    if v.abs() < 0.005 { 0.0 } else { v }
}

/// A frame's human-readable line.
pub struct SceneLine<'a>(pub &'a OutputLine<'a>);

impl fmt::Display for SceneLine<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let l = self.0;
        write!(
            f,
            "frame {:>6}  t {:>8.2} s  pose ({:.2}, {:.2}) {:>4.0}°  |",
            l.frame,
            l.t,
            z(l.pose.x),
            z(l.pose.y),
            l.pose.theta.to_degrees()
        )?;
        let mut any = false;
        for class in [ObjectClass::Chair, ObjectClass::Desk, ObjectClass::Box] {
            let mut first = true;
            for o in l.objects.iter().filter(|o| o.class == class) {
                if first {
                    write!(f, " {}", class.as_str())?;
                    first = false;
                } else {
                    f.write_str(",")?;
                }
                write!(f, " #{} ({:.1}, {:.1})", o.id, z(o.x), z(o.y))?;
                any = true;
            }
            if !first {
                f.write_str(" ")?;
            }
        }
        if !any {
            f.write_str(" no objects ")?;
        }
        f.write_str("| ")?;
        if l.doors.is_empty() {
            f.write_str("no doors")?;
        } else {
            write!(f, "door{}", if l.doors.len() == 1 { "" } else { "s" })?;
            for (k, d) in l.doors.iter().enumerate() {
                let sep = if k == 0 { " " } else { ", " };
                write!(f, "{sep}({:.1}, {:.1}) {:.2} m", z(d.x), z(d.y), d.width)?;
            }
        }
        if let Some(people) = l.people.filter(|p| !p.is_empty()) {
            f.write_str("  | walking:")?;
            for (k, p) in people.iter().enumerate() {
                let sep = if k == 0 { " " } else { ", " };
                let speed = p.vx.hypot(p.vy);
                write!(
                    f,
                    "{sep}#{} ({:.1}, {:.1}) {speed:.1} m/s",
                    p.id,
                    z(p.x),
                    z(p.y)
                )?;
            }
        }
        write!(f, "  | {:.1} ms", l.timing_ms.total)?;
        if l.deadline_missed {
            f.write_str(" MISSED")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::output::{DoorOut, FaultsOut, LidarOut, ObjectOut, PersonOut, PoseOut, TimingOut};
    use perception::fusion::Evidence;

    fn object(id: u32, class: ObjectClass, x: f64, y: f64) -> ObjectOut {
        ObjectOut {
            id,
            class,
            x,
            y,
            score: 0.9,
            source: Evidence::AB,
            bbox: None,
            hits: Some(5),
            last_seen: Some(7),
        }
    }

    fn line<'a>(objects: &'a [ObjectOut], doors: &'a [DoorOut]) -> OutputLine<'a> {
        OutputLine {
            frame: 7,
            t: 1.4,
            pose: PoseOut {
                x: 1.0,
                y: -0.5,
                theta: core::f64::consts::FRAC_PI_2,
            },
            objects,
            walls: &[],
            doors,
            detections: None,
            people: None,
            timing_ms: TimingOut {
                total: 14.2,
                ..TimingOut::default()
            },
            deadline_ms: 250.0,
            deadline_missed: false,
            degraded: false,
            power_w: None,
            power_source: "model",
            faults: FaultsOut::default(),
            lidar: LidarOut::default(),
        }
    }

    #[test]
    fn says_pose_objects_by_class_with_ids_doors_and_time() {
        let objects = [
            object(3, ObjectClass::Box, 2.0, 1.0),
            object(12, ObjectClass::Chair, -1.0, 0.5),
            object(4, ObjectClass::Chair, 0.3, 2.3),
            object(9, ObjectClass::DoorFrame, 4.0, 0.0),
        ];
        let doors = [DoorOut {
            x: 4.0,
            y: 0.0,
            width: 0.92,
            score: 0.8,
        }];
        let s = SceneLine(&line(&objects, &doors)).to_string();
        assert_eq!(
            s,
            "frame      7  t     1.40 s  pose (1.00, -0.50)   90°  | chair #12 (-1.0, 0.5), #4 (0.3, 2.3)  box #3 (2.0, 1.0) | door (4.0, 0.0) 0.92 m  | 14.2 ms"
        );
        let walker = [PersonOut {
            id: 20,
            x: 1.0,
            y: 2.0,
            vx: 0.6,
            vy: -0.8,
            score: 0.9,
        }];
        let mut l = line(&objects, &doors);
        l.people = Some(&walker);
        let s = SceneLine(&l).to_string();
        assert!(
            s.ends_with("0.92 m  | walking: #20 (1.0, 2.0) 1.0 m/s  | 14.2 ms"),
            "{s}"
        );
        let empty = SceneLine(&line(&[], &[])).to_string();
        assert!(
            empty.contains("| no objects | no doors  | 14.2 ms"),
            "{empty}"
        );
    }
}
