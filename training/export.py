"""Export a trained checkpoint to the ONNX files the runtime loads.

    python training/export.py --weights runs/NAME/weights/best.pt --out models/yolo \
        --seam fixed --deskew false [--calib DATASET/images/train --calib-images 256]

Writes `umbra-yolov8n.onnx` (fp32, opset 17, simplified, static 1x3x64x384 -> 1x68x504: the
graph cut before its box decoding by `logits_head.py`; the runtime's decoder does that part)
and, with `--calib`, `umbra-yolov8n-int8.onnx`: static int8, QOperator form, convolutions only
(`QLinearConv`, per-tensor), the form tract executes in integer, quantised from the cut graph
so that the DFL's expectation stays float (quantised, its uint8 probabilities moved boxes by
up to 7 px). QDQ is run in float by tract (slower than fp32), and QOperator on all ops needs
`QLinearSigmoid`, which tract rejects. `--full-head` keeps Ultralytics' 1x8x504 output (the
runtime reads both forms).
Calibration images are the first N of the folder in name order (deterministic).

Both files declare how their training images were drawn, as ONNX metadata the runtime reads
(`models/src/conventions.rs`): `umbra.seam` (`--seam`: `fixed`, bin 0 first, or `quiet`) and
`umbra.deskew` (`--deskew true|false`: labels drawn where the sweep read them). They must be
the flags the training set was made with (`umbra-sim dataset --seam ... --deskew`); with
`--data DATASET` they are read from its `dataset.json`. Nothing is assumed: an export that says
neither, from a set that does not record them, stops with an error.
"""

import argparse
import json
import shutil
from pathlib import Path

import numpy as np

import logits_head
import offline  # noqa: F401
import qat_ranges
from ultralytics import YOLO


def png_tensor(path: Path) -> np.ndarray:
    """A dataset PNG as the runtime's input tensor (1x3x64x384 float, channel 0 = red = newest)."""
    import cv2

    bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
    rgb = bgr[:, :, ::-1]
    return np.ascontiguousarray(rgb.transpose(2, 0, 1)[None].astype(np.float32) / 255.0)


def ultralytics_onnx(weights: Path) -> Path:
    """`weights` exported by Ultralytics as the runtime's graph before the cut: opset 17,
    simplified, static 1x3x64x384, full head. Ultralytics writes it beside the weights."""
    f = YOLO(str(weights)).export(format="onnx", imgsz=(64, 384), opset=17, simplify=True,
                                  dynamic=False, batch=1, device="cpu")
    return Path(f)


def quantise(fp32: Path, out: Path, calib: Path, n: int, per_channel: bool = False,
             ranges: dict | None = None, exclude: tuple[str, ...] = ()) -> None:
    """`fp32` as int8 in `out`, calibrated on the first `n` PNGs of `calib`; `ranges`:
    onnxruntime `TensorQuantOverrides` that replace the measured ranges of those tensors
    (a quantisation-aware run's, `qat_ranges.overrides`); `exclude`: convolutions left float."""
    from onnxruntime.quantization import (CalibrationDataReader, QuantFormat, QuantType,
                                          quantize_static)

    files = sorted(calib.glob("*.png"))[:n]

    class Reader(CalibrationDataReader):
        def __init__(self):
            self.it = iter(files)

        def get_next(self):
            f = next(self.it, None)
            return None if f is None else {"images": png_tensor(f)}

    quantize_static(
        str(fp32), str(out), Reader(), quant_format=QuantFormat.QOperator,
        op_types_to_quantize=["Conv"], per_channel=per_channel, activation_type=QuantType.QUInt8,
        weight_type=QuantType.QInt8, nodes_to_exclude=list(exclude),
        extra_options={"TensorQuantOverrides": ranges} if ranges else None,
    )


SEAM_KEY, DESKEW_KEY = "umbra.seam", "umbra.deskew"


def declare(path: Path, seam: str, deskew: bool) -> None:
    """Writes the drawing conventions into `path`'s metadata (replacing earlier values)."""
    import onnx

    m = onnx.load(str(path))
    keep = [p for p in m.metadata_props if p.key not in (SEAM_KEY, DESKEW_KEY)]
    del m.metadata_props[:]
    m.metadata_props.extend(keep)
    for k, v in ((SEAM_KEY, seam), (DESKEW_KEY, "true" if deskew else "false")):
        e = m.metadata_props.add()
        e.key, e.value = k, v
    onnx.save(m, str(path))


def conventions_of(data: Path) -> tuple[str | None, bool | None]:
    """The seam rule and swept labels a dataset was made with (its `dataset.json`); `None`
    where it does not say (sets made before `umbra-sim` recorded them)."""
    d = json.loads((data / "dataset.json").read_text())
    deskew = d.get("deskew")
    return d.get("seam"), None if deskew is None else bool(deskew)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--weights", required=True)
    ap.add_argument("--out", default="models/yolo")
    ap.add_argument("--calib", help="folder of PNGs for int8 calibration")
    ap.add_argument("--calib-images", type=int, default=256)
    ap.add_argument("--per-channel", action="store_true",
                    help="int8 weights per output channel (as `qat.py --per-channel` trains)")
    ap.add_argument("--float-head", action="store_true",
                    help="int8: leave the head's six output convolutions float (as `qat.py "
                    "--float-head` trains; a checkpoint of such a run is recognised without it)")
    ap.add_argument("--full-head", action="store_true",
                    help="keep the DFL and box decoding in the graph (1x8x504)")
    ap.add_argument("--seam", choices=("fixed", "quiet"),
                    help="the training images' seam rule (else --data's)")
    ap.add_argument("--deskew", choices=("true", "false"),
                    help="whether the training labels were swept (else --data's)")
    ap.add_argument("--data", type=Path,
                    help="the training set's folder: its dataset.json gives --seam and --deskew")
    a = ap.parse_args()
    seam, deskew = conventions_of(a.data) if a.data else (None, None)
    seam = a.seam or seam
    deskew = deskew if a.deskew is None else a.deskew == "true"
    if seam is None or deskew is None:
        ap.error("say how the training images were drawn: --seam and --deskew, or --data with a "
                 "dataset.json that records them")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    f = ultralytics_onnx(Path(a.weights))
    fp32 = out / "umbra-yolov8n.onnx"
    if a.full_head:
        shutil.copy(f, fp32)
    else:
        logits_head.cut(Path(f), fp32)
    declare(fp32, seam, deskew)
    print(f"wrote {fp32} (seam {seam}, deskew {str(deskew).lower()})")
    if a.calib:
        q = out / "umbra-yolov8n-int8.onnx"
        import onnx

        graph = onnx.load(str(fp32)).graph
        trained = qat_ranges.kept(Path(a.weights))
        float_head = a.float_head or qat_ranges.trained_float_head(trained)
        if float_head and not a.float_head:
            print("int8: the head's output convolutions stay float, as its quantisation-aware "
                  "run trained them")
        skip = tuple(qat_ranges.head_outputs(graph)) if float_head else ()
        ranges = qat_ranges.overrides(trained, graph, skip)
        if ranges:
            print(f"int8 on the ranges its quantisation-aware run trained through "
                  f"({len(ranges)} tensors)")
        quantise(fp32, q, Path(a.calib), a.calib_images, a.per_channel, ranges, skip)
        declare(q, seam, deskew)
        print(f"wrote {q}")


if __name__ == "__main__":
    main()
