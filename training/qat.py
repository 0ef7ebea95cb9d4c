"""Quantisation-aware fine-tuning: train the network through the int8 model's own rounding.

    python training/qat.py --data DATASET/data.yaml --init checkpoints/var25.pt \
        --calib DATASET/images/train --epochs 2 --lr0 0.0001 --name qat1
    python training/qat.py --strip runs/qat1/weights/last.pt checkpoints/qat1.pt

The shipped int8 model (`export.py`) is onnxruntime's static quantisation of the convolutions
only, in QOperator form (`QLinearConv`), per tensor — the form tract runs in integer. Each
convolution, batch norm folded in, reads its input as uint8 and writes its output as uint8
(asymmetric, the range the min and max over the calibration images), with int8 weights
(symmetric, the range the largest weight). Applied after training, that rounding cost var21
to var25 0.07–0.13 mAP50-95 (`models/README.md`), and per-channel weights or a float head
won back only part of it.

Here every one of those convolutions runs through the same rounding while it trains (fake
quantisation, straight-through gradients): batch norm folded with its running statistics
(frozen, as at export), the folded weights rounded to int8 on their largest value, input and
output rounded to uint8 on ranges measured once, before training, over the same calibration
images the export uses. The DFL's fixed convolution is not in the exported graph (the runtime
decodes it in float) and is left alone. Ultralytics' own QAT (ModelOpt) quantises per channel
and exports Q/DQ nodes, which tract runs in float: not the model we ship.

`--per-channel` rounds the folded weights per output channel instead, as `export.py
--per-channel` writes them; from rt36 it did no better than per tensor (qat36 against qat36t,
`models/README.md`), and tract runs that form 2-3 times slower on the Pis.

`--strip` writes an ordinary Ultralytics checkpoint (the fake quantisation taken out, optimizer
state dropped) that keeps the ranges it trained through (`qat_ranges.py`): `export.py` makes
its fp32 file like any other's, and its int8 file on those ranges rather than ones measured
again on the trained weights.
"""

import argparse
import sys
import time
from pathlib import Path

import offline  # noqa: F401  (must come before ultralytics)
import torch
import torch.nn.functional as F
from torch import nn

import train as train_mod
from exact import ExactTrainer
from ultralytics.nn.modules import Conv

# The int8 model's integer ranges: activations uint8, weights int8 symmetric (onnxruntime
# quantises weights on [-127, 127]).
A_MIN, A_MAX = 0, 255
W_MAX = 127

# Where `--strip` keeps the ranges a run trained through, for `export.py` (`qat_ranges.py`):
# {module name: [in lo, in hi, out lo, out hi]}.
RANGES_KEY = "qat_ranges"


def fq_act(x: torch.Tensor, lo: float, hi: float) -> torch.Tensor:
    """`x` rounded as onnxruntime's uint8 activations on the range [lo, hi] (0 always inside)."""
    lo, hi = min(lo, 0.0), max(hi, 0.0)
    scale = max((hi - lo) / (A_MAX - A_MIN), 1e-8)
    zero = int(round(A_MIN - lo / scale))
    return torch.fake_quantize_per_tensor_affine(x, scale, zero, A_MIN, A_MAX)


def fq_weight(w: torch.Tensor, per_channel: bool = False) -> torch.Tensor:
    """`w` rounded as int8 on its largest magnitude (symmetric, zero point 0): per tensor, or
    per output channel as onnxruntime's `per_channel=True` quantises a convolution's weights."""
    if per_channel:
        scale = (w.detach().abs().amax(dim=(1, 2, 3)) / W_MAX).clamp(min=1e-12).float()
        zero = torch.zeros(w.shape[0], dtype=torch.int32, device=w.device)
        return torch.fake_quantize_per_channel_affine(w, scale, zero, 0, -W_MAX, W_MAX)
    scale = max(float(w.detach().abs().max()) / W_MAX, 1e-12)
    return torch.fake_quantize_per_tensor_affine(w, scale, 0, -W_MAX, W_MAX)


def folded(block: Conv) -> tuple[torch.Tensor, torch.Tensor]:
    """An Ultralytics `Conv` block's weights and bias with its batch norm folded in (running
    statistics, frozen), as the exported graph holds them."""
    bn = block.bn
    g = bn.weight / torch.sqrt(bn.running_var + bn.eps)
    return block.conv.weight * g.view(-1, 1, 1, 1), bn.bias - bn.running_mean * g


class QConv(Conv):
    """Ultralytics' Conv (conv, batch norm, SiLU) as the int8 export computes it."""

    per_channel = False  # weights rounded per output channel (`prepare` sets it per layer)

    def forward(self, x):
        conv = self.conv
        w, b = folded(self)
        r = self.q_range.tolist()
        y = F.conv2d(fq_act(x, r[0], r[1]), fq_weight(w, self.per_channel), b, conv.stride,
                     conv.padding, conv.dilation, conv.groups)
        return self.act(fq_act(y, r[2], r[3]))


class QConv2d(nn.Conv2d):
    """A bare convolution (the head's outputs) as the int8 export computes it."""

    per_channel = False

    def forward(self, x):
        r = self.q_range.tolist()
        y = F.conv2d(fq_act(x, r[0], r[1]), fq_weight(self.weight, self.per_channel), self.bias,
                     self.stride, self.padding, self.dilation, self.groups)
        return fq_act(y, r[2], r[3])


def quantised_layers(model: nn.Module, float_head: bool = False):
    """(name, module, output-producing module) of every convolution the int8 export quantises;
    `float_head`: not the head's bare output convolutions (`export.py --float-head`)."""
    for name, m in model.named_modules():
        if "dfl" in name:
            continue  # the DFL is decoded in float by the runtime, not in the graph
        if isinstance(m, Conv) and isinstance(getattr(m, "bn", None), nn.BatchNorm2d):
            yield name, m, m.bn
        elif type(m) is nn.Conv2d and not name.endswith(".conv") and not float_head:
            yield name, m, m  # a bare convolution, not the inside of a Conv block


def calibration_tensors(folder: Path, n: int) -> list[torch.Tensor]:
    """The first `n` PNGs of `folder` in name order, as `export.py` calibrates on them."""
    from export import png_tensor

    files = sorted(folder.glob("*.png"))[:n]
    if not files:
        raise SystemExit(f"no calibration PNGs in {folder}")
    return [torch.from_numpy(png_tensor(f)) for f in files]


@torch.no_grad()
def prepare(model: nn.Module, images: list[torch.Tensor], per_channel: bool = False,
            ranges: str = "max", float_head: bool = False) -> int:
    """Measures each quantised convolution's input and output range over `images` and turns it
    into its fake-quantised class, its weights rounded per tensor or per output channel.
    `ranges`: "max", the extremes over all the images (what onnxruntime's MinMax calibration
    measures), or "mean", the mean of each image's extremes (narrower: finer steps, more
    clipping). `float_head`: the head's output convolutions stay float. Returns how many
    layers were prepared."""
    layers = list(quantised_layers(model, float_head))
    per_image: dict[str, list[list[float]]] = {name: [] for name, _, _ in layers}
    hooks = []
    for name, m, out in layers:
        def on_in(mod, args, name=name):
            x = args[0]
            per_image[name].append([float(x.min()), float(x.max()), 0.0, 0.0])

        def on_out(mod, args, y, name=name):
            r = per_image[name][-1]
            r[2], r[3] = float(y.min()), float(y.max())

        hooks += [m.register_forward_pre_hook(on_in), out.register_forward_hook(on_out)]
    was = model.training
    model.eval()
    for x in images:
        model(x)
    for h in hooks:
        h.remove()
    model.train(was)
    for name, m, _ in layers:
        r = torch.tensor(per_image[name], dtype=torch.float32).reshape(-1, 4)
        lo = (r[:, 0::2].mean(0) if ranges == "mean" else r[:, 0::2].amin(0)).clamp(max=0.0)
        hi = (r[:, 1::2].mean(0) if ranges == "mean" else r[:, 1::2].amax(0)).clamp(min=0.0)
        # [in lo, in hi, out lo, out hi], zero always inside (as onnxruntime keeps it)
        m.register_buffer("q_range", torch.stack([lo[0], hi[0], lo[1], hi[1]]))
        m.__class__ = QConv if isinstance(m, Conv) else QConv2d
        m.per_channel = per_channel
    return len(layers)


def trained_ranges(model: nn.Module) -> dict[str, list[float]]:
    """The ranges each fake-quantised convolution of `model` rounds on, by module name."""
    return {name: m.q_range.tolist() for name, m in model.named_modules()
            if isinstance(m, (QConv, QConv2d))}


def strip(model: nn.Module) -> int:
    """Takes the fake quantisation out again (the classes and their ranges). Returns a count."""
    n = 0
    for m in model.modules():
        if isinstance(m, (QConv, QConv2d)):
            m.__class__ = Conv if isinstance(m, QConv) else nn.Conv2d
            del m.q_range
            m.__dict__.pop("per_channel", None)
            n += 1
    return n


class QATTrainer(ExactTrainer):
    """The exact-shape trainer whose model trains through the int8 rounding."""

    calib: list[torch.Tensor] = []
    per_channel = False
    ranges = "max"
    float_head = False

    def get_model(self, cfg=None, weights=None, verbose=True):
        model = super().get_model(cfg, weights, verbose)
        n = prepare(model, self.calib, self.per_channel, self.ranges, self.float_head)
        form = "per channel" if self.per_channel else "per tensor"
        print(f"qat: {n} convolutions fake-quantised ({form} weights) on {len(self.calib)} "
              "calibration images")
        return model


def strip_checkpoint(src: Path, dst: Path) -> None:
    ckpt = torch.load(str(src), map_location="cpu", weights_only=False)
    model = ckpt.get("ema") or ckpt["model"]
    ranges = trained_ranges(model)
    n = strip(model.float())
    ckpt.update(model=model.half(), ema=None, optimizer=None, updates=None,
                train_results=None)
    ckpt[RANGES_KEY] = ranges  # the ranges it trained through, for export.py
    torch.save(ckpt, str(dst))
    print(f"wrote {dst}: {n} layers back to float convolutions, their ranges kept")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data")
    ap.add_argument("--init", type=Path, help="the float checkpoint to fine-tune")
    ap.add_argument("--calib", type=Path, help="folder of training PNGs (export.py's)")
    ap.add_argument("--calib-images", type=int, default=256)
    ap.add_argument("--per-channel", action="store_true",
                    help="round weights per output channel (export with `export.py --per-channel`)")
    ap.add_argument("--ranges", choices=("max", "mean"), default="max",
                    help="activation ranges: extremes over the calibration images, or the mean "
                    "of each image's")
    ap.add_argument("--float-head", action="store_true",
                    help="leave the head's six output convolutions float (export with "
                    "`export.py --float-head`)")
    ap.add_argument("--epochs", type=int, default=2)
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--lr0", type=float, default=1e-4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--name", default="qat")
    ap.add_argument("--resume", action="store_true",
                    help="continue runs/NAME/weights/last.pt (the ranges are measured again, "
                    "on its weights)")
    ap.add_argument("--strip", nargs=2, type=Path, metavar=("IN", "OUT"),
                    help="write IN as an ordinary checkpoint OUT and stop")
    a = ap.parse_args()
    # The classes from the module `qat`, not `__main__`: the checkpoints pickle (and are
    # compared against) those.
    import qat

    if a.strip:
        qat.strip_checkpoint(*a.strip)
        return
    if not (a.data and (a.init or a.resume) and a.calib):
        ap.error("--data, --init (or --resume) and --calib are needed to train")
    qat.QATTrainer.calib = calibration_tensors(a.calib, a.calib_images)
    qat.QATTrainer.per_channel = a.per_channel
    qat.QATTrainer.ranges = a.ranges
    qat.QATTrainer.float_head = a.float_head
    t0 = time.time()
    w = train_mod.train(Path(a.data), a.epochs, a.batch, a.seed, a.device, a.workers, a.name,
                        a.resume, init=a.init, lr0=a.lr0, trainer=qat.QATTrainer)
    print(f"trained in {time.time() - t0:.0f} s: {w}", file=sys.stderr)


if __name__ == "__main__":
    main()
