//! The last three revolutions' ranges by bin and the robot's poses at the first and last ray
//! of each: Method A reads the newest, Method B's raster all three, the recorder the newest.
//! Fixed size, allocated once.

use perception::geometry::Pose2;
use perception::raster::SCAN_COLUMNS;

/// The robot's map pose at a revolution's first and last ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RevolutionPose {
    /// At the first ray.
    pub start: Pose2,
    /// At the last ray.
    pub end: Pose2,
}

impl RevolutionPose {
    /// The poses at the first and the last ray.
    pub const fn new(start: Pose2, end: Pose2) -> Self {
        RevolutionPose { start, end }
    }

    /// A robot standing at `p` for the whole revolution.
    pub const fn still(p: Pose2) -> Self {
        RevolutionPose { start: p, end: p }
    }

    /// The pose at the middle of the revolution.
    pub fn middle(&self) -> Pose2 {
        self.start.midway(&self.end)
    }
}

/// Revolutions Method B's raster is made of.
pub const METHOD_B_HISTORY: usize = perception::raster::RASTER_C;

/// The ring of the last [`METHOD_B_HISTORY`] revolutions.
pub struct ScanHistory {
    /// Ranges by bin (0 = not drawn), slot `n % 3` for the n-th revolution.
    ranges: [[f32; SCAN_COLUMNS]; METHOD_B_HISTORY],
    /// The robot's map poses during each of those revolutions.
    poses: [RevolutionPose; METHOD_B_HISTORY],
    /// Revolutions put in so far.
    revolutions: u64,
}

impl Default for ScanHistory {
    fn default() -> Self {
        ScanHistory {
            ranges: [[0.0; SCAN_COLUMNS]; METHOD_B_HISTORY],
            poses: [RevolutionPose::still(Pose2::IDENTITY); METHOD_B_HISTORY],
            revolutions: 0,
        }
    }
}

impl ScanHistory {
    /// The slot the next revolution goes into; fill it with [`ScanHistory::next_mut`] and
    /// close it with [`ScanHistory::commit`].
    fn slot(&self) -> usize {
        (self.revolutions % METHOD_B_HISTORY as u64) as usize
    }

    /// The next revolution's ranges, to be written.
    pub fn next_mut(&mut self) -> &mut [f32; SCAN_COLUMNS] {
        let s = self.slot();
        &mut self.ranges[s]
    }

    /// The revolution being built (written by [`ScanHistory::next_mut`], not yet committed).
    pub fn pending(&self) -> &[f32; SCAN_COLUMNS] {
        &self.ranges[self.slot()]
    }

    /// Closes the pending revolution with the robot's poses during it.
    pub fn commit(&mut self, pose: RevolutionPose) {
        let s = self.slot();
        self.poses[s] = pose;
        self.revolutions += 1;
    }

    /// Revolutions committed so far.
    pub fn revolutions(&self) -> u64 {
        self.revolutions
    }

    /// The newest revolution's ranges (after a commit).
    pub fn newest(&self) -> &[f32; SCAN_COLUMNS] {
        &self.ranges[self.index(0)]
    }

    /// The three revolutions, newest first, and the robot's poses during the previous one
    /// (the revolution Method B's labels are drawn from). `None` before three are in.
    pub fn three(&self) -> Option<([&[f32; SCAN_COLUMNS]; 3], RevolutionPose)> {
        (self.revolutions >= METHOD_B_HISTORY as u64).then(|| {
            let (newest, prev, oldest) = (self.index(0), self.index(1), self.index(2));
            (
                [
                    &self.ranges[newest],
                    &self.ranges[prev],
                    &self.ranges[oldest],
                ],
                self.poses[prev],
            )
        })
    }

    /// The slot of the revolution `back` before the newest.
    fn index(&self, back: usize) -> usize {
        (self.revolutions as usize + METHOD_B_HISTORY - 1 - back) % METHOD_B_HISTORY
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn three_newest_first_with_the_middle_ones_pose() {
        let mut h = ScanHistory::default();
        for n in 0..5u8 {
            h.next_mut().fill(f32::from(n));
            h.commit(RevolutionPose::still(Pose2::new(f32::from(n), 0.0, 0.0)));
            if n < 2 {
                assert!(h.three().is_none());
            }
        }
        let (scans, pose) = h.three().unwrap();
        assert_eq!([scans[0][0], scans[1][0], scans[2][0]], [4.0, 3.0, 2.0]);
        assert_eq!(pose.middle().x, 3.0);
        assert_eq!(h.newest()[0], 4.0);
        assert_eq!(h.revolutions(), 5);
    }
}
