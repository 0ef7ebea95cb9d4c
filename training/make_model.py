"""Make umbra's production YOLOv8n in one command: data -> training -> export -> evaluation -> card.

    python training/make_model.py --work /tmp/umbra-model            # all stages
    python training/make_model.py --work DIR --stages export,eval,card # later stages only

Stages (each prints its progress; everything is seeded and deterministic on CPU):
  data    `umbra-sim dataset` (built here with cargo, release): the training set (rooms of the
          kinds in --kinds, scenario-level train/val/test split), a second test set of a room
          kind not in training with more clutter (--ood-kinds, --ood-clutter, all test), a
          third of the training kinds from many more scenarios with few frames each
          (--wide-scenarios x --wide-frames, --wide-seed, all test: the spread between it and
          the held-out split says how far apart two figures must be to differ), and the fixed
          reference split that `tests/tests/eval_b_ultralytics.rs` regenerates.
  train   YOLOv8n from scratch (or from --init weights) with `train.py`: rect 64x384, every
          Ultralytics augmentation off, the mirrored room on (`mirror.py`).
  export  fp32 ONNX and the int8 QOperator form (`export.py`) into models/yolo, and the
          checkpoint itself (models/yolo/umbra-yolov8n.pt, to continue from in a later run).
  eval    the Rust evaluator (`umbra-lab eval-b`) on the three test sets, fp32 and int8, and
          Ultralytics' validator (`ultra_val.py`) on the first two; writes
          models/yolo/ultralytics-test.json for the Rust test.
  card    the generated part of models/README.md (data, seed, epochs, hardware, time, metrics
          per class, sha256 of every file).
"""

import argparse
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
MODELS = ROOT / "models" / "yolo"
CARD = ROOT / "models" / "README.md"
BEGIN, END = "<!-- model-card:begin -->", "<!-- model-card:end -->"
# The split `tests/tests/eval_b_ultralytics.rs` regenerates and compares against.
REFERENCE = ["--scenarios", "40", "--frames", "50", "--seed", "11"]
STAGES = ["data", "train", "export", "eval", "card"]
# The test sets the Rust evaluator scores (`sets`): held-out split, unseen kind, wider set.
TEST_SETS = ("train", "ood", "wide")


def sh(cmd: list[str], **kw) -> None:
    print("+", " ".join(str(c) for c in cmd), flush=True)
    subprocess.run([str(c) for c in cmd], check=True, **kw)


def sha256(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def bins() -> tuple[Path, Path]:
    sh(["cargo", "build", "--release", "-p", "umbra-sim", "--bin", "umbra-sim", "-p",
        "umbra-lab", "--bin", "umbra-lab"], cwd=ROOT)
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release"
    return target / "umbra-sim", target / "umbra-lab"


def dataset(sim: Path, out: Path, args: list[str]) -> dict:
    """Writes a dataset unless `out` already holds one made by the same arguments."""
    stamp = out / "command.txt"
    want = " ".join(args)
    if stamp.exists() and stamp.read_text() == want:
        print(f"dataset {out} is up to date ({want})")
    else:
        if out.exists():
            shutil.rmtree(out)
        sh([sim, "dataset", "--out", out, "--no-method-a", "--no-recordings", "--pictures", "0",
            *args])
        stamp.write_text(want)
    return json.loads((out / "dataset.json").read_text())


def drawing(a) -> list[str]:
    """The seam rule and swept labels every set of the model is drawn with (none by default,
    so the stamps of sets made before these flags still hold)."""
    return (["--seam", a.seam] if a.seam != "fixed" else []) + (["--deskew"] if a.deskew else [])


def sets(a) -> dict[str, list[str]]:
    common = ["--frames", str(a.frames)]
    return {
        "train": ["--scenarios", str(a.scenarios), *common, "--seed", str(a.seed), "--kinds",
                  a.kinds, "--clutter", str(a.clutter), *drawing(a),
                  *(["--worn", str(a.worn)] if a.worn else [])],
        "ood": ["--scenarios", str(a.ood_scenarios), *common, "--seed", str(a.seed + 1),
                "--kinds", a.ood_kinds, "--clutter", str(a.ood_clutter), "--test-only",
                *drawing(a)],
        "wide": ["--scenarios", str(a.wide_scenarios), "--frames", str(a.wide_frames), "--seed",
                 str(a.wide_seed), "--kinds", a.kinds, "--clutter", str(a.clutter),
                 "--test-only", *drawing(a)],
        "reference": REFERENCE,
    }


def evaluate(lab: Path, sim_sets: dict, work: Path, threads: int) -> dict:
    res = {}
    for model in ("umbra-yolov8n.onnx", "umbra-yolov8n-int8.onnx"):
        for name in TEST_SETS:
            out = work / f"eval-{name}-{model}.json"
            sh([lab, "eval-b", "--data", work / name, "--split", "test", "--model",
                MODELS / model, "--threads", str(threads), "--json", out])
            res[f"{name}/{model}"] = json.loads(out.read_text())
    py = sys.executable
    for name in ("train", "ood", "reference"):
        out = work / f"ultra-{name}.json"
        sh([py, HERE / "ultra_val.py", "--weights", MODELS / "umbra-yolov8n.pt", "--data",
            work / name / "data.yaml", "--split", "test", "--json", out])
        res[f"ultralytics/{name}"] = json.loads(out.read_text())
    ref = res["ultralytics/reference"]
    ref = {
        "what": "Ultralytics validation (training/ultra_val.py: DetectionValidator, 64x384 "
                "unpadded) of the checkpoint exported to models/yolo/umbra-yolov8n.onnx",
        "dataset": {"command": "umbra-sim dataset " + " ".join(REFERENCE), "split": "test",
                    "images": len(list((work / "reference" / "images" / "test").glob("*.png")))},
        "weights_sha256": sha256(MODELS / "umbra-yolov8n.pt"),
        **{k: v for k, v in ref.items() if k != "images"},
    }
    (MODELS / "ultralytics-test.json").write_text(json.dumps(ref, indent=2) + "\n")
    (work / "eval.json").write_text(json.dumps(res, indent=2))
    return res


def hardware(device: str) -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    if device != "cpu":
        import torch

        return f"{torch.cuda.get_device_name(0)} (CUDA), host CPU {cpu}"
    return f"CPU only: {os.cpu_count()} x {cpu}"


def table(m: dict) -> list[str]:
    rows = ["| class | P | R | mAP50 | mAP50-95 |", "|---|---|---|---|---|",
            f"| all | {m['p']:.3f} | {m['r']:.3f} | {m['map50']:.3f} | {m['map50_95']:.3f} |"]
    for c in m["per_class"]:
        rows.append(f"| {c['class']} | {c['p']:.3f} | {c['r']:.3f} | {c['map50']:.3f} | "
                    f"{c['map50_95']:.3f} |")
    return rows


def spread(a, ev: dict, ds: dict) -> list[str]:
    """The card's table of the held-out split beside the wider test set of the same kinds."""
    wide = ds["wide"]["frames"]["test"]
    L = ["", f"**A wider test set of the training kinds** (`umbra-sim dataset "
         f"{' '.join(sets(a)['wide'])}`: {wide:,} images from {a.wide_scenarios} scenarios, "
         f"against the held-out split's {ds['train']['frames']['test']:,} from far fewer). "
         "The difference between the two is the spread a figure carries from its test set "
         "alone; two models closer than it are not told apart by either:", "",
         "| model | ruler | held-out mAP50 / mAP50-95 | wider set | difference |",
         "|---|---|---|---|---|"]
    for model in ("umbra-yolov8n.onnx", "umbra-yolov8n-int8.onnx"):
        t, w = ev[f"train/{model}"], ev[f"wide/{model}"]
        pairs = [("ours", t, w)]
        if t.get("study_rule") and w.get("study_rule"):
            pairs.append(("the study's", t["study_rule"], w["study_rule"]))
        for ruler, x, y in pairs:
            L.append(f"| {model} | {ruler} | {x['map50']:.4f} / {x['map50_95']:.4f} | "
                     f"{y['map50']:.4f} / {y['map50_95']:.4f} | "
                     f"{y['map50'] - x['map50']:+.4f} / {y['map50_95'] - x['map50_95']:+.4f} |")
    return L


def card(a, work: Path, info: dict) -> None:
    ev = json.loads((work / "eval.json").read_text())
    ds = {k: json.loads((work / k / "dataset.json").read_text()) for k in TEST_SETS}
    cmd = info["command"]
    t = ds["train"]["frames"]
    L = [BEGIN, "", "### Model card (generated by `training/make_model.py`)", ""]
    if info.get("lineage"):
        # Weights from a chain of continuations (`--weights`): the training log above holds
        # every step; the card says where the weights came from and what they were tested on.
        L += [f"- **Weights:** {info['lineage']}",
              "- **Architecture:** YOLOv8n (`training/yolov8n-umbra.yaml`, nc 4: chair, box, "
              "desk, door_frame).",
              f"- **Held-out test set:** the test split of `umbra-sim dataset "
              f"{' '.join(sets(a)['train'])}` ({t['test']:,} images; no weights in the chain "
              "were trained on seed 21's test scenarios).",
              f"- **Second test set (room kind never trained on):** `umbra-sim dataset "
              f"{' '.join(sets(a)['ood'])}` ({ds['ood']['frames']['test']:,} images)."]
    else:
        L += [f"- **Command:** `{cmd}`" + (f" (stages run as: {'; '.join(info['runs'])})"
                                           if len(info["runs"]) > 1 else ""),
              "- **Architecture:** YOLOv8n (`training/yolov8n-umbra.yaml`, nc 4: chair, box, "
              "desk, door_frame), " + (f"initialised from `{info['init']}`" if info.get("init")
                                       else "from scratch (no pretrained weights)") + ".",
              f"- **Training data:** `umbra-sim dataset {' '.join(sets(a)['train'])}` "
              f"({t['train']:,} train / {t['val']:,} val / {t['test']:,} test images; "
              "scenarios split by a seeded shuffle, so no test scenario is seen in training).",
              f"- **Second test set (room kinds not in training):** `umbra-sim dataset "
              f"{' '.join(sets(a)['ood'])}` ({ds['ood']['frames']['test']:,} images).",
              f"- **Training:** {info['epochs']} epochs, batch {a.batch}, seed {a.seed}, "
              f"mirrored room p = {a.mirror}, every Ultralytics augmentation off; Ultralytics "
              f"{info['ultralytics']}, torch {info['torch']}; {info['hardware']}; "
              f"{info['train_s']:,.0f} s of training. Checkpoint: `best.pt` (highest val "
              "fitness)."]
    if info.get("int8_weights"):
        L += ["- **Export:** fp32 ONNX opset 17, simplified, from the weights above. int8 "
              "QOperator, convolutions only, per-tensor (`training/export.py`), from other "
              f"weights: {info['int8_lineage']}; calibrated on the first 256 PNGs of "
              f"`{info['calib']}`, the images the fine-tuning measured its ranges on."]
    else:
        L += ["- **Export:** fp32 ONNX opset 17, simplified; int8 QOperator, convolutions only, "
              "per-tensor, calibrated on the first 256 training images (`training/export.py`)."]
    L += ["", "**Held-out test scenarios** (Rust evaluator `umbra-lab eval-b`, fp32):", ""]
    L += table(ev["train/umbra-yolov8n.onnx"])
    L += ["", "**Second test set, unseen room kind** (fp32):", ""]
    L += table(ev["ood/umbra-yolov8n.onnx"])
    L += ["", "| set | model | mAP50 | mAP50-95 | Ultralytics mAP50 / mAP50-95 (fp32 .pt) |",
          "|---|---|---|---|---|"]
    for name, label in (("train", "held-out"), ("ood", "unseen kind")):
        u = ev[f"ultralytics/{name}"]
        for model in ("umbra-yolov8n.onnx", "umbra-yolov8n-int8.onnx"):
            m = ev[f"{name}/{model}"]
            L.append(f"| {label} | {model} | {m['map50']:.4f} | {m['map50_95']:.4f} | "
                     f"{u['map50']:.4f} / {u['map50_95']:.4f} |")
    study = [(label, model, ev[f"{name}/{model}"].get("study_rule"))
             for name, label in (("train", "held-out"), ("ood", "unseen kind"))
             for model in ("umbra-yolov8n.onnx", "umbra-yolov8n-int8.onnx")]
    if all(m for _, _, m in study):
        L += ["", "**The study's ruler** (`umbra-lab eval-b`: our true boxes and the model's "
              "widened as the study's label generator draws them, + 20 px wide and + 12 px tall, "
              "clamped):", "", "| set | model | mAP50 | mAP50-95 |", "|---|---|---|---|"]
        L += [f"| {label} | {model} | {m['map50']:.4f} | {m['map50_95']:.4f} |"
              for label, model, m in study]
    L += spread(a, ev, ds)
    L += ["", "**sha256:**", ""]
    for f in ("umbra-yolov8n.pt", "umbra-yolov8n.onnx", "umbra-yolov8n-int8.onnx",
              "ultralytics-test.json"):
        L.append(f"- `{f}` {sha256(MODELS / f)}")
    L += ["", END]
    text = CARD.read_text()
    if BEGIN in text:
        text = text[: text.index(BEGIN)] + "\n".join(L) + text[text.index(END) + len(END):]
    else:
        text = text.rstrip() + "\n\n" + "\n".join(L) + "\n"
    CARD.write_text(text)
    print(f"wrote the model card in {CARD}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, required=True, help="datasets, runs' results, evals")
    ap.add_argument("--stages", default=",".join(STAGES), help=",".join(STAGES))
    ap.add_argument("--scenarios", type=int, default=600)
    ap.add_argument("--frames", type=int, default=25)
    ap.add_argument("--seed", type=int, default=21)
    ap.add_argument("--kinds", default="rect,tworooms")
    ap.add_argument("--clutter", type=int, default=3)
    ap.add_argument("--ood-scenarios", type=int, default=40)
    ap.add_argument("--ood-kinds", default="lshape")
    ap.add_argument("--ood-clutter", type=int, default=6)
    ap.add_argument("--wide-scenarios", type=int, default=300)
    ap.add_argument("--wide-frames", type=int, default=5)
    ap.add_argument("--wide-seed", type=int, default=70)
    ap.add_argument("--seam", choices=("fixed", "quiet"), default="fixed",
                    help="every set's raster seam (`umbra-sim dataset --seam`); the exported "
                    "files declare it and the runtime follows")
    ap.add_argument("--deskew", action="store_true",
                    help="every set's labels drawn where the sweep read them (`--deskew`); "
                    "declared in the exported files like --seam")
    ap.add_argument("--worn", type=float, default=0.0,
                    help="share of the training set's scenarios seen by a worn LiDAR "
                    "(`umbra-sim dataset --worn`); the test sets stay fresh, so figures compare")
    ap.add_argument("--epochs", type=int, default=14)
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--mirror", type=float, default=0.5)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--init", type=Path, help="start from these weights instead of scratch")
    ap.add_argument("--resume", action="store_true", help="continue an interrupted run")
    ap.add_argument("--weights", type=Path,
                    help="export/eval/card these weights (a continuation) instead of a train stage's")
    ap.add_argument("--lineage", help="with --weights: the card's line on where they came from")
    ap.add_argument("--int8-weights", type=Path,
                    help="export the int8 file from these weights (a `qat.py` fine-tune)")
    ap.add_argument("--int8-lineage", help="with --int8-weights: the card's line on them")
    ap.add_argument("--calib", type=Path,
                    help="int8 calibration PNGs (default: the train set's training images)")
    ap.add_argument("--threads", type=int, default=1, help="tract threads for eval")
    a = ap.parse_args()
    stages = a.stages.split(",")
    unknown = set(stages) - set(STAGES)
    if unknown:
        ap.error(f"unknown stages {sorted(unknown)}")
    work = a.work.resolve()
    work.mkdir(parents=True, exist_ok=True)
    info_path = work / "info.json"
    info = json.loads(info_path.read_text()) if info_path.exists() else {"runs": []}
    info["command"] = ("python training/make_model.py --work DIR "
                       + " ".join(f"--{k.replace('_', '-')}" + ("" if v is True else f" {v}")
                                  for k, v in vars(a).items()
                                  if k not in ("work", "stages", "resume", "threads", "weights",
                                               "lineage", "int8_weights", "int8_lineage",
                                               "calib")
                                  and v is not None and v is not False))
    info["runs"].append(" ".join(sys.argv[1:]))
    sim, lab = bins() if {"data", "eval"} & set(stages) else (None, None)
    if "data" in stages:
        for name, args in sets(a).items():
            dataset(sim, work / name, args)
    if "train" in stages:
        import offline  # noqa: F401
        import torch
        import ultralytics
        from train import train

        t0 = time.time()
        w = train(work / "train" / "data.yaml", a.epochs, a.batch, a.seed, a.device, a.workers,
                  "production", a.resume, a.mirror, a.init)
        info.update(train_s=info.get("train_s", 0) * a.resume + time.time() - t0,
                    epochs=a.epochs, weights=str(w), init=str(a.init) if a.init else None,
                    ultralytics=ultralytics.__version__, torch=torch.__version__,
                    hardware=hardware(a.device))
        info_path.write_text(json.dumps(info, indent=2))
    if a.weights:
        info.update(weights=str(a.weights.resolve().parent), best=str(a.weights.resolve()),
                    lineage=a.lineage or f"`{a.weights}`")
    if a.int8_weights:
        info.update(int8_weights=str(a.int8_weights.resolve()),
                    int8_lineage=a.int8_lineage or f"`{a.int8_weights}`")
    calib = a.calib or work / "train" / "images" / "train"
    info["calib"] = str(calib)
    if "export" in stages:
        best = Path(info.get("best") or Path(info["weights"]) / "best.pt")
        # Both files declare how the sets were drawn (`export.py --seam --deskew`).
        drawn = ["--seam", a.seam, "--deskew", str(a.deskew).lower()]
        sh([sys.executable, HERE / "export.py", "--weights", best, "--out", MODELS, "--calib",
            calib, "--calib-images", "256", *drawn])
        if info.get("int8_weights"):
            # The int8 file from its own (quantisation-aware) weights, calibrated on the
            # images its fine-tuning measured its ranges on; the fp32 file stays `best`'s.
            tmp = work / "int8-export"
            sh([sys.executable, HERE / "export.py", "--weights", info["int8_weights"], "--out",
                tmp, "--calib", calib, "--calib-images", "256", *drawn])
            shutil.copy(tmp / "umbra-yolov8n-int8.onnx", MODELS / "umbra-yolov8n-int8.onnx")
        shutil.copy(best, MODELS / "umbra-yolov8n.pt")
    if "eval" in stages:
        evaluate(lab, sets(a), work, a.threads)
    if "card" in stages:
        card(a, work, info)
    info_path.write_text(json.dumps(info, indent=2))


if __name__ == "__main__":
    main()
