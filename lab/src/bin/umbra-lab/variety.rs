//! The simulator's variety as `umbra-lab forest-data` takes it: the shares of a varied world's
//! furniture styles and of the LiDAR units that read the scenes (each the `umbra-sim dataset`
//! flag of the same name, `docs/simulator.md`; 0 draws none), and how they set a scene.

use lab::scenes_a::SceneConfig;

/// Shares of the simulator's variety, 0–1 each (0: none, every scene as it always was).
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct Variety {
    /// Share of a varied world's chairs drawn as office chairs (`docs/world.md` says why none).
    #[arg(long, default_value_t = 0.0)]
    pub office_chairs: f64,
    /// Share of a varied world's desks drawn as round tables.
    #[arg(long, default_value_t = 0.0)]
    pub round_tables: f64,
    /// Share of a varied world's boxes drawn with sides of their own.
    #[arg(long, default_value_t = 0.0)]
    pub box_sizes: f64,
    /// Share of a varied world's boxes drawn dark.
    #[arg(long, default_value_t = 0.0)]
    pub dark_boxes: f64,
    /// Share of office chairs whose base's arms lie in the scan plane.
    #[arg(long, default_value_t = 0.0)]
    pub office_spokes: f64,
    /// Share of scenes seen by a worn LiDAR.
    #[arg(long, default_value_t = 0.0)]
    pub worn: f64,
    /// Share of scenes seen by a LiDAR that returns by received power.
    #[arg(long, default_value_t = 0.0)]
    pub power: f64,
}

impl Variety {
    /// Sets these shares in `cfg`.
    pub fn apply(&self, cfg: &mut SceneConfig) {
        cfg.world.office_chairs = self.office_chairs;
        cfg.world.round_tables = self.round_tables;
        cfg.world.box_sizes = self.box_sizes;
        cfg.world.dark_boxes = self.dark_boxes;
        cfg.world.office_spokes = self.office_spokes;
        cfg.worn = self.worn;
        cfg.power = self.power;
    }
}
