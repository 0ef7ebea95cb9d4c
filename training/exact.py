"""Ultralytics' detection trainer and validator, seeing our images at exactly 64 x 384.

For validation Ultralytics pads rectangular batches by half a stride: our 384 x 64 rasters
become 96 x 416 letterboxes, grey rows and columns all round, which the network never sees in
training (train batches are unpadded) nor at run time. Measured on a 7-epoch model: val mAP50
0.0001 letterboxed vs the real figure unpadded. These subclasses set the val batch shape
back to 64 x 384; nothing else changes.

The trainer also puts `mirror.MirrorRoom` first in the training transforms, with the
probability in `ExactTrainer.mirror_p` (0 = off), and reads its results.csv with the standard
library (Ultralytics uses polars, which a machine without a package index may not have).
"""

import csv

from ultralytics.models.yolo.detect import DetectionTrainer, DetectionValidator

from mirror import MirrorRoom


def _unpad(ds):
    shapes = ds.batch_shapes
    assert (shapes == shapes[0]).all() and tuple(shapes[0]) == (96, 416), (
        f"expected 384x64 images only (val batch shape 96x416), got {shapes[:3]}")
    ds.batch_shapes[:] = [64, 384]
    return ds


class ExactValidator(DetectionValidator):
    def build_dataset(self, img_path, mode="val", batch=None):
        return _unpad(super().build_dataset(img_path, mode, batch))


class ExactTrainer(DetectionTrainer):
    mirror_p = 0.0

    def build_dataset(self, img_path, mode="train", batch=None):
        ds = super().build_dataset(img_path, mode, batch)
        if mode == "val":
            return _unpad(ds)
        if self.mirror_p > 0.0:
            ds.transforms.insert(0, MirrorRoom(self.mirror_p))
        return ds

    def read_results_csv(self):
        """results.csv as {column: [values]}, as Ultralytics' polars reader returns it."""
        try:
            with open(self.csv, newline="") as f:
                rows = list(csv.DictReader(f))
        except OSError:
            return {}
        return {k.strip(): [float(r[k]) for r in rows] for k in (rows[0] if rows else {})}
