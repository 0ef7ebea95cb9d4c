//! Method B's network at run time: a YOLOv8n ONNX file run by `tract`.
//!
//! The model is parsed, checked and optimised **once** at start-up for the one concrete shape
//! it will see (`1 × 3 × 64 × 384` `f32` in; out either `1 × 68 × 504`, the head's box-side bins
//! and class logits that the shipped files give, or Ultralytics' decoded `1 × 8 × 504`: see
//! `perception::yolo::Head`), then run once per frame. The
//! input tensor is allocated once too: the raster is encoded straight into it
//! ([`YoloModel::input_mut`]) and handed to tract by reference count, so no frame copies or
//! allocates it. What tract allocates inside a run is its own business (constant per frame; a
//! test counts it).
//!
//! The file is compiled into the binary ([`BUILTIN_ONNX`]); `--model PATH` loads another. A
//! missing, corrupt or wrong-shaped file is a [`ModelError`] naming the file and what it found.
//! What the file declares about its training images (its seam, swept labels) is read from its
//! metadata at load ([`YoloModel::conventions`], [`crate::conventions`]).

use std::fmt;
use std::path::Path;
use std::sync::Arc;

use crate::conventions::Conventions;
use perception::raster::{RASTER_C, RASTER_H, RASTER_LEN, RASTER_W};
use perception::yolo::{ANCHORS, Head, LOGIT_ROWS, OUTPUT_ROWS};
use tract_onnx::prelude::*;
use tract_onnx::tract_core::internal::SimpleState;
use tract_onnx::tract_hir::infer::Factoid;

/// The production model, compiled in (fp32, see `models/README.md`).
pub static BUILTIN_ONNX: &[u8] = include_bytes!("../yolo/umbra-yolov8n.onnx");
/// The same model quantised (static int8, convolutions as `QLinearConv`).
pub static BUILTIN_INT8_ONNX: &[u8] = include_bytes!("../yolo/umbra-yolov8n-int8.onnx");
/// SHA-256 of [`BUILTIN_ONNX`] (hex), computed at build time.
pub const BUILTIN_SHA256: &str = env!("UMBRA_MODEL_SHA256");
/// SHA-256 of [`BUILTIN_INT8_ONNX`] (hex).
pub const BUILTIN_INT8_SHA256: &str = env!("UMBRA_MODEL_INT8_SHA256");
/// Name the compiled-in model goes by in messages.
pub const BUILTIN_NAME: &str = "<built-in umbra-yolov8n.onnx>";
/// Name the compiled-in int8 model goes by in messages.
pub const BUILTIN_INT8_NAME: &str = "<built-in umbra-yolov8n-int8.onnx>";

/// The input shape every model must accept.
pub const INPUT_SHAPE: [usize; 4] = [1, RASTER_C, RASTER_H, RASTER_W];
/// The output shape of a model exported by Ultralytics (boxes decoded in the graph).
pub const OUTPUT_SHAPE: [usize; 3] = [1, OUTPUT_ROWS, ANCHORS];
/// The output shape of a model cut before its box decoding (`training/logits_head.py`; the
/// shipped files).
pub const LOGITS_SHAPE: [usize; 3] = [1, LOGIT_ROWS, ANCHORS];

/// Why a model could not be loaded or run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelError {
    /// The file (or [`BUILTIN_NAME`]).
    pub file: String,
    /// What is wrong.
    pub kind: ModelErrorKind,
}

/// What is wrong with a model.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ModelErrorKind {
    /// The file could not be read.
    Io(String),
    /// The bytes are not an ONNX model tract can read.
    Parse(String),
    /// The model has not exactly one input and at least one output.
    Arity {
        /// Inputs found.
        inputs: usize,
        /// Outputs found.
        outputs: usize,
    },
    /// The input is not `1 × 3 × 64 × 384` `f32`.
    InputShape(String),
    /// The output is neither `1 × 68 × 504` nor `1 × 8 × 504`.
    OutputShape(String),
    /// tract could not type or optimise the graph.
    Optimise(String),
    /// The file's metadata declares a convention this runtime does not know
    /// ([`crate::conventions`]).
    Metadata(String),
    /// A run failed.
    Run(String),
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "model {}: ", self.file)?;
        match &self.kind {
            ModelErrorKind::Io(e) => write!(f, "cannot read it: {e}"),
            ModelErrorKind::Parse(e) => write!(f, "not a readable ONNX model: {e}"),
            ModelErrorKind::Arity { inputs, outputs } => write!(
                f,
                "has {inputs} inputs and {outputs} outputs, expected 1 input and 1 output"
            ),
            ModelErrorKind::InputShape(s) => {
                write!(f, "input is {s}, expected f32 {INPUT_SHAPE:?}")
            }
            ModelErrorKind::OutputShape(s) => {
                write!(
                    f,
                    "output is {s}, expected f32 {LOGITS_SHAPE:?} or {OUTPUT_SHAPE:?}"
                )
            }
            ModelErrorKind::Optimise(e) => write!(f, "cannot prepare it for {INPUT_SHAPE:?}: {e}"),
            ModelErrorKind::Metadata(e) => write!(f, "{e}"),
            ModelErrorKind::Run(e) => write!(f, "inference failed: {e}"),
        }
    }
}

impl std::error::Error for ModelError {}

/// How to run a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct YoloOptions {
    /// Worker threads for tract's matrix products (1 = run on the calling thread).
    pub threads: usize,
}

impl Default for YoloOptions {
    fn default() -> Self {
        YoloOptions { threads: 1 }
    }
}

type Plan = Arc<TypedRunnableModel>;

/// A loaded, optimised model with its input tensor.
pub struct YoloModel {
    name: String,
    head: Head,
    conventions: Conventions,
    state: TypedSimpleState,
    input: Arc<Tensor>,
    /// Frames whose input had to be reallocated because tract still held the last one.
    input_reallocations: u64,
}

impl fmt::Debug for YoloModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("YoloModel")
            .field("name", &self.name)
            .finish()
    }
}

/// The conventions in the ONNX `metadata_props` tract keeps as `onnx.metadata_props.KEY`.
fn declared_conventions(model: &InferenceModel) -> Result<Conventions, String> {
    const PREFIX: &str = "onnx.metadata_props.";
    let entries = model.properties.iter().filter_map(|(k, v)| {
        let key = k.strip_prefix(PREFIX)?;
        let value = v.try_as_plain_ram().ok()?.to_scalar::<String>().ok()?;
        Some((key, value.as_str()))
    });
    Conventions::from_metadata(entries).map_err(|e| e.to_string())
}

fn shape_of(fact: &InferenceFact) -> String {
    format!("{fact:?}")
}

impl YoloModel {
    /// The compiled-in production model.
    pub fn builtin(opts: YoloOptions) -> Result<Self, ModelError> {
        Self::from_bytes(BUILTIN_ONNX, BUILTIN_NAME, opts)
    }

    /// The compiled-in int8 model ([`BUILTIN_INT8_ONNX`]).
    pub fn builtin_int8(opts: YoloOptions) -> Result<Self, ModelError> {
        Self::from_bytes(BUILTIN_INT8_ONNX, BUILTIN_INT8_NAME, opts)
    }

    /// Loads `path`, or the compiled-in model when there is none.
    pub fn load_or_builtin(path: Option<&Path>, opts: YoloOptions) -> Result<Self, ModelError> {
        Self::load_or_builtin_as(path, false, opts)
    }

    /// Loads `path`, or when there is none the compiled-in model, its int8 form when `int8`.
    pub fn load_or_builtin_as(
        path: Option<&Path>,
        int8: bool,
        opts: YoloOptions,
    ) -> Result<Self, ModelError> {
        match path {
            Some(p) => Self::load(p, opts),
            None if int8 => Self::builtin_int8(opts),
            None => Self::builtin(opts),
        }
    }

    /// Loads a model file.
    pub fn load(path: &Path, opts: YoloOptions) -> Result<Self, ModelError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| ModelError {
            file: name.clone(),
            kind: ModelErrorKind::Io(e.to_string()),
        })?;
        Self::from_bytes(&bytes, &name, opts)
    }

    /// Parses, checks and optimises a model from its bytes; `name` is used in errors.
    pub fn from_bytes(bytes: &[u8], name: &str, opts: YoloOptions) -> Result<Self, ModelError> {
        let err = |kind| ModelError {
            file: name.to_string(),
            kind,
        };
        // Value infos are hints some exporters get wrong (the study's dynamic-quantised model
        // declares shapes its own graph contradicts); shapes are re-derived from the input.
        let model = tract_onnx::onnx()
            .with_ignore_value_info(true)
            .model_for_read(&mut std::io::Cursor::new(bytes))
            .map_err(|e| err(ModelErrorKind::Parse(format!("{e:#}"))))?;
        let conventions =
            declared_conventions(&model).map_err(|e| err(ModelErrorKind::Metadata(e)))?;
        let (inputs, outputs) = (model.inputs.len(), model.outputs.len());
        if inputs != 1 || outputs != 1 {
            return Err(err(ModelErrorKind::Arity { inputs, outputs }));
        }
        let declared = model
            .input_fact(0)
            .map_err(|e| err(ModelErrorKind::Parse(format!("{e:#}"))))?
            .clone();
        // A fully known input shape must be ours; symbolic dimensions are set to ours below.
        if let Some(dims) = declared.shape.as_concrete_finite().ok().flatten()
            && dims.as_slice() != INPUT_SHAPE
        {
            return Err(err(ModelErrorKind::InputShape(shape_of(&declared))));
        }
        if let Some(dt) = declared.datum_type.concretize()
            && dt != f32::datum_type()
        {
            return Err(err(ModelErrorKind::InputShape(shape_of(&declared))));
        }
        let typed = model
            .with_input_fact(0, f32::fact(INPUT_SHAPE).into())
            .and_then(|m| m.into_typed())
            .map_err(|e| err(ModelErrorKind::Optimise(format!("{e:#}"))))?;
        let out = typed
            .output_fact(0)
            .map_err(|e| err(ModelErrorKind::Optimise(format!("{e:#}"))))?;
        let head = match out.shape.as_concrete() {
            _ if out.datum_type != f32::datum_type() => None,
            Some(s) if s == OUTPUT_SHAPE => Some(Head::Boxes),
            Some(s) if s == LOGITS_SHAPE => Some(Head::Logits),
            _ => None,
        };
        let Some(head) = head else {
            return Err(err(ModelErrorKind::OutputShape(format!("{out:?}"))));
        };
        let mut options = RunOptions::default();
        if opts.threads > 1 {
            options.executor = Some(tract_linalg::multithread::Executor::multithread(
                opts.threads,
            ));
        }
        let plan: Plan = typed
            .into_optimized()
            .and_then(|m| m.into_runnable_with_options(&options))
            .map_err(|e| err(ModelErrorKind::Optimise(format!("{e:#}"))))?;
        let state =
            SimpleState::new(&plan).map_err(|e| err(ModelErrorKind::Optimise(format!("{e:#}"))))?;
        let input = Arc::new(
            Tensor::zero::<f32>(&INPUT_SHAPE)
                .map_err(|e| err(ModelErrorKind::Optimise(format!("{e:#}"))))?,
        );
        Ok(YoloModel {
            name: name.to_string(),
            head,
            conventions,
            state,
            input,
            input_reallocations: 0,
        })
    }

    /// The file the model came from.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// What the file declares about its training images ([`crate::conventions`]).
    pub fn conventions(&self) -> Conventions {
        self.conventions
    }

    /// Which form of output the model gives.
    pub fn head(&self) -> Head {
        self.head
    }

    /// The input tensor's `1 × 3 × 64 × 384` floats, to encode the raster into
    /// (`perception::raster::encode_chw_f32`).
    pub fn input_mut(&mut self) -> &mut [f32] {
        if Arc::get_mut(&mut self.input).is_none() {
            // tract kept a reference to the last input: start a fresh one (counted).
            self.input_reallocations += 1;
            self.input = Arc::new(Tensor::zero::<f32>(&INPUT_SHAPE).expect("fixed shape"));
        }
        let t = Arc::get_mut(&mut self.input).expect("just made exclusive");
        let s = t
            .to_plain_array_view_mut::<f32>()
            .ok()
            .and_then(|v| v.into_slice())
            .expect("a fresh plain f32 tensor");
        debug_assert_eq!(s.len(), RASTER_LEN);
        s
    }

    /// Runs the network on the current input; calls `f` with the output floats
    /// ([`Self::head`]`.rows()` × 504, what `perception::yolo::decode` reads).
    pub fn run<R>(&mut self, f: impl FnOnce(&[f32]) -> R) -> Result<R, ModelError> {
        let err = |e: TractError| ModelError {
            file: self.name.clone(),
            kind: ModelErrorKind::Run(format!("{e:#}")),
        };
        let outputs = self
            .state
            .run(tvec!(TValue::from_const(self.input.clone())))
            .map_err(err)?;
        let view = outputs[0].to_plain_array_view::<f32>().map_err(err)?;
        let out = view.as_slice().unwrap_or(&[]);
        if out.len() != self.head.rows() * ANCHORS {
            return Err(ModelError {
                file: self.name.clone(),
                kind: ModelErrorKind::OutputShape(format!("{:?}", outputs[0].shape())),
            });
        }
        Ok(f(out))
    }

    /// Frames whose input tensor had to be reallocated (0 in normal operation).
    pub fn input_reallocations(&self) -> u64 {
        self.input_reallocations
    }
}

#[cfg(test)]
mod test {
    #[test]
    fn the_version_names_the_compiled_in_models_by_their_hash() {
        use sha2::{Digest, Sha256};
        let hex = |b: &[u8]| -> String {
            Sha256::digest(b)
                .iter()
                .map(|x| format!("{x:02x}"))
                .collect()
        };
        assert_eq!(BUILTIN_SHA256, hex(BUILTIN_ONNX));
        assert_eq!(BUILTIN_INT8_SHA256, hex(BUILTIN_INT8_ONNX));
        assert_ne!(BUILTIN_SHA256, BUILTIN_INT8_SHA256);
    }

    use super::*;

    #[test]
    fn builtin_model_loads_and_runs() {
        let mut m = YoloModel::builtin(YoloOptions::default()).unwrap();
        m.input_mut().fill(0.0);
        let n = m.run(|o| o.len()).unwrap();
        assert_eq!(
            m.head(),
            Head::Logits,
            "the shipped file is cut before its DFL"
        );
        assert_eq!(n, perception::yolo::LOGITS_LEN);
        m.input_mut()[0] = 1.0;
        m.run(|_| ()).unwrap();
        assert_eq!(m.input_reallocations(), 0, "tract must give the input back");
    }

    #[test]
    fn quantised_model_loads() {
        let mut m = YoloModel::load_or_builtin_as(None, true, YoloOptions::default()).unwrap();
        assert_eq!(m.name(), BUILTIN_INT8_NAME);
        assert_eq!(
            m.conventions(),
            YoloModel::builtin(YoloOptions::default())
                .unwrap()
                .conventions(),
            "both compiled-in files declare how their images were drawn alike"
        );
        assert_eq!(m.head(), Head::Logits);
        m.run(|o| assert_eq!(o.len(), perception::yolo::LOGITS_LEN))
            .unwrap();
    }

    #[test]
    fn garbage_is_a_parse_error_naming_the_file() {
        let e = YoloModel::from_bytes(b"not an onnx file", "bad.onnx", YoloOptions::default())
            .unwrap_err();
        assert_eq!(e.file, "bad.onnx");
        assert!(matches!(e.kind, ModelErrorKind::Parse(_)), "{e}");
        assert!(e.to_string().starts_with("model bad.onnx: "), "{e}");
    }

    #[test]
    fn truncated_model_is_an_error() {
        let half = &BUILTIN_ONNX[..BUILTIN_ONNX.len() / 2];
        let e = YoloModel::from_bytes(half, "half.onnx", YoloOptions::default()).unwrap_err();
        assert!(matches!(e.kind, ModelErrorKind::Parse(_)), "{e}");
    }

    #[test]
    fn wrong_shapes_are_named() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("yolo/testdata");
        let e = YoloModel::load(&dir.join("wrong-input.onnx"), YoloOptions::default()).unwrap_err();
        assert!(matches!(e.kind, ModelErrorKind::InputShape(_)), "{e}");
        assert!(e.to_string().contains("640"), "{e}");
        let e =
            YoloModel::load(&dir.join("wrong-output.onnx"), YoloOptions::default()).unwrap_err();
        assert!(matches!(e.kind, ModelErrorKind::OutputShape(_)), "{e}");
        assert!(e.to_string().contains("wrong-output.onnx"), "{e}");
    }

    #[test]
    fn a_model_in_ultralytics_own_form_still_loads() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("yolo/testdata");
        let mut m = YoloModel::load(&dir.join("boxes-form.onnx"), YoloOptions::default()).unwrap();
        assert_eq!(m.head(), Head::Boxes);
        for (i, x) in m.input_mut().iter_mut().enumerate() {
            *x = i as f32;
        }
        let out = m.run(|o| o.to_vec()).unwrap();
        assert_eq!(out.len(), perception::yolo::OUTPUT_LEN);
        assert!(out.iter().enumerate().all(|(i, &x)| x == i as f32));
    }

    /// `bytes` with an ONNX `metadata_props` entry appended: field 14 of `ModelProto`, a
    /// `StringStringEntryProto` (key 1, value 2); protobuf merges a field appended to a
    /// message, so this is what an exporter's metadata reads as.
    fn with_metadata(bytes: &[u8], key: &str, value: &str) -> Vec<u8> {
        let field = |tag: u8, s: &str| {
            assert!(s.len() < 128, "one-byte lengths only");
            [&[tag, s.len() as u8][..], s.as_bytes()].concat()
        };
        let entry = [field(0x0a, key), field(0x12, value)].concat();
        [bytes, &[0x72, entry.len() as u8], &entry].concat()
    }

    #[test]
    fn the_file_declares_how_its_images_were_drawn() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("yolo/testdata/boxes-form.onnx");
        let plain = std::fs::read(path).unwrap();
        let load = |b: &[u8]| YoloModel::from_bytes(b, "m.onnx", YoloOptions::default());
        assert_eq!(load(&plain).unwrap().conventions(), Conventions::default());
        let declared = with_metadata(
            &with_metadata(&plain, "umbra.seam", "quiet"),
            "umbra.deskew",
            "true",
        );
        let c = load(&declared).unwrap().conventions();
        assert_eq!(c.seam, Some(perception::seam::SeamRule::Quiet));
        assert_eq!(c.deskew, Some(true));
        let e = load(&with_metadata(&plain, "umbra.seam", "emptiest")).unwrap_err();
        assert!(matches!(e.kind, ModelErrorKind::Metadata(_)), "{e}");
        assert!(e.to_string().contains("umbra.seam"), "{e}");
    }

    #[test]
    fn missing_file_is_an_io_error() {
        let e =
            YoloModel::load(Path::new("/nonexistent/m.onnx"), YoloOptions::default()).unwrap_err();
        assert!(matches!(e.kind, ModelErrorKind::Io(_)), "{e}");
        assert!(e.to_string().contains("/nonexistent/m.onnx"));
    }
}
