//! Method A, the geometric pipeline, end to end: cloud → adaptive DBSCAN → walls, segments,
//! corners → fragment merge → features → classifier → objects; door frames from the segments.
//!
//! [`MethodA`] owns every buffer the pipeline needs (about 430 kB, listed in
//! `memory-budget.md`); [`MethodA::run`] allocates nothing. The classifier is a parameter
//! ([`Classifier`]): the compiled-in forest lives in `models`, which depends on this crate.

use heapless::Vec;

use crate::class::ObjectClass;
use crate::cloud::{CloudConfig, GlobalCloud, Scan};
use crate::dbscan::{Dbscan, DbscanConfig, DbscanStats, MAX_CLUSTERS};
use crate::doors::{self, DoorConfig, Doors};
use crate::features::{self, FeatureFrame, N_FEATURES};
use crate::geometry::Point2;
use crate::merge::{self, Fragment, MergeConfig, MergeStats};
use crate::shape::{self, OrientedBox};
use crate::walls::{self, Corners, Segments, WallConfig, WallScratch};

/// Objects (merged groups) per frame at most: one per fragment.
pub const MAX_CANDIDATES: usize = MAX_CLUSTERS;

/// Every Method A setting.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MethodAConfig {
    /// Cloud aging and range window.
    pub cloud: CloudConfig,
    /// Clustering.
    pub dbscan: DbscanConfig,
    /// Walls, segments, corners.
    pub walls: WallConfig,
    /// Fragment merge.
    pub merge: MergeConfig,
    /// Door frames.
    pub doors: DoorConfig,
    /// Feature frame.
    pub frame: FeatureFrame,
}

/// A classifier of feature vectors.
pub trait Classifier {
    /// The class (`None`: none of the furniture classes) and its score in [0, 1].
    fn classify(&self, features: &[f32; N_FEATURES]) -> (Option<ObjectClass>, f32);
}

/// The classifier that recognises nothing: every candidate stays unclassified (for collecting
/// training data, where the labels come from elsewhere).
#[derive(Debug, Clone, Copy, Default)]
pub struct Unclassified;

impl Classifier for Unclassified {
    fn classify(&self, _: &[f32; N_FEATURES]) -> (Option<ObjectClass>, f32) {
        (None, 0.0)
    }
}

/// A merged group of fragments before classification.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Candidate {
    /// Minimum-area box of the points.
    pub bbox: OrientedBox,
    /// The object's estimated centre: the box centre, completed by the class's shape where
    /// only its near side was seen ([`complete_centre`]).
    pub centre: Point2,
    /// Feature vector.
    pub features: [f32; N_FEATURES],
    /// Points.
    pub points: u32,
    /// Fragments merged.
    pub fragments: u8,
    /// The classifier's answer.
    pub class: Option<ObjectClass>,
    /// Its score.
    pub score: f32,
}

/// What a frame's run did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MethodAStats {
    /// Clustering.
    pub dbscan: DbscanStats,
    /// Clusters that were walls.
    pub wall_clusters: u32,
    /// Fragments merged into candidates.
    pub fragments: u32,
    /// Merging.
    pub merge: MergeStats,
    /// Segments, corners or doors that did not fit their lists.
    pub over_capacity: u32,
}

/// The pipeline's state.
#[derive(Clone)]
pub struct MethodA {
    cloud: GlobalCloud,
    dbscan: Dbscan,
    wall_scratch: WallScratch,
    segments: Segments,
    corners: Corners,
    doors: Doors,
    frags: Vec<Fragment, MAX_CLUSTERS>,
    group: [u8; MAX_CLUSTERS],
    candidates: Vec<Candidate, MAX_CANDIDATES>,
    stats: MethodAStats,
}

impl core::fmt::Debug for MethodA {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("MethodA")
            .field("cloud", &self.cloud)
            .field("candidates", &self.candidates.len())
            .field("stats", &self.stats)
            .finish()
    }
}

impl Default for MethodA {
    fn default() -> Self {
        Self::new()
    }
}

impl MethodA {
    /// Empty state.
    pub fn new() -> Self {
        MethodA {
            cloud: GlobalCloud::new(),
            dbscan: Dbscan::new(),
            wall_scratch: WallScratch::new(),
            segments: Segments::new(),
            corners: Corners::new(),
            doors: Doors::new(),
            frags: Vec::new(),
            group: [0; MAX_CLUSTERS],
            candidates: Vec::new(),
            stats: MethodAStats::default(),
        }
    }

    /// The global cloud.
    pub fn cloud(&self) -> &GlobalCloud {
        &self.cloud
    }

    /// Adds one revolution to the cloud (after aging it).
    pub fn add_scan(&mut self, scan: &Scan<'_>, cfg: &MethodAConfig) -> usize {
        self.cloud.add_scan(scan, &cfg.cloud)
    }

    /// Forgets the cloud.
    pub fn reset(&mut self) {
        self.cloud.clear();
        self.candidates.clear();
        self.segments.clear();
        self.corners.clear();
        self.doors.clear();
    }

    /// Runs the pipeline on the current cloud, seen from `sensor` (the LiDAR's map position).
    pub fn run(&mut self, sensor: Point2, cfg: &MethodAConfig, classifier: &impl Classifier) {
        self.stats = MethodAStats::default();
        self.segments.clear();
        self.corners.clear();
        self.doors.clear();
        self.frags.clear();
        self.candidates.clear();

        self.dbscan.run(self.cloud.iter(), &cfg.dbscan);
        self.stats.dbscan = self.dbscan.stats();

        for k in 0..self.dbscan.clusters().len() {
            let pts = self.dbscan.cluster_points(k);
            let pb = shape::principal_box(&[pts]);
            if walls::is_wall(&pb, &cfg.walls) {
                self.stats.wall_clusters += 1;
                self.stats.over_capacity += walls::fit_segments(
                    pts,
                    sensor,
                    &cfg.walls,
                    &mut self.wall_scratch,
                    &mut self.segments,
                    &mut self.corners,
                );
            } else {
                let _ = self.frags.push(Fragment {
                    cluster: k as u16,
                    centroid: shape::centroid(&[pts]),
                    bbox: shape::min_area_box(&[pts]),
                });
            }
        }
        self.stats.fragments = self.frags.len() as u32;

        let n_groups = merge::merge(
            &self.frags,
            &cfg.merge,
            &mut self.group,
            &mut self.stats.merge,
        );
        for g in 0..n_groups {
            let mut parts: [&[Point2]; MAX_CLUSTERS] = [&[]; MAX_CLUSTERS];
            let mut np = 0;
            let mut last = 0;
            for (i, (f, &gi)) in self.frags.iter().zip(self.group.iter()).enumerate() {
                if gi as usize == g {
                    parts[np] = self.dbscan.cluster_points(f.cluster as usize);
                    np += 1;
                    last = i;
                }
            }
            let parts = &parts[..np];
            // A lone fragment's box was computed for the merge already.
            let bbox = if np == 1 {
                self.frags[last].bbox
            } else {
                shape::min_area_box(parts)
            };
            let angle = match cfg.frame {
                FeatureFrame::Object => bbox.angle,
                FeatureFrame::Axis => 0.0,
            };
            let f = features::features(parts, angle);
            let (class, score) = classifier.classify(&f);
            let centre = class.map_or(bbox.centre, |c| complete_centre(c, &bbox, sensor));
            let _ = self.candidates.push(Candidate {
                bbox,
                centre,
                features: f,
                points: shape::count(parts) as u32,
                fragments: np as u8,
                class,
                score,
            });
        }

        let cloud = &self.cloud;
        self.stats.over_capacity += doors::find(
            &self.segments,
            sensor,
            || cloud.iter(),
            &cfg.doors,
            &mut self.doors,
        );
    }

    /// Every merged group of the last run, classified or not.
    pub fn candidates(&self) -> &[Candidate] {
        &self.candidates
    }

    /// The recognised furniture of the last run.
    pub fn objects(&self) -> impl Iterator<Item = (ObjectClass, &Candidate)> + '_ {
        self.candidates
            .iter()
            .filter_map(|c| c.class.map(|k| (k, c)))
    }

    /// The points of candidate `i`'s fragments (for labelling training data).
    pub fn candidate_points(&self, i: usize) -> impl Iterator<Item = &Point2> + '_ {
        self.frags
            .iter()
            .zip(self.group.iter())
            .filter(move |(_, g)| **g as usize == i)
            .flat_map(move |(f, _)| self.dbscan.cluster_points(f.cluster as usize).iter())
    }

    /// Wall segments of the last run.
    pub fn segments(&self) -> &[walls::Segment] {
        &self.segments
    }

    /// Corners of the last run.
    pub fn corners(&self) -> &[Point2] {
        &self.corners
    }

    /// Door frames of the last run.
    pub fn doors(&self) -> &[doors::Door] {
        &self.doors
    }

    /// Statistics of the last run.
    pub fn stats(&self) -> MethodAStats {
        self.stats
    }
}

/// The centre of an object of class `class` whose points span `bbox`, seen from `sensor`.
///
/// A LiDAR sees the near side of things: one face of a box, the two front legs of a desk. The
/// class's proportions give the depth `D` the object should have across its long side `l`;
/// when the points span less (`w < D`), the centre moves `(D − w) / 2` away from the sensor,
/// perpendicular to the long side:
///
/// | class | `D` |
/// |---|---|
/// | chair (legs on a square) | `l` |
/// | desk (legs on a 2:1 rectangle) | `l / 2` if two sides are seen (`w ≥ 0.3 m`) or `l ≥ 1.1 m` (a long side); else `2 l` (a short side) |
/// | box (solid, 3:2) | `l / 1.5` if two faces are seen (`w ≥ 0.15 m`) or `l ≥ 0.48 m` (a long face); else `1.5 l` |
///
/// A lone leg (`l < 0.15 m`) has no direction to complete in: its box centre stands.
pub fn complete_centre(class: ObjectClass, bbox: &OrientedBox, sensor: Point2) -> Point2 {
    let (l, w) = (bbox.length, bbox.width);
    if l < 0.15 {
        return bbox.centre;
    }
    let depth = match class {
        ObjectClass::Chair => l,
        ObjectClass::Desk => {
            if w >= 0.3 || l >= 1.1 {
                l / 2.0
            } else {
                2.0 * l
            }
        }
        ObjectClass::Box => {
            if w >= 0.15 || l >= 0.48 {
                l / 1.5
            } else {
                1.5 * l
            }
        }
        ObjectClass::DoorFrame => return bbox.centre,
    };
    let shift = ((depth - w) / 2.0).max(0.0);
    let (s, c) = (libm::sinf(bbox.angle), libm::cosf(bbox.angle));
    let mut n = Point2::new(-s, c);
    let away = bbox.centre - sensor;
    if n.x * away.x + n.y * away.y < 0.0 {
        n = Point2::new(-n.x, -n.y);
    }
    Point2::new(bbox.centre.x + n.x * shift, bbox.centre.y + n.y * shift)
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::geometry::Pose2;

    /// Calls everything a chair, score 1.
    struct AllChairs;
    impl Classifier for AllChairs {
        fn classify(&self, _: &[f32; N_FEATURES]) -> (Option<ObjectClass>, f32) {
            (Some(ObjectClass::Chair), 1.0)
        }
    }

    #[test]
    fn room_with_a_chair() {
        let mut m = MethodA::new();
        let cfg = MethodAConfig::default();
        // The robot turns slowly in place so that every ray lands somewhere new.
        for k in 0..40 {
            let th = k as f32 * 0.013;
            let scan = Scan {
                ranges: &scan_room_at(th),
                start: Pose2::new(0.0, 0.0, th),
                end: Pose2::new(0.0, 0.0, th),
                mount: Pose2::IDENTITY,
            };
            m.add_scan(&scan, &cfg);
        }
        m.run(Point2::default(), &cfg, &AllChairs);
        assert!(m.stats().wall_clusters >= 1, "{:?}", m.stats());
        assert!(m.segments().len() >= 4, "{:?}", m.segments());
        let objs: std::vec::Vec<_> = m.objects().collect();
        assert_eq!(objs.len(), 1, "{:?}", m.candidates());
        assert!(
            objs[0].1.bbox.centre.distance(Point2::new(1.0, 0.5)) < 0.05,
            "{:?}",
            objs[0]
        );
        assert!(m.doors().is_empty());
    }

    fn scan_room_at(th: f32) -> [f32; 360] {
        let mut r = [0.0f32; 360];
        let world = scan_room_fine();
        for (d, out) in r.iter_mut().enumerate() {
            let a = (d as f32).to_radians() + th;
            let idx = (libm::roundf(a.to_degrees() * 10.0) as i64).rem_euclid(3600) as usize;
            *out = world[idx];
        }
        r
    }

    /// A square room 4 × 4 m around the origin with a chair (legs r = 2 cm) at (1, 0.5).
    fn scan_room_fine() -> std::vec::Vec<f32> {
        (0..3600)
            .map(|k| {
                let a = (k as f32 / 10.0).to_radians();
                let (c, s) = (libm::cosf(a), libm::sinf(a));
                let mut best = f32::MAX;
                for t in [2.0 / c.abs(), 2.0 / s.abs()] {
                    if t.is_finite() && t < best {
                        best = t;
                    }
                }
                for (lx, ly) in [(0.8f32, 0.3f32), (1.2, 0.3), (1.2, 0.7), (0.8, 0.7)] {
                    let b = lx * c + ly * s;
                    let disc = b * b - (lx * lx + ly * ly - 0.02f32 * 0.02);
                    if disc >= 0.0 {
                        let t = b - libm::sqrtf(disc);
                        if t > 0.0 && t < best {
                            best = t;
                        }
                    }
                }
                if best <= 3.5 { best } else { 0.0 }
            })
            .collect()
    }

    #[test]
    fn centre_completion_moves_away_from_the_sensor() {
        // Front face of a 0.6 × 0.4 box seen from below: the centre is 0.2 m further up.
        let face = OrientedBox {
            centre: Point2::new(0.0, 1.0),
            angle: 0.0,
            length: 0.6,
            width: 0.01,
        };
        let c = complete_centre(ObjectClass::Box, &face, Point2::new(0.0, 0.0));
        assert!(c.distance(Point2::new(0.0, 1.195)) < 1e-4, "{c:?}");
        let c = complete_centre(ObjectClass::Box, &face, Point2::new(0.0, 3.0));
        assert!(c.distance(Point2::new(0.0, 0.805)) < 1e-4, "{c:?}");
        // Two front legs of a desk 1.6 m apart: depth 0.8 m.
        let legs = OrientedBox {
            length: 1.6,
            width: 0.05,
            ..face
        };
        let c = complete_centre(ObjectClass::Desk, &legs, Point2::new(0.0, 0.0));
        assert!(c.distance(Point2::new(0.0, 1.375)) < 1e-4, "{c:?}");
        // Two sides seen, or one leg: unchanged.
        let full = OrientedBox { width: 0.4, ..face };
        let part = OrientedBox { width: 0.3, ..face };
        let c = complete_centre(ObjectClass::Box, &part, Point2::new(0.0, 0.0));
        assert!(c.distance(Point2::new(0.0, 1.05)) < 1e-4, "{c:?}");
        assert_eq!(
            complete_centre(ObjectClass::Box, &full, Point2::default()),
            full.centre
        );
        let leg = OrientedBox {
            length: 0.05,
            width: 0.04,
            ..face
        };
        assert_eq!(
            complete_centre(ObjectClass::Chair, &leg, Point2::default()),
            leg.centre
        );
    }

    #[test]
    fn empty_and_degenerate_clouds() {
        let mut m = MethodA::new();
        let cfg = MethodAConfig::default();
        m.run(Point2::default(), &cfg, &AllChairs);
        assert!(m.candidates().is_empty() && m.segments().is_empty());
        for _ in 0..30 {
            m.add_scan(
                &Scan {
                    ranges: &[1.0; 1],
                    start: Pose2::IDENTITY,
                    end: Pose2::IDENTITY,
                    mount: Pose2::IDENTITY,
                },
                &cfg,
            );
        }
        m.run(Point2::default(), &cfg, &AllChairs);
        assert_eq!(m.candidates().len(), 1);
    }
}
