"""Train umbra's YOLOv8n on a simulator dataset (Ultralytics, from scratch, offline).

    python training/train.py --data DATASET/data.yaml --epochs 12 --batch 32 --seed 0 --name small

Augmentations are chosen by physics, not by Ultralytics' defaults: every colour, geometric and
composite augmentation of Ultralytics is off, and a mirrored room (`mirror.py`, p = 0.5) is on.
Ultralytics' left-right flip is NOT a mirrored room for our raster: it mirrors all 384 columns,
moving the 24 zero padding columns to the left and shifting every bearing by 24°. The up-down
flip mirrors range, which no real scan does. Colour (HSV) changes would alter the channel
intensities that encode which revolution a return belongs to; scale/translate would change
range or bearing per pixel, which the sensor fixes; mosaic/mixup/cutmix paste scans together.
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


# The optimiser, pinned: with `optimizer="auto"` Ultralytics picks AdamW (lr 0.00125 for 4
# classes) below 10k iterations and switches to SGD (lr 0.01) above, so a longer run would
# silently change optimiser. A continuation (`--init`) warms up briefly and decays on a cosine.
SCHEDULE = dict(optimizer="AdamW", lr0=0.00125, lrf=0.01, momentum=0.937, weight_decay=0.0005)


def train(data: Path, epochs: int, batch: int = 32, seed: int = 0, device: str = "cpu",
          workers: int = 2, name: str = "small", resume: bool = False, mirror: float = 0.5,
          init: Path | None = None, lr0: float | None = None, cache: str | bool = "ram",
          hours: float | None = None, amp: bool = False, trainer=ExactTrainer) -> Path:
    """Train (or resume) one run; returns its weights folder.

    Every image is 64 x 384, so the `rect` batch shapes are all equal and Ultralytics keeps the
    DataLoader's shuffling on (it turns it off only for unequal shapes);
    `training/test_training.py` checks that two epochs see different orders.

    `hours` caps the run's wall time (Ultralytics' `time`: the epoch count is refitted to it after
    each epoch, and the cosine schedule with it). `amp` is off unless asked for: Ultralytics'
    AMP check downloads a model, which an offline machine cannot. `trainer` is `ExactTrainer`
    or a subclass of it (`qat.py`'s).
    """
    sched = dict(SCHEDULE)
    if lr0 is not None:
        sched["lr0"] = lr0
    if init:
        # Ultralytics' warm-up starts the biases at lr 0.1 over at least 100 iterations, which
        # undoes a trained model (seen: val mAP50 0.96 -> 0.27 after one short epoch): biases
        # start at lr0 instead.
        sched.update(warmup_epochs=0.2, warmup_bias_lr=sched["lr0"], cos_lr=True)
    trainer.mirror_p = mirror
    weights = HERE / "runs" / name / "weights"
    if resume:
        YOLO(str(weights / "last.pt")).train(resume=True, trainer=trainer)
    else:
        YOLO(str(HERE / "yolov8n-umbra.yaml")).train(
            data=str(Path(data).resolve()), imgsz=384, rect=True, epochs=epochs, batch=batch,
            workers=workers, device=device, seed=seed, deterministic=True,
            pretrained=str(init) if init else False, amp=amp, plots=False,
            project=str(HERE / "runs"), name=name, exist_ok=True, val=True,
            trainer=trainer, cache=cache, **({"time": hours} if hours else {}),
            **sched, **OFF,
        )
    return weights


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True, help="data.yaml written by umbra-sim dataset")
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--name", default="small")
    ap.add_argument("--mirror", type=float, default=0.5,
                    help="probability of a mirrored room (training/mirror.py); 0 = off")
    ap.add_argument("--init", type=Path, help="start from these weights (e.g. the committed .pt)")
    ap.add_argument("--resume", action="store_true", help="continue runs/NAME/weights/last.pt")
    ap.add_argument("--lr0", type=float, help=f"initial learning rate (default {SCHEDULE['lr0']})")
    ap.add_argument("--no-cache", action="store_true", help="read images from disk each epoch")
    ap.add_argument("--hours", type=float, help="stop after this many hours (refits the epochs)")
    ap.add_argument("--amp", action="store_true", help="mixed precision (GPU, online machines)")
    a = ap.parse_args()

    t0 = time.time()
    w = train(Path(a.data), a.epochs, a.batch, a.seed, a.device, a.workers, a.name, a.resume,
              a.mirror, a.init, a.lr0, False if a.no_cache else "ram", a.hours, a.amp)
    print(f"trained in {time.time() - t0:.0f} s: {w}")


if __name__ == "__main__":
    main()
