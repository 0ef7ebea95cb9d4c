//! Method B's own work allocates nothing per frame, and tract's per-frame allocations are a
//! constant: a counting global allocator watches this thread while simulated revolutions are
//! encoded into the model's input, run through the compiled-in YOLOv8n and decoded.

use perception::raster::{RasterConfig, encode_chw_f32};
use perception::yolo::{ANCHORS, DecodeConfig, DecodeScratch, Detection, MAX_DETECTIONS, decode};
use sim::dataset::{DatasetConfig, simulate};
use umbra_tests::counted;

#[global_allocator]
static ALLOC: umbra_tests::Counting = umbra_tests::Counting;

#[test]
fn method_b_frames_allocate_nothing_outside_tract() {
    let cfg = DatasetConfig {
        scenarios: 1,
        frames: 20,
        seed: 5,
        ..DatasetConfig::default()
    };
    let mut revs = Vec::new();
    simulate(0, &cfg, |_, f, _| revs.push(f.ranges_m()), |_, _| {});
    let mut model = models::yolo::YoloModel::builtin(Default::default()).expect("model");
    let raster = RasterConfig::default();
    let mut scratch = Box::new(DecodeScratch::new());
    let mut dets: heapless::Vec<Detection, MAX_DETECTIONS> = heapless::Vec::new();
    // The counter counts.
    assert_eq!(counted(|| drop(std::hint::black_box(vec![0u8; 16]))), 1);
    let mut ours = 0;
    let mut tract = Vec::new();
    let mut found = 0;
    let mut output: Vec<f32> = Vec::with_capacity(perception::yolo::LOGITS_LEN);
    for (n, w) in revs.windows(3).enumerate() {
        ours += counted(|| {
            encode_chw_f32(model.input_mut(), [&w[2], &w[1], &w[0]], &raster).unwrap();
        });
        // tract's run, the output copied into a buffer sized before (no allocation of ours).
        let t = counted(|| {
            model
                .run(|o| {
                    output.clear();
                    output.extend_from_slice(o);
                })
                .unwrap()
        });
        // Warm-up: tract may size its session buffers on the first runs.
        if n >= 2 {
            tract.push(t);
        }
        ours += counted(|| {
            decode(
                &output,
                ANCHORS,
                &DecodeConfig::RUNTIME,
                &mut scratch,
                &mut dets,
            )
            .unwrap();
        });
        found += dets.len();
    }
    eprintln!("tract allocations per run: {tract:?}; ours: {ours}; detections: {found}");
    assert!(found > 0, "the model detects something in a furnished room");
    assert_eq!(ours, 0, "{ours} allocations in encoding and decoding");
    assert!(
        tract.windows(2).all(|w| w[0] == w[1]),
        "tract's per-run allocations vary: {tract:?}"
    );
}
