"""Checks of the training setup that need Ultralytics (not run in CI: run them with the training
environment, `.venv/bin/python training/test_training.py DATASET/data.yaml`).

* shuffling: Ultralytics turns DataLoader shuffling off for `rect=True` when the batch shapes
  differ; ours are all 64 x 384, so it must stay on — two epochs of the trainer's own
  dataloader must see the images in different orders, every batch exactly 64 x 384.
* the logits head: the shipped checkpoint exported with Ultralytics' full head, and the same
  graph cut by `logits_head.py` with the DFL, anchors and sigmoid done in numpy as
  `perception::yolo::decode` does them, give the same 1 x 8 x 504 on real rasters.
* quantisation-aware training (`qat.py`): the shipped checkpoint with its convolutions
  fake-quantised on N calibration images must compute what onnxruntime's int8 export,
  calibrated on the same N images, computes — far closer to it than the float model is (the
  rest is the integer accumulators' rounding, about one output step), with weights rounded
  per tensor and per output channel alike.
* the ranges a quantisation-aware run trained through (`qat_ranges.py`): kept in a
  checkpoint, they must land on every convolution's input and output tensors of the exported
  graph, and the int8 file made on them must compute what the fake quantisation computes even
  when the images it is calibrated on would give other ranges.
* the drawing conventions (`export.declare`): a file declares its seam and swept labels once
  each, as the runtime reads them (`models/src/conventions.rs`), and a dataset's manifest
  gives them (`export.conventions_of`).
* the report model's fit (`fit_report_model.py`): a track-frame off every piece is a phantom,
  one on a piece while it stands there is not, door frames are left out; the weights written
  for raw features give the probabilities of the standardised fit.
"""

import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

import offline  # noqa: F401  (must come before ultralytics)
from exact import ExactTrainer
from train import HERE, OFF


def epoch_orders(data: Path, epochs: int = 2, batch: int = 8) -> list[list[str]]:
    t = ExactTrainer(overrides=dict(
        model=str(HERE / "yolov8n-umbra.yaml"), data=str(data), imgsz=384, rect=True, epochs=2,
        batch=batch, workers=0, device="cpu", seed=0, deterministic=True, pretrained=False,
        plots=False, project="/tmp/umbra-test-training", name="t", exist_ok=True, **OFF))
    t.data = t.get_dataset()
    t.model = t.get_model(cfg=str(HERE / "yolov8n-umbra.yaml"), verbose=False)
    dl = t.get_dataloader(t.data["train"], batch_size=batch, rank=-1, mode="train")
    n = len(dl.dataset)
    orders = []
    for _ in range(epochs):
        files: list[str] = []
        for b in dl:
            assert tuple(b["img"].shape[2:]) == (64, 384), b["img"].shape
            files += [Path(p).name for p in b["im_file"]]
            if len(files) >= n:
                break
        orders.append(files)
    return orders


def test_shuffled(data: Path) -> None:
    a, b = epoch_orders(data)
    assert sorted(a) == sorted(b), "an epoch must see every image once"
    assert a != b, "two epochs saw the same order: the training dataloader is not shuffled"
    print(f"shuffled: epoch 1 starts {a[:3]}, epoch 2 starts {b[:3]}")


def decode_logits(lg: np.ndarray) -> np.ndarray:
    """A 1 x 68 x 504 logits head as Ultralytics' 1 x 8 x 504 (what the Rust decoder computes)."""
    a = lg.shape[2]
    bins = lg[0, :64].reshape(4, 16, a)
    e = np.exp(bins - bins.max(1, keepdims=True))
    side = (e / e.sum(1, keepdims=True) * np.arange(16)[None, :, None]).sum(1)
    pts, strides = [], []
    for s, h, w in [(8, 8, 48), (16, 4, 24), (32, 2, 12)]:
        ys, xs = np.meshgrid(np.arange(h) + 0.5, np.arange(w) + 0.5, indexing="ij")
        pts.append(np.stack([xs.ravel(), ys.ravel()]))
        strides.append(np.full(h * w, s))
    p, st = np.concatenate(pts, 1), np.concatenate(strides)
    lo, hi = p - side[:2], p + side[2:]
    boxes = np.concatenate([(lo + hi) / 2, hi - lo]) * st
    return np.concatenate([boxes, 1 / (1 + np.exp(-lg[0, 64:]))])[None]


def test_logits_head(data: Path) -> None:
    import onnxruntime as ort

    import logits_head
    from export import png_tensor, ultralytics_onnx

    tmp = Path(tempfile.mkdtemp())
    # Ultralytics writes the export beside the weights: export a copy, not the shipped file.
    shutil.copy(HERE.parent / "models/yolo/umbra-yolov8n.pt", tmp / "full.pt")
    full = ultralytics_onnx(tmp / "full.pt")
    logits_head.cut(full, tmp / "cut.onnx")
    run = {k: ort.InferenceSession(str(f), providers=["CPUExecutionProvider"])
           for k, f in (("full", full), ("cut", tmp / "cut.onnx"))}
    images = sorted((data.parent / "images" / "test").glob("*.png"))[:20]
    worst = 0.0
    for f in images:
        x = {"images": png_tensor(f)}
        want = run["full"].run(None, x)[0]
        got = decode_logits(run["cut"].run(None, x)[0])
        worst = max(worst, float(np.abs(want - got).max()))
    assert worst < 1e-3, f"cut head differs by {worst} px"
    print(f"logits head: {len(images)} images, largest difference {worst:.2e}")


def test_qat_emulates_int8(data: Path, calib: int = 32, per_channel: bool = False) -> None:
    import onnxruntime as ort
    import torch
    from ultralytics import YOLO

    import logits_head
    import qat
    from export import png_tensor, quantise, ultralytics_onnx

    tmp = Path(tempfile.mkdtemp())
    shutil.copy(HERE.parent / "models/yolo/umbra-yolov8n.pt", tmp / "m.pt")
    f32 = tmp / "m.onnx"
    logits_head.cut(ultralytics_onnx(tmp / "m.pt"), f32)
    folder = data.parent / "images" / "train"
    quantise(f32, tmp / "m8.onnx", folder, calib, per_channel)
    model = YOLO(str(tmp / "m.pt")).model.float().eval()
    n = qat.prepare(model, qat.calibration_tensors(folder, calib), per_channel)
    run = {k: ort.InferenceSession(str(f), providers=["CPUExecutionProvider"])
           for k, f in (("fp32", f32), ("int8", tmp / "m8.onnx"))}
    emulated_off, float_off = [], []
    for f in sorted((data.parent / "images" / "test").glob("*.png"))[:10]:
        x = png_tensor(f)
        with torch.no_grad():
            d = model(torch.from_numpy(x))[1]
        emu = torch.cat([d["boxes"], d["scores"]], 1).numpy()
        int8 = run["int8"].run(None, {"images": x})[0]
        emulated_off.append(float(np.abs(emu - int8).mean()))
        float_off.append(float(np.abs(run["fp32"].run(None, {"images": x})[0] - int8).mean()))
    e, fl = float(np.mean(emulated_off)), float(np.mean(float_off))
    assert n > 60, f"only {n} convolutions fake-quantised"
    assert e < 0.35 * fl, f"emulation off int8 by {e:.3f}, float by {fl:.3f}"
    form = "per channel" if per_channel else "per tensor"
    print(f"qat ({form}): {n} convolutions; mean |emulated - int8| {e:.3f}, "
          f"|float - int8| {fl:.3f}")


def test_qat_ranges_carried(data: Path, calib: int = 32) -> None:
    import onnx
    import onnxruntime as ort
    import torch
    from ultralytics import YOLO

    import logits_head
    import qat
    import qat_ranges
    from export import png_tensor, quantise, ultralytics_onnx

    tmp = Path(tempfile.mkdtemp())
    shutil.copy(HERE.parent / "models/yolo/umbra-yolov8n.pt", tmp / "m.pt")
    f32 = tmp / "m.onnx"
    logits_head.cut(ultralytics_onnx(tmp / "m.pt"), f32)
    folder = data.parent / "images" / "train"
    model = YOLO(str(tmp / "m.pt")).model.float().eval()
    qat.prepare(model, qat.calibration_tensors(folder, calib))
    ckpt = torch.load(str(tmp / "m.pt"), map_location="cpu", weights_only=False)
    ckpt[qat.RANGES_KEY] = qat.trained_ranges(model)
    torch.save(ckpt, str(tmp / "r.pt"))
    graph = onnx.load(str(f32)).graph
    trained = qat_ranges.kept(tmp / "r.pt")
    ranges = qat_ranges.overrides(trained, graph)
    convs = [n for n in graph.node if n.op_type == "Conv"]
    missing = [n.name for n in convs if n.input[0] not in ranges or n.output[0] not in ranges]
    assert convs and not missing, f"convolutions without ranges: {missing}"
    # A run with the head float is told from one without by its ranges alone.
    assert not qat_ranges.trained_float_head(trained)
    head = YOLO(str(tmp / "m.pt")).model.float().eval()
    qat.prepare(head, qat.calibration_tensors(folder, 2), float_head=True)
    torch.save({**ckpt, qat.RANGES_KEY: qat.trained_ranges(head)}, str(tmp / "h.pt"))
    assert qat_ranges.trained_float_head(qat_ranges.kept(tmp / "h.pt"))
    # Calibrated on 2 images, the export would measure ranges of its own; the overrides win.
    quantise(f32, tmp / "with.onnx", folder, 2, ranges=ranges)
    quantise(f32, tmp / "without.onnx", folder, 2)
    run = {k: ort.InferenceSession(str(tmp / f"{k}.onnx"), providers=["CPUExecutionProvider"])
           for k in ("with", "without")}
    off: dict[str, list[float]] = {"with": [], "without": []}
    for f in sorted((data.parent / "images" / "test").glob("*.png"))[:10]:
        x = png_tensor(f)
        with torch.no_grad():
            d = model(torch.from_numpy(x))[1]
        emu = torch.cat([d["boxes"], d["scores"]], 1).numpy()
        for k in off:
            off[k].append(float(np.abs(emu - run[k].run(None, {"images": x})[0]).mean()))
    w, wo = float(np.mean(off["with"])), float(np.mean(off["without"]))
    assert w < 0.5 * wo, f"int8 on the kept ranges off the emulation by {w:.3f}, without {wo:.3f}"
    print(f"qat ranges: {len(convs)} convolutions, {len(ranges)} tensors; mean |emulated - int8| "
          f"{w:.3f} on the kept ranges, {wo:.3f} on ranges measured again")


def test_conventions_declared() -> None:
    import json

    import onnx

    from export import DESKEW_KEY, SEAM_KEY, conventions_of, declare

    tmp = Path(tempfile.mkdtemp())
    f = tmp / "m.onnx"
    shutil.copy(HERE.parent / "models/yolo/testdata/boxes-form.onnx", f)
    declare(f, "quiet", True)
    declare(f, "fixed", False)
    props = [(p.key, p.value) for p in onnx.load(str(f)).metadata_props]
    mine = [kv for kv in props if kv[0] in (SEAM_KEY, DESKEW_KEY)]
    assert sorted(mine) == [(DESKEW_KEY, "false"), (SEAM_KEY, "fixed")], props
    (tmp / "dataset.json").write_text(json.dumps({"seed": 1}))
    assert conventions_of(tmp) == (None, None)
    (tmp / "dataset.json").write_text(json.dumps({"seam": "quiet", "deskew": True}))
    assert conventions_of(tmp) == ("quiet", True)


def test_report_model_fit() -> None:
    from fit_report_model import fit, prob, raw_weights, read_run, rust

    run = Path(tempfile.mkdtemp())
    names = ["score", "rate"]
    (run / "tracks.txt").write_text(
        "# frame id class x y source score rate\n"
        "5 1 box 1.100 0.100 B 0.9 1.0\n"
        "5 2 box 1.450 0.000 B 0.4 0.5\n"
        "5 3 chair 2.000 1.000 B 0.3 0.4\n"
        "5 4 door_frame 3.000 0.000 B 0.5 1.0\n"   # left to the doors
        "5 5 desk 0.000 3.000 B 0.2 0.1\n")        # logged, not reported: no label
    (run / "labels.txt").write_text("# frame id phantom\n5 1 0\n5 2 0\n5 3 1\n")
    got_names, x, y = read_run(run)
    assert got_names == names and y.tolist() == [0, 0, 1], (got_names, y)
    assert x.shape == (3, 2)
    rng = np.random.default_rng(0)
    xs = rng.normal(size=(400, 2)) * [0.2, 3.0] + [0.6, 10.0]
    ys = (xs[:, 0] + 0.1 * rng.normal(size=400) < 0.55).astype(float)
    w, b, mean, scale = fit(xs, ys, 1.0)
    rw, rb = raw_weights(w, b, mean, scale)
    p_std = 1.0 / (1.0 + np.exp(-(((xs - mean) / scale) @ w + b)))
    assert np.allclose(prob(xs, rw, rb), p_std, atol=1e-9)
    assert rw[0] < 0, "a low score must mean a phantom"
    text = rust(rw, rb, 0.5, 50, names, "test")
    assert "// score" in text and "threshold: 0.5" in text and "max_hits: 50" in text
    assert ".e" not in text


if __name__ == "__main__":
    test_report_model_fit()
    test_conventions_declared()
    test_qat_ranges_carried(Path(sys.argv[1]))
    test_qat_emulates_int8(Path(sys.argv[1]))
    test_qat_emulates_int8(Path(sys.argv[1]), per_channel=True)
    test_logits_head(Path(sys.argv[1]))
    test_shuffled(Path(sys.argv[1]))
    print("ok")
