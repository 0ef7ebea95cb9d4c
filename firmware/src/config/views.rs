//! What each part of the runtime gets from the configuration: the deadline's stage budgets,
//! the pose filter and the drive's odometry constants, Method A's and Method B's settings, the
//! LiDAR's window and mount, the OpenCR link. One conversion each.

use drivers::lds01::{AssemblerConfig, ChecksumPolicy, Lds01Config};
use drivers::opencr::OpencrConfig;
use perception::method_a::MethodAConfig;
use perception::pose::{HeadingConfig, OdometryConfig, PoseFilter};

use super::{ChecksumSetting, Config};

impl Config {
    /// The drive's odometry constants (`[odometry]`).
    pub fn odometry(&self) -> OdometryConfig {
        let o = &self.odometry;
        OdometryConfig {
            wheel_radius_m: o.wheel_radius_m,
            wheel_separation_m: o.wheel_separation_m,
            ticks_per_rev: o.ticks_per_rev,
        }
    }

    /// The deadline and the stage budgets, unset ones as their share of the deadline.
    pub fn budgets(&self) -> crate::deadline::Budgets {
        let d = self.runtime.deadline_ms;
        let b = &self.runtime.budget_ms;
        crate::deadline::Budgets {
            deadline_ms: d,
            ingest_ms: b.ingest.unwrap_or(d * 0.04),
            pose_ms: b.pose.unwrap_or(d * 0.08),
            method_a_ms: b.method_a.unwrap_or(d * 0.26),
            method_b_ms: b.method_b.unwrap_or(d * 0.56),
            output_ms: b.output.unwrap_or(d * 0.06),
        }
    }

    /// A pose filter with these settings; a calibration given (hard iron, field reference)
    /// overrides the file's.
    pub fn pose_filter(&self, calibration: Option<([f32; 2], [f32; 2])>) -> PoseFilter {
        let hard_iron = calibration.map(|c| c.0);
        let odo = self.odometry();
        let heading = HeadingConfig {
            offset_rad: self.compass.offset_deg.to_radians(),
            field_tolerance: self.compass.field_tolerance,
            ..HeadingConfig::default()
        };
        let hi = hard_iron.or(self.compass.hard_iron_ut).unwrap_or([0.0; 2]);
        let mut f = PoseFilter::new(odo, heading, (hi[0], hi[1]));
        if let Some(r) = calibration.map(|c| c.1).or(self.compass.field_reference_ut) {
            f.set_field_reference(r[0], r[1]);
        }
        f
    }

    /// Method B's decoding settings.
    pub fn method_b_decode(&self) -> perception::yolo::DecodeConfig {
        let b = &self.method_b;
        perception::yolo::DecodeConfig {
            conf: b.conf,
            iou: b.iou,
            agnostic: b.agnostic_nms,
            ..perception::yolo::DecodeConfig::RUNTIME
        }
    }

    /// Method B's raster settings.
    pub fn method_b_raster(&self) -> perception::raster::RasterConfig {
        perception::raster::RasterConfig {
            max_range_m: self.method_b.max_range_m,
        }
    }

    /// The Method A pipeline settings (its range window is the LiDAR's).
    pub fn method_a(&self) -> MethodAConfig {
        let a = &self.method_a;
        let mut c = MethodAConfig::default();
        c.cloud.drop_fraction = a.drop_fraction;
        c.cloud.clear_margin_m = a.clear_margin_m;
        c.cloud.clear_beyond_rays = a.clear_beyond_rays;
        c.cloud.range_min_m = self.lidar.min_range_m;
        c.cloud.range_max_m = self.lidar.max_range_m;
        c.dbscan.eps_min_m = a.eps_min_m;
        c.dbscan.eps_max_m = a.eps_max_m;
        c.dbscan.min_samples = a.min_samples;
        c.dbscan.min_cluster_points = a.min_cluster_points;
        c.merge.link_m = a.merge_link_m;
        c.walls.wall_area_m2 = a.wall_area_m2;
        c.walls.wall_aspect = a.wall_aspect;
        c.walls.corner_min_deg = a.corner_min_deg;
        c.doors.max_angle_deg = a.door_max_angle_deg;
        c.doors.min_gap_m = a.door_min_gap_m;
        c.doors.max_gap_m = a.door_max_gap_m;
        c
    }

    /// The LiDAR's pose on the robot.
    pub fn lidar_mount(&self) -> perception::geometry::Pose2 {
        perception::geometry::Pose2::new(
            self.method_a.lidar_mount_x_m,
            self.method_a.lidar_mount_y_m,
            0.0,
        )
    }

    /// The OpenCR reader settings.
    pub fn opencr(&self) -> OpencrConfig {
        OpencrConfig {
            id: self.opencr.id,
            left_addr: self.opencr.left_addr,
            right_addr: self.opencr.right_addr,
            timeout: std::time::Duration::from_millis(self.opencr.timeout_ms),
        }
    }

    /// The LiDAR stream settings, the same for every model: the `[lidar]` range window is the
    /// pipeline's working range (which Method A's thresholds and Method B's training data
    /// assume), and the checksum policy only concerns the LDS-01.
    pub fn lidar(&self) -> drivers::lidar::LidarConfig {
        let l = self.lds01();
        drivers::lidar::LidarConfig {
            min_range_m: Some(l.assembler.min_range_m),
            max_range_m: Some(l.assembler.max_range_m),
            stale_after_us: l.assembler.stale_after_us,
            lds01_checksum: l.checksum,
        }
    }

    /// The LDS-01 driver settings.
    pub fn lds01(&self) -> Lds01Config {
        Lds01Config {
            checksum: match self.lidar.checksum {
                ChecksumSetting::Verify => ChecksumPolicy::Verify,
                ChecksumSetting::Count => ChecksumPolicy::Count,
            },
            assembler: AssemblerConfig {
                min_range_m: self.lidar.min_range_m,
                max_range_m: self.lidar.max_range_m,
                stale_after_us: self.lidar.stale_after_ms * 1000,
            },
        }
    }
}
