//! A track's belief: its most likely class and that class's share of the evidence, which
//! methods have seen it, and the footprint its class gives it.

use crate::class::ObjectClass;
use crate::fusion::Evidence;

use super::Track;

impl Track {
    /// The most likely class.
    pub fn class(&self) -> ObjectClass {
        let mut best = 0;
        for k in 1..4 {
            if self.class_evidence[k] > self.class_evidence[best] {
                best = k;
            }
        }
        ObjectClass::ALL[best]
    }

    /// The class's share of the evidence, in [0, 1].
    pub fn class_score(&self) -> f32 {
        let total: f32 = self.class_evidence.iter().sum();
        if total > 0.0 {
            self.class_evidence[self.class() as usize] / total
        } else {
            0.0
        }
    }

    /// Which methods have seen it.
    pub fn evidence(&self) -> Evidence {
        match (self.seen_a, self.seen_b) {
            (true, true) => Evidence::AB,
            (false, true) => Evidence::B,
            _ => Evidence::A,
        }
    }

    /// Radius of the footprint negative evidence looks across, m (a desk's legs span ~1.8 m).
    pub(super) fn radius(&self) -> f32 {
        class_radius(self.class())
    }
}

/// Footprint radius of a class, m.
pub(super) fn class_radius(c: ObjectClass) -> f32 {
    match c {
        ObjectClass::Chair => 0.3,
        ObjectClass::Box => 0.35,
        ObjectClass::Desk => 0.9,
        ObjectClass::DoorFrame => 0.5,
    }
}
