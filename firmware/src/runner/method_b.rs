//! Method B as a stage of the frame: the last three revolutions encoded as the 64 × 384 × 3
//! raster into the network's input, the network run, its boxes decoded and placed in the map
//! from the middle revolution's poses, the way the training labels were drawn (its middle's
//! pose, or with `deskew` where the sweep stood when it read each box's bearing).
//!
//! The network is behind the [`Network`] trait so that the loop builds the same with and
//! without tract (feature `method-b`: `models::yolo::YoloModel` implements it).

use perception::fusion::PlacedBox;
use perception::geometry::Pose2;
use perception::mirror_look::{FuseConfig, fuse_second_look, mirror_chw};
use perception::raster::{RasterConfig, SCAN_COLUMNS, encode_chw_f32};
use perception::seam::{Rolled, SeamRule, turned};
use perception::sweep::Sweep;
use perception::yolo::{ANCHORS, DecodeConfig, DecodeScratch, Detection, MAX_DETECTIONS, decode};

use super::history::RevolutionPose;

/// Method B's network: an input tensor to fill and a run that hands its output to a closure.
pub trait Network {
    /// The model's name, for messages.
    fn name(&self) -> &str;
    /// The `1 × 3 × 64 × 384` input floats.
    fn input_mut(&mut self) -> &mut [f32];
    /// Runs on the current input and calls `f` with the output floats (either form
    /// `perception::yolo::decode` reads); the error is
    /// a message naming the model.
    fn run_with(&mut self, f: &mut dyn FnMut(&[f32])) -> Result<(), String>;
}

#[cfg(feature = "method-b")]
impl Network for models::yolo::YoloModel {
    fn name(&self) -> &str {
        models::yolo::YoloModel::name(self)
    }
    fn input_mut(&mut self) -> &mut [f32] {
        models::yolo::YoloModel::input_mut(self)
    }
    fn run_with(&mut self, f: &mut dyn FnMut(&[f32])) -> Result<(), String> {
        self.run(f).map_err(|e| e.to_string())
    }
}

/// Where Method B runs (`[method_b] schedule`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Schedule {
    /// By the board (`docs/pi-budget.md`): on a Pi 3, live, its own thread; else inline.
    /// The frame loop reads an unresolved `Auto` as `Inline`.
    #[default]
    Auto,
    /// In the frame, after Method A, every frame the overrun policy allows.
    Inline,
    /// On a thread of its own (`b_worker.rs`): frames never wait for it; its boxes join the
    /// frame in which they arrive.
    Worker,
}

impl Schedule {
    /// `Auto` made concrete: its own thread on a board whose one core does not run the network
    /// inside a frame with margin (a Pi 3, projected 114–505 ms against 250), when frames come
    /// at the LiDAR's pace (`live`: a port, or a simulation or replay in real time); inline
    /// otherwise, so that a replay at full speed stays deterministic and a Pi 5 (17–34 ms)
    /// keeps Method B in every frame.
    pub fn resolve(self, board: crate::power::Board, live: bool) -> Schedule {
        use crate::power::Board;
        match self {
            Schedule::Auto => match board {
                Board::Pi3b | Board::Pi3bPlus if live => Schedule::Worker,
                _ => Schedule::Inline,
            },
            s => s,
        }
    }
}

/// Which compiled-in file Method B runs (`[method_b] precision`); a `--model` or `[method_b]
/// model` file is run whatever this says. fp32 by default on every board: int8 counts fewer
/// instructions only on a Pi 3 with a 64-bit OS (147 against 159 M a frame; a Pi 5 +4 %, a
/// Pi 3 on a 32-bit OS +52 %, `docs/pi-budget.md`), and through the world model it scores worse
/// (`docs/world.md`, 49th and 54th sessions).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// `umbra-yolov8n.onnx`.
    #[default]
    Fp32,
    /// `umbra-yolov8n-int8.onnx`: the same network fine-tuned through the int8 file's rounding
    /// (`training/qat.py`), within 0.01 mAP50-95 of fp32 (`models/README.md`).
    Int8,
}

/// Where the raster starts (`[method_b] seam`, `perception::seam`): it must be the rule the
/// model's training images were drawn with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Seam {
    /// Bin 0, the LiDAR's forward axis, in the first column.
    #[default]
    Fixed,
    /// The middle of the longest unbroken surface in the first column.
    Quiet,
}

impl From<SeamRule> for Seam {
    fn from(rule: SeamRule) -> Self {
        match rule {
            SeamRule::Fixed => Seam::Fixed,
            SeamRule::Quiet => Seam::Quiet,
        }
    }
}

impl Seam {
    /// The rule in `perception`'s terms.
    pub fn rule(self) -> SeamRule {
        match self {
            Seam::Fixed => SeamRule::Fixed,
            Seam::Quiet => SeamRule::Quiet,
        }
    }
}

/// Method B at run time: the loaded model and how to read its boxes.
pub struct MethodBSetup {
    /// The network, loaded and optimised at start-up.
    pub model: Box<dyn Network + Send>,
    /// Raster settings (must match the training data's).
    pub raster: RasterConfig,
    /// Thresholds and suppression.
    pub decode: DecodeConfig,
    /// The LiDAR's pose on the robot.
    pub mount: Pose2,
    /// Inline or on its own thread (resolved; `Auto` runs inline).
    pub schedule: Schedule,
    /// Inline: Method B in one frame of this many (frame numbers divisible by it); 1: every
    /// frame. A saving of power and CPU, not of any frame's time (the frames it runs in take
    /// as long as before).
    pub every: u32,
    /// A second look at the mirrored raster, fused with the first
    /// (`perception::mirror_look`): twice the network's time.
    pub mirror: bool,
    /// Where the raster starts.
    pub seam: Seam,
    /// Boxes read as the sweep read them (`perception::sweep`): for models trained on labels
    /// drawn that way (`umbra-sim dataset --deskew`); else from the pose at the revolution's
    /// middle.
    pub deskew: bool,
}

/// Method B's working memory, allocated once.
pub struct MethodBScratch {
    detections: heapless::Vec<Detection, MAX_DETECTIONS>,
    /// The mirrored look's boxes, then the fused ones (`mirror`).
    second: heapless::Vec<Detection, MAX_DETECTIONS>,
    fused: heapless::Vec<Detection, MAX_DETECTIONS>,
    decode: Box<DecodeScratch>,
}

impl Default for MethodBScratch {
    fn default() -> Self {
        MethodBScratch {
            detections: heapless::Vec::new(),
            second: heapless::Vec::new(),
            fused: heapless::Vec::new(),
            decode: Box::new(DecodeScratch::new()),
        }
    }
}

impl MethodBSetup {
    /// Runs on three revolutions (newest first) and calls `place` with each box in the map;
    /// `during` is the robot's poses during the previous revolution (the labels' revolution).
    /// `Err` carries the message of a failed frame.
    pub fn frame(
        &mut self,
        scans: [&[f32; SCAN_COLUMNS]; 3],
        during: RevolutionPose,
        scratch: &mut MethodBScratch,
        mut place: impl FnMut(PlacedBox),
    ) -> Result<(), String> {
        let seam = self.seam.rule().seam(scans, &self.raster);
        let rolled = scans.map(|scan| Rolled { scan, seam });
        encode_chw_f32(
            self.model.input_mut(),
            [&rolled[0], &rolled[1], &rolled[2]],
            &self.raster,
        )
        .map_err(|e| e.to_string())?;
        let fuse_cfg = FuseConfig::of(&self.decode);
        let cfg = if self.mirror {
            fuse_cfg.look_decode(&self.decode)
        } else {
            self.decode
        };
        look(
            self.model.as_mut(),
            &cfg,
            &mut scratch.decode,
            &mut scratch.detections,
        )?;
        if self.mirror {
            mirror_chw(self.model.input_mut()).map_err(|e| e.to_string())?;
            look(
                self.model.as_mut(),
                &cfg,
                &mut scratch.decode,
                &mut scratch.second,
            )?;
            let s = &mut *scratch;
            fuse_second_look(&mut s.detections, &mut s.second, &fuse_cfg, &mut s.fused);
        }
        // Column c is bearing c + seam; read from the pose at the middle of the revolution,
        // or (`deskew`) from where the sweep stood when it read that bearing.
        let lidar = turned(&during.middle().compose(&self.mount), seam);
        let sweep = Sweep {
            start: during.start,
            end: during.end,
            mount: self.mount,
        };
        for d in scratch.detections.iter() {
            let centre = if self.deskew {
                let (range, bearing) = d.polar(&self.raster);
                sweep.point(bearing.to_degrees() + seam as f32, range)
            } else {
                d.centre(&lidar, &self.raster)
            };
            let range = centre.distance(perception::geometry::Point2::new(lidar.x, lidar.y));
            place(PlacedBox {
                class: d.class,
                centre,
                score: d.score,
                bbox: [d.cx, d.cy, d.w, d.h],
                width_m: perception::fusion::width_across(d.w, range),
            });
        }
        Ok(())
    }
}

/// One run of the network on its current input, its boxes decoded into `dets`.
fn look(
    model: &mut (dyn Network + Send),
    cfg: &DecodeConfig,
    scratch: &mut DecodeScratch,
    dets: &mut heapless::Vec<Detection, MAX_DETECTIONS>,
) -> Result<(), String> {
    let mut decoded = None;
    model.run_with(&mut |out| {
        decoded = Some(decode(out, ANCHORS, cfg, scratch, dets));
    })?;
    match decoded {
        Some(Err(e)) => Err(e.to_string()),
        _ => Ok(()),
    }
}

/// The seam and box placement Method B draws with for the model `name`: `[method_b] seam` and
/// `deskew` where set, else what the file declares ([`follow_model`]); said once in the log.
pub fn drawing(
    name: &str,
    declared: models::conventions::Conventions,
    seam: Option<Seam>,
    deskew: Option<bool>,
) -> (Seam, bool) {
    let seam = follow_model("seam", seam, declared.seam.map(Seam::from), Seam::Fixed);
    let deskew = follow_model("deskew", deskew, declared.deskew, false);
    let placed = if deskew {
        "where the sweep read them"
    } else {
        "from the revolution's middle"
    };
    log::info!(
        "Method B reads {name}: seam {}, boxes placed {placed}",
        seam.rule().name()
    );
    (seam, deskew)
}

/// A drawing convention of Method B's (its seam, swept boxes): the configuration's when set,
/// else what the model file declares (`models::conventions`), else `default` (files that
/// declare nothing). A configuration that contradicts the file wins, with a warning: the
/// model then reads images drawn unlike its training's.
pub fn follow_model<T: PartialEq + core::fmt::Debug + Copy>(
    what: &str,
    configured: Option<T>,
    declared: Option<T>,
    default: T,
) -> T {
    match (configured, declared) {
        (Some(c), Some(d)) if c != d => {
            log::warn!(
                "[method_b] {what} = {c:?} overrides the model's own {d:?}: its images are then \
                 drawn unlike its training's"
            );
            c
        }
        (Some(c), _) => c,
        (None, Some(d)) => d,
        (None, None) => default,
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn the_model_file_decides_unless_the_configuration_does() {
        let q = Some(Seam::Quiet);
        assert_eq!(follow_model("seam", None, None, Seam::Fixed), Seam::Fixed);
        assert_eq!(follow_model("seam", None, q, Seam::Fixed), Seam::Quiet);
        assert_eq!(
            follow_model("seam", Some(Seam::Fixed), q, Seam::Fixed),
            Seam::Fixed
        );
        assert!(follow_model("deskew", Some(true), None, false));
        assert_eq!(Seam::from(SeamRule::Quiet).rule(), SeamRule::Quiet);
        assert_eq!(Seam::from(SeamRule::Fixed), Seam::Fixed);
    }
}
