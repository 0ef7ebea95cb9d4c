//! The settings a world is drawn from: its room kinds and how much of the wider variety
//! (`variety.rs`) it holds. Every share is 0 by default, so the worlds of every seed are the
//! ones they always were.

/// The room layouts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoomKind {
    /// A rectangle.
    Rect,
    /// A rectangle with a corner cut out.
    LShape,
    /// Two rectangles joined by a corridor.
    TwoRooms,
    /// A rectangle with a notch cut into the middle of one side (a U, or a room around an
    /// alcove of the building): two inner corners, each the end of a wall seen end-on from
    /// much of the room, as an L-shaped room's one is. For training Method B on inner corners
    /// while the L-shaped room stays its unseen kind (`models/README.md`).
    Notch,
}

impl RoomKind {
    /// Name used in file names and reports.
    pub fn name(self) -> &'static str {
        match self {
            RoomKind::Rect => "rect",
            RoomKind::LShape => "lshape",
            RoomKind::TwoRooms => "tworooms",
            RoomKind::Notch => "notch",
        }
    }
}

/// World generation settings.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldConfig {
    /// Layouts to draw from (uniformly).
    pub kinds: Vec<RoomKind>,
    /// Furniture per square metre of floor (then rounded, at least 2).
    pub furniture_density: f32,
    /// Chance that a single room gets a doorway.
    pub door_chance: f64,
    /// Clutter items: drawn uniformly from 0..=max.
    pub max_clutter: usize,
    /// Chance that a world is drawn *varied* ([`super::World::varied`], `variety.rs`): walls 0.05–0.25 m
    /// thick of any reflectivity, doorways from 0.75 m and up to corners, open door leaves,
    /// partition stubs, furniture against walls and chairs tucked at desks, shelves and square
    /// pillars, and a LiDAR whose reach and dropouts vary. 0 (the default) draws nothing extra,
    /// so the worlds of every seed are the ones they always were.
    pub varied: f64,
    /// Share of a varied world's chairs drawn as office chairs on a five-star base
    /// (`variety.rs`). 0 (the default) draws none and leaves every world as it was.
    pub office_chairs: f64,
    /// Share of a varied world's desks drawn as round tables on three or four legs
    /// (`variety.rs`). 0 (the default) draws none and leaves every world as it was.
    pub round_tables: f64,
    /// Share of a varied world's boxes drawn with sides of their own
    /// (`variety.rs`, `box_half`: storage and moving boxes, crates and low cabinets, 0.3–0.9 m
    /// long and 0.25–0.6 m deep, square ones too) instead of the study's 3 : 2 box. 0 (the
    /// default) draws none and leaves every world as it was.
    pub box_sizes: f64,
    /// Share of a varied world's boxes drawn dark (`variety.rs`, reflectivity 0.05–0.5: black
    /// and brown plastic crates, dark cardboard) instead of 0.55–0.9. 0 (the default) draws
    /// none and leaves every world as it was.
    pub dark_boxes: f64,
    /// Share of office chairs whose base's five arms lie in the scan plane, each seen whole from
    /// the hub to its caster (`variety.rs`: a LiDAR mounted at the hub's height, 0.1–0.15 m, as
    /// on robots lower than a TurtleBot3 Burger), instead of cut at one radius where they
    /// climb through it. 0 (the default) draws none and leaves every world as it was.
    pub office_spokes: f64,
}

impl Default for WorldConfig {
    fn default() -> Self {
        WorldConfig {
            kinds: vec![RoomKind::Rect, RoomKind::LShape, RoomKind::TwoRooms],
            furniture_density: 0.2,
            door_chance: 0.8,
            max_clutter: 3,
            varied: 0.0,
            office_chairs: 0.0,
            round_tables: 0.0,
            box_sizes: 0.0,
            dark_boxes: 0.0,
            office_spokes: 0.0,
        }
    }
}
