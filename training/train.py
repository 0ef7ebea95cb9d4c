"""Train umbra's YOLOv8n on a simulator dataset (Ultralytics, from scratch, offline).

    python training/train.py --data DATASET/data.yaml --epochs 12 --batch 32 --seed 0 --name small

Augmentations are chosen by physics, not by Ultralytics' defaults: every colour, geometric and
composite augmentation is off. In particular Ultralytics' left-right flip is NOT a mirrored
room for our raster: it mirrors all 384 columns, moving the 24 zero padding columns to the left
and shifting every bearing by 24°. (A valid mirror, column d -> (360 - d) mod 360 with the
padding kept on the right, needs a custom transform; see the production-model issue.)
The up-down flip mirrors range, which no real scan does.
"""

import argparse
import time
from pathlib import Path

import offline  # noqa: F401  (must come before ultralytics)
from exact import ExactTrainer
from ultralytics import YOLO

HERE = Path(__file__).resolve().parent

OFF = dict(
    mosaic=0.0, mixup=0.0, cutmix=0.0, copy_paste=0.0, fliplr=0.0, flipud=0.0,
    translate=0.0, scale=0.0, degrees=0.0, shear=0.0, perspective=0.0,
    hsv_h=0.0, hsv_s=0.0, hsv_v=0.0, erasing=0.0, close_mosaic=0,
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True, help="data.yaml written by umbra-sim dataset")
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--name", default="small")
    ap.add_argument("--resume", action="store_true", help="continue runs/NAME/weights/last.pt")
    a = ap.parse_args()

    t0 = time.time()
    last = HERE / "runs" / a.name / "weights" / "last.pt"
    if a.resume:
        model = YOLO(str(last))
        model.train(resume=True, trainer=ExactTrainer)
    else:
        model = YOLO(str(HERE / "yolov8n-umbra.yaml"))
        model.train(
            data=str(Path(a.data).resolve()), imgsz=384, rect=True, epochs=a.epochs,
            batch=a.batch, workers=a.workers, device=a.device, seed=a.seed, deterministic=True,
            pretrained=False, amp=a.device != "cpu", plots=False, project=str(HERE / "runs"),
            name=a.name, exist_ok=True, val=True, trainer=ExactTrainer, **OFF,
        )
    print(f"trained in {time.time() - t0:.0f} s: {HERE / 'runs' / a.name / 'weights'}")


if __name__ == "__main__":
    main()
