//! A track's likelihood: the mean probability of its observations
//! ([`crate::calibration`]), and the rule that holds back furniture seen only in the ways the
//! methods are mostly wrong.

use crate::class::ObjectClass;

use super::{Track, TrackConfig};

impl Track {
    /// The mean probability of its observations (0 before the first): how often the
    /// methods' detections like these stood on a piece of their class.
    pub fn likelihood(&self) -> f32 {
        if self.hits == 0 {
            0.0
        } else {
            self.p_sum / self.hits as f32
        }
    }

    /// A piece of furniture whose observations were, on the whole, the kind that is wrong more
    /// often than [`TrackConfig::min_likelihood`] allows (desks: or
    /// [`TrackConfig::min_desk_likelihood`]): not reported while so. Door frames are judged by
    /// the map's walls instead ([`Track::door_at_wall_end`]).
    pub fn unlikely(&self, cfg: &TrackConfig) -> bool {
        let least = match self.class() {
            ObjectClass::DoorFrame => return false,
            ObjectClass::Desk => cfg.min_likelihood.max(cfg.min_desk_likelihood),
            _ => cfg.min_likelihood,
        };
        self.likelihood() < least
    }
}
