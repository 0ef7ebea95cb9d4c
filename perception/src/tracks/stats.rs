//! The track table's counters: what it created, deleted, evicted, merged and refused.

#[cfg(doc)]
use super::TrackConfig;

/// Counters of the track table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackStats {
    /// Tracks created.
    pub created: u64,
    /// Tracks deleted (seen empty, or tentative and unseen).
    pub deleted: u64,
    /// Tracks evicted because the table was full.
    pub evicted: u64,
    /// Observations refused: a non-finite coordinate or score, or beyond
    /// [`TrackConfig::max_observation_m`].
    pub rejected: u64,
    /// Frames whose pose could not be used (non-finite).
    pub bad_poses: u64,
    /// Tracks merged into another of their class (one object seen twice).
    pub merged: u64,
}
