"""Ultralytics' own validation of a checkpoint on a dataset split, as JSON, for comparison with
the Rust evaluator (`umbra-lab eval-b`).

    python training/ultra_val.py --weights runs/NAME/weights/best.pt --data DATASET/data.yaml \
        --split test --json ultra.json

One setting differs from `model.val()`: the validator's rectangular batches get no extra half
stride of padding (Ultralytics pads val images to 96 x 384 by default), so it sees exactly the
64 x 384 images the runtime sees; everything else (conf 0.001, IoU 0.7, multi-label NMS,
matching, AP, the F1 operating point) is Ultralytics' code.
"""

import argparse
import json

import offline  # noqa: F401
from exact import ExactValidator
from ultralytics import YOLO


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--weights", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--split", default="test")
    ap.add_argument("--json", required=True)
    a = ap.parse_args()
    model = YOLO(a.weights)
    m = model.val(data=a.data, split=a.split, imgsz=384, rect=True, batch=16, device="cpu",
                  plots=False, validator=ExactValidator, workers=0, half=False)
    names = m.names
    per = [
        {"class": names[int(c)], "p": float(p), "r": float(r), "map50": float(a50),
         "map50_95": float(a)}
        for c, p, r, a50, a in zip(m.box.ap_class_index, m.box.p, m.box.r, m.box.ap50, m.box.ap)
    ]
    out = {"p": float(m.box.mp), "r": float(m.box.mr), "map50": float(m.box.map50),
           "map50_95": float(m.box.map), "images": int(m.seen) if hasattr(m, "seen") else None, "per_class": per}
    with open(a.json, "w") as f:
        json.dump(out, f, indent=2)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
