//! Where Method B's raster starts: the bearing its first column holds, chosen so that the
//! image's left and right edges (the 0°/360° seam, where a box cannot wrap) cut through a
//! plain wall rather than through furniture or a doorway.
//!
//! The raster's columns are bearings, and a 360° scan has no natural first column. With bin 0
//! first (the LiDAR's forward axis), an object straight ahead is cut in two: its label keeps
//! the larger part and the network learns to ignore the smaller one. On the simulator's
//! held-out images 8 % of the boxes touched that seam, and the shipped model found them at a
//! lower rate than the rest (0.83 against 0.93; `docs/method-b.md`).
//!
//! **The rule ([`quiet_seam`]):** a boundary between two neighbouring bins is *smooth* when,
//! in each of the three revolutions, both bins drew a pixel and their rows differ by at most
//! [`SMOOTH_ROWS`] (one continuous surface). The seam goes in the middle of the longest run of
//! smooth boundaries, that is, the middle of the longest stretch of unbroken wall. Furniture
//! and doorways break a surface at their sides, so they are not there. A scan smooth all
//! round, or with no smooth boundary, keeps bin 0 first.
//!
//! [`Rolled`] is a revolution seen from that start: bin `d` of it is bin `d + seam` of the
//! scan. The runtime and the simulator's labels both use it, so the image, its labels and the
//! boxes decoded from it agree: a box's column `c` is bearing `c + seam`, so the decoder's
//! LiDAR pose is turned by `seam` degrees ([`turned`]). `no_std`, allocation-free: one pass
//! over the bins.

use crate::geometry::Pose2;
use crate::raster::{RASTER_C, RasterConfig, SCAN_COLUMNS, ScanBins, row_for_range};

/// Two neighbouring bins are one surface when their rows differ by at most this (4 rows
/// ≈ 0.25 m at the default 4 m raster). Chosen on the training family's validation images
/// (`docs/method-b.md`): 1–2 rows call a wall seen at a grazing angle broken, 6 join a box to
/// the wall behind it.
pub const SMOOTH_ROWS: usize = 4;

/// How the raster's first column is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeamRule {
    /// Bin 0 (the LiDAR's forward axis) is the first column.
    #[default]
    Fixed,
    /// The first column is the middle of the longest unbroken surface ([`quiet_seam`]).
    Quiet,
}

impl SeamRule {
    /// The rule's name in configuration files, dataset manifests and model metadata.
    pub const fn name(self) -> &'static str {
        match self {
            SeamRule::Fixed => "fixed",
            SeamRule::Quiet => "quiet",
        }
    }

    /// The bin the first column holds for these revolutions, newest first.
    pub fn seam<S: ScanBins + ?Sized>(self, scans: [&S; RASTER_C], cfg: &RasterConfig) -> usize {
        match self {
            SeamRule::Fixed => 0,
            SeamRule::Quiet => quiet_seam(scans, cfg),
        }
    }
}

/// The row bin `d` of `scan` draws, if any.
fn row<S: ScanBins + ?Sized>(scan: &S, d: usize, cfg: &RasterConfig) -> Option<usize> {
    let (r, valid) = scan.bin(d % SCAN_COLUMNS);
    if valid { row_for_range(r, cfg) } else { None }
}

/// Whether the boundary between bins `b − 1` and `b` is smooth in every revolution.
fn smooth<S: ScanBins + ?Sized>(scans: &[&S; RASTER_C], b: usize, cfg: &RasterConfig) -> bool {
    let before = (b + SCAN_COLUMNS - 1) % SCAN_COLUMNS;
    scans
        .iter()
        .all(|s| match (row(*s, before, cfg), row(*s, b, cfg)) {
            (Some(a), Some(c)) => a.abs_diff(c) <= SMOOTH_ROWS,
            _ => false,
        })
}

/// The bin to put in the raster's first column: the middle of the longest run of smooth
/// boundaries (see the module docs), 0 when every boundary is smooth or none is. Ties go to
/// the run found first from bin 0, so the choice is deterministic.
pub fn quiet_seam<S: ScanBins + ?Sized>(scans: [&S; RASTER_C], cfg: &RasterConfig) -> usize {
    // Start the walk just after a broken boundary, so no run is split by the wrap.
    let Some(broken) = (0..SCAN_COLUMNS).find(|&b| !smooth(&scans, b, cfg)) else {
        return 0;
    };
    let (mut best_len, mut best_end, mut run) = (0usize, 0usize, 0usize);
    for i in 1..=SCAN_COLUMNS {
        let b = (broken + i) % SCAN_COLUMNS;
        if smooth(&scans, b, cfg) {
            run += 1;
            if run > best_len {
                (best_len, best_end) = (run, b);
            }
        } else {
            run = 0;
        }
    }
    if best_len == 0 {
        return 0;
    }
    (best_end + SCAN_COLUMNS - best_len / 2) % SCAN_COLUMNS
}

/// A revolution whose bin `d` is the scan's bin `d + seam`: the raster drawn from `seam` on.
#[derive(Debug, Clone, Copy)]
pub struct Rolled<'a, S: ?Sized> {
    /// The revolution.
    pub scan: &'a S,
    /// The bin that becomes bin 0.
    pub seam: usize,
}

impl<S: ScanBins + ?Sized> ScanBins for Rolled<'_, S> {
    fn bin(&self, d: usize) -> (f32, bool) {
        self.scan.bin((d + self.seam) % SCAN_COLUMNS)
    }
}

/// The LiDAR's pose turned so that its forward axis is bearing `seam`: the pose a raster
/// drawn from `seam` on is decoded with (column `c` is bearing `c + seam` of `lidar`).
pub fn turned(lidar: &Pose2, seam: usize) -> Pose2 {
    lidar.compose(&Pose2::new(0.0, 0.0, (seam as f32).to_radians()))
}

#[cfg(test)]
mod test {
    use super::*;

    /// A room seen from its middle: a wall 2 m off all round.
    fn wall() -> [f32; SCAN_COLUMNS] {
        [2.0; SCAN_COLUMNS]
    }

    #[test]
    fn a_smooth_room_and_an_empty_one_keep_bin_0() {
        let cfg = RasterConfig::default();
        let w = wall();
        assert_eq!(quiet_seam([&w, &w, &w], &cfg), 0);
        let none = [0.0f32; SCAN_COLUMNS];
        assert_eq!(quiet_seam([&none, &none, &none], &cfg), 0);
    }

    #[test]
    fn the_seam_goes_opposite_two_objects() {
        // Objects at bins 350..10 (across the old seam) and 170..190: the two stretches of wall
        // between them are 160 bins each, the first found from bin 0 is 10..170 → middle 90.
        let mut s = wall();
        for d in (350..360).chain(0..10).chain(170..190) {
            s[d] = 1.0;
        }
        let cfg = RasterConfig::default();
        let seam = quiet_seam([&s, &s, &s], &cfg);
        assert!((88..=92).contains(&seam), "{seam}");
        // Neither object is cut: every bin of each is on one side of the seam.
        for obj in [[350usize, 9], [170, 189]] {
            let col = |d: usize| (d + SCAN_COLUMNS - seam) % SCAN_COLUMNS;
            let (a, b) = (col(obj[0]), col(obj[1]));
            let span = (obj[1] + SCAN_COLUMNS - obj[0]) % SCAN_COLUMNS;
            assert_eq!((b + SCAN_COLUMNS - a) % SCAN_COLUMNS, span);
            assert!(a < b, "{obj:?} cut: columns {a}..{b}");
        }
    }

    #[test]
    fn every_revolution_must_be_smooth_there() {
        // The longest stretch in the newest revolution is broken in the oldest one.
        let cfg = RasterConfig::default();
        let mut newest = wall();
        newest[0] = 1.0;
        newest[200] = 1.0;
        let mut oldest = newest;
        oldest[100] = 1.0;
        // With the oldest: runs of 98, 98 and 158 boundaries (202..359): the last one's middle.
        let seam = quiet_seam([&newest, &newest, &oldest], &cfg);
        assert!((278..=282).contains(&seam), "{seam}");
        // Without it, 2..199 is the longest (198): its middle.
        let seam_newest_only = quiet_seam([&newest, &newest, &newest], &cfg);
        assert!((98..=102).contains(&seam_newest_only), "{seam_newest_only}");
    }

    #[test]
    fn a_missing_return_breaks_a_surface() {
        let cfg = RasterConfig::default();
        let mut s = wall();
        s[0] = 0.0;
        s[120] = 0.0;
        s[240] = 0.0;
        // Three runs of 119 boundaries; the first after bin 0: 1..120 → middle ≈ 60.
        let seam = quiet_seam([&s, &s, &s], &cfg);
        assert!((59..=62).contains(&seam), "{seam}");
    }

    #[test]
    fn rolled_bins_and_the_turned_pose_agree() {
        let mut s = wall();
        s[95] = 1.0;
        let r = Rolled { scan: &s, seam: 90 };
        assert_eq!(r.bin(5), (1.0, true));
        assert_eq!(r.bin(275), s.bin(5));
        // Column 5 of the rolled raster, bearing 5° from the turned pose, is bearing 95° of
        // the LiDAR: the same point.
        let lidar = Pose2::new(1.0, 2.0, 0.3);
        let p = turned(&lidar, 90)
            .transform(crate::geometry::Point2::from_polar(1.0, 5f32.to_radians()));
        let q = lidar.transform(crate::geometry::Point2::from_polar(1.0, 95f32.to_radians()));
        assert!(p.distance(q) < 1e-5, "{p:?} {q:?}");
    }

    #[test]
    fn fixed_is_bin_0() {
        let mut s = wall();
        s[0] = 1.0;
        let cfg = RasterConfig::default();
        assert_eq!(SeamRule::Fixed.seam([&s, &s, &s], &cfg), 0);
        assert_ne!(SeamRule::Quiet.seam([&s, &s, &s], &cfg), 0);
    }
}
