"""A mirrored room: the one geometric augmentation that is valid for umbra's raster.

The raster (`perception::raster`) has one column per degree of bearing, columns 0..359, and 24
zero padding columns on the right (384 = 6 strides of 64). A room mirrored about the robot's
x axis puts the reading at bearing d at bearing -d. Mirroring about the bearing 179.5 deg
instead (column d -> 359 - d) is the same mirrored room seen by a robot turned by 1 deg, an
equally real scan, and it maps whole columns to whole columns, so boxes stay exact:
pixel x -> 360 - x, padding stays on the right, nothing crosses the 0/360 seam.

Ultralytics' own `fliplr` mirrors all 384 columns instead: the padding moves to the left and
every bearing shifts by 24 deg, a scan no LiDAR produces. An up-down flip mirrors range, which
no real scan does either; both stay off (see `train.py`).

    python training/mirror.py --check DATASET [--images 200]

checks the transform on a dataset: every mirrored box must hold exactly the mirrored pixels.
"""

import argparse
import random
from pathlib import Path

import numpy as np

BINS = 360
WIDTH = 384


class MirrorRoom:
    """Ultralytics transform (labels dict in, labels dict out), applied with probability `p`."""

    def __init__(self, p: float = 0.5):
        self.p = p

    def __call__(self, labels: dict) -> dict:
        if self.p <= 0.0 or random.random() >= self.p:
            return labels
        img = labels["img"]
        if img.shape[1] != WIDTH:
            raise ValueError(f"MirrorRoom expects {WIDTH}-column rasters, got {img.shape}")
        out = img.copy()
        out[:, :BINS] = img[:, BINS - 1 :: -1]
        labels["img"] = np.ascontiguousarray(out)
        inst = labels["instances"]
        fmt = inst._bboxes.format
        inst.convert_bbox(format="xyxy")
        span = BINS / WIDTH if inst.normalized else float(BINS)
        b = inst.bboxes
        x1 = b[:, 0].copy()
        b[:, 0] = span - b[:, 2]
        b[:, 2] = span - x1
        inst.convert_bbox(format=fmt)
        return labels


def _check(dataset: Path, n: int) -> None:
    import cv2
    from ultralytics.utils.instance import Instances

    images = sorted((dataset / "images" / "train").glob("*.png"))[:n]
    if not images:
        raise SystemExit(f"no images under {dataset}/images/train")
    boxes_checked = 0
    for f in images:
        img = cv2.imread(str(f), cv2.IMREAD_COLOR)
        lab = dataset / "labels" / "train" / (f.stem + ".txt")
        rows = np.loadtxt(lab, ndmin=2) if lab.stat().st_size else np.zeros((0, 5))
        inst = Instances(rows[:, 1:5].astype(np.float32).copy(), bbox_format="xywh",
                         normalized=True)
        labels = MirrorRoom(p=1.0)({"img": img, "instances": inst})
        m, mb = labels["img"], labels["instances"]
        assert m[:, BINS:].max(initial=0) == 0, f"{f}: padding not kept on the right"
        assert (m[:, :BINS] == img[:, BINS - 1 :: -1]).all()
        mb.convert_bbox("xyxy")
        orig = rows[:, 1:5].copy()
        ox1 = (orig[:, 0] - orig[:, 2] / 2) * WIDTH
        ox2 = (orig[:, 0] + orig[:, 2] / 2) * WIDTH
        for k in range(len(rows)):
            x1, x2 = mb.bboxes[k, 0] * WIDTH, mb.bboxes[k, 2] * WIDTH
            assert abs(x1 - (BINS - ox2[k])) < 1e-3 and abs(x2 - (BINS - ox1[k])) < 1e-3
            a, b = int(round(ox1[k])), int(round(ox2[k]))
            ma, mbx = int(round(x1)), int(round(x2))
            assert 0 <= ma <= mbx <= BINS, f"{f}: box {k} left the bearing columns"
            # The pixels inside the mirrored box are the original box's, column order reversed.
            assert (m[:, ma:mbx] == img[:, a:b][:, ::-1]).all(), f"{f}: box {k} content moved"
            boxes_checked += 1
    print(f"mirror check: {len(images)} images, {boxes_checked} boxes, all exact")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", type=Path, required=True, help="dataset folder (umbra-sim dataset)")
    ap.add_argument("--images", type=int, default=200)
    a = ap.parse_args()
    import offline  # noqa: F401

    _check(a.check, a.images)
