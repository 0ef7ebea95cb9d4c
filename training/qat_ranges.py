"""The activation ranges a quantisation-aware run trained through, carried into its int8 file.

`qat.py` measures each quantised convolution's input and output range once, before training,
and the network then learns through rounding on those ranges. The weights move while it
trains, so the ranges `export.py` would measure again on the trained float weights are not
the ones it learnt with: from rn45 (models/README.md, qat45) some layers' ranges came out
twice as wide, and the int8 file lost 0.13 mAP50-95 that the fake quantisation had not. So
`qat.py --strip` keeps the ranges in the checkpoint (`qat.RANGES_KEY`), and `export.py` hands
them to onnxruntime's quantiser as overrides (`overrides`), each on the ONNX tensors of the
convolution it belongs to. Convolutions are matched by their weights (batch norm folded in,
as both the export and the fake quantisation fold it), not by name, since the exported
graph's node names do not follow the module tree one to one.
"""

import numpy as np
import torch
from onnx import numpy_helper

import qat


@torch.no_grad()
def folded_weight(module) -> np.ndarray:
    """A quantised convolution's weights as the exported graph holds them: an Ultralytics
    `Conv` block's with its batch norm folded in (`qat.folded`), a bare one's as they are."""
    w = qat.folded(module)[0] if getattr(module, "bn", None) is not None else module.weight
    return w.float().numpy()


def head_outputs(graph) -> list[str]:
    """Names of the convolutions no activation follows: the detection head's outputs (every
    other convolution of the graph is an Ultralytics `Conv` block's, a SiLU after it)."""
    activated = {n.input[0] for n in graph.node if n.op_type == "Sigmoid"}
    return [n.name for n in graph.node if n.op_type == "Conv" and n.output[0] not in activated]


def kept(checkpoint) -> tuple[dict, object]:
    """The ranges a quantisation-aware run kept in `checkpoint` (a path) and its model (float),
    loaded once for `trained_float_head` and `overrides`; `({}, None)` when it kept none (not
    from a quantisation-aware run)."""
    ckpt = torch.load(str(checkpoint), map_location="cpu", weights_only=False)
    ranges = ckpt.get(qat.RANGES_KEY)
    if not ranges:
        return {}, None
    return ranges, (ckpt.get("ema") or ckpt["model"]).float()


def trained_float_head(trained: tuple[dict, object]) -> bool:
    """Whether a checkpoint (`kept`'s answer) is from a quantisation-aware run that left the
    head's output convolutions float (`qat.py --float-head`): it has ranges, and none of them is
    a bare convolution's (`qat.quantised_layers`), so its int8 file must leave those float too.
    `export.py` reads it so that no flag has to be repeated, in `make_model.py` or by hand."""
    ranges, model = trained
    if not ranges:
        return False
    body = {name for name, _, _ in qat.quantised_layers(model, float_head=True)}
    bare = {name for name, _, _ in qat.quantised_layers(model)} - body
    return bool(body & set(ranges)) and not bare & set(ranges)


def overrides(trained: tuple[dict, object], graph, skip: tuple[str, ...] = ()) -> dict:
    """onnxruntime's `TensorQuantOverrides` for the ONNX `graph` from the ranges a checkpoint
    kept (`kept`'s answer): `{tensor: [{"rmin": lo, "rmax": hi}]}` for every convolution's
    input and output, but those named in `skip` (left float). Empty when the checkpoint has
    none (not from a quantisation-aware run). A convolution of the graph with no layer whose
    weights match raises, as does a layer matched twice: the ranges would be put on the wrong
    tensors."""
    ranges, model = trained
    if not ranges:
        return {}
    layers = {name: folded_weight(m) for name, m in model.named_modules() if name in ranges}
    inits = {i.name: i for i in graph.initializer}
    out: dict = {}
    used: set = set()

    def widen(tensor: str, lo: float, hi: float) -> None:
        # A tensor read by two convolutions (the head's two branches) has one range.
        if tensor in out:
            lo, hi = min(lo, out[tensor][0]["rmin"]), max(hi, out[tensor][0]["rmax"])
        out[tensor] = [{"rmin": np.float32(lo), "rmax": np.float32(hi)}]

    for node in graph.node:
        if node.op_type != "Conv" or node.input[1] not in inits or node.name in skip:
            continue
        w = numpy_helper.to_array(inits[node.input[1]]).astype(np.float32)
        best, err = None, np.inf
        for name, lw in layers.items():
            if lw.shape == w.shape:
                e = float(np.abs(lw - w).max() / (np.abs(w).max() + 1e-12))
                if e < err:
                    best, err = name, e
        if best is None or err > 1e-3:
            raise SystemExit(f"qat ranges: no layer matches {node.name} (best {best}, {err:.2g})")
        if best in used:
            raise SystemExit(f"qat ranges: {best} matches two convolutions")
        used.add(best)
        r = ranges[best]
        widen(node.input[0], r[0], r[1])
        widen(node.output[0], r[2], r[3])
    return out
