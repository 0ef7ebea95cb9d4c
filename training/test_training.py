"""Checks of the training setup that need Ultralytics (not run in CI: run them with the training
environment, `.venv/bin/python training/test_training.py DATASET/data.yaml`).

* shuffling: Ultralytics turns DataLoader shuffling off for `rect=True` when the batch shapes
  differ; ours are all 64 x 384, so it must stay on — two epochs of the trainer's own
  dataloader must see the images in different orders, every batch exactly 64 x 384.
"""

import sys
from pathlib import Path

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


if __name__ == "__main__":
    test_shuffled(Path(sys.argv[1]))
    print("ok")
