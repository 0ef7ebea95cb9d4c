//! The object classes umbra recognises, with the names the output line uses
//! (`docs/interfaces.md` §3).

use core::fmt;

/// An object class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ObjectClass {
    /// A chair (four thin legs at LiDAR height).
    Chair,
    /// A box (a solid rectangle).
    Box,
    /// A desk (four legs, wider).
    Desk,
    /// A door frame (two jambs with a gap).
    DoorFrame,
}

impl ObjectClass {
    /// All classes, in model output order.
    pub const ALL: [ObjectClass; 4] = [
        ObjectClass::Chair,
        ObjectClass::Box,
        ObjectClass::Desk,
        ObjectClass::DoorFrame,
    ];

    /// The name in the output line.
    pub const fn as_str(self) -> &'static str {
        match self {
            ObjectClass::Chair => "chair",
            ObjectClass::Box => "box",
            ObjectClass::Desk => "desk",
            ObjectClass::DoorFrame => "door_frame",
        }
    }

    /// Parses an output-line name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.as_str() == name)
    }
}

impl fmt::Display for ObjectClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn names_round_trip() {
        for c in ObjectClass::ALL {
            assert_eq!(ObjectClass::from_name(c.as_str()), Some(c));
        }
        assert_eq!(ObjectClass::from_name("table"), None);
        assert_eq!(ObjectClass::DoorFrame.as_str(), "door_frame");
    }
}
