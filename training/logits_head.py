"""Cut an exported YOLOv8 ONNX graph before its box decoding: the runtime's "logits head".

    python training/logits_head.py IN.onnx OUT.onnx

Ultralytics' export ends its detection head with the DFL (a softmax over 16 bins per box side,
then their expectation), the anchor arithmetic and the class sigmoids, giving `1 x 8 x 504`.
tract runs that softmax on a non-trailing axis through its slow generic path: 29 % of the
whole model's time for 4 x 16 x 504 values (docs/method-b.md). The cut graph outputs the head's
raw `1 x 68 x 504` instead: rows 0-63 the box-side bins (side-major: left, top, right, bottom,
16 bins each), rows 64-67 the class logits. `perception::yolo::decode` takes the expectation
and the sigmoid itself, and only for the anchors it keeps. Works on the fp32 and the int8
(QOperator) files alike: both keep the head's tail in float.
"""

import argparse
import sys
from pathlib import Path

import onnx
from onnx import helper

OUTPUT = "logits"


def producer(graph: onnx.GraphProto, name: str) -> onnx.NodeProto:
    for n in graph.node:
        if name in n.output:
            return n
    raise ValueError(f"no node produces {name}")


def cut(src: Path, dst: Path) -> None:
    """Writes `src` with its output replaced by the head's box bins and class logits."""
    model = onnx.load(str(src))
    g = model.graph
    if len(g.output) != 1:
        raise ValueError(f"{src}: expected one output, found {len(g.output)}")
    if g.output[0].name == OUTPUT:
        raise ValueError(f"{src}: already a logits head")
    softmax = [n for n in g.node if n.op_type == "Softmax"]
    if len(softmax) != 1:
        raise ValueError(f"{src}: expected one Softmax (the DFL), found {len(softmax)}")
    # Softmax <- Transpose <- Reshape(1, 4, 16, A) <- the head's (1, 64, A) box bins.
    transpose = producer(g, softmax[0].input[0])
    reshape = producer(g, transpose.input[0])
    if (transpose.op_type, reshape.op_type) != ("Transpose", "Reshape"):
        raise ValueError(f"{src}: the DFL is not Reshape -> Transpose -> Softmax")
    bins = reshape.input[0]
    # The output Concat's second input is the class sigmoid; its input the class logits.
    last = producer(g, g.output[0].name)
    sigmoid = producer(g, last.input[1])
    if (last.op_type, sigmoid.op_type) != ("Concat", "Sigmoid"):
        raise ValueError(f"{src}: the output is not Concat(boxes, Sigmoid(classes))")
    classes = sigmoid.input[0]
    g.node.append(helper.make_node("Concat", [bins, classes], [OUTPUT], axis=1,
                                   name="/umbra/logits"))
    dims = [d.dim_value for d in g.output[0].type.tensor_type.shape.dim]
    rows = 64 + dims[1] - 4
    del g.output[:]
    g.output.append(helper.make_tensor_value_info(OUTPUT, onnx.TensorProto.FLOAT,
                                                  [dims[0], rows, dims[2]]))
    # Drop what no longer reaches the output (the DFL, anchors, sigmoid), in graph order.
    needed, keep = {OUTPUT}, []
    for n in reversed(g.node):
        if any(o in needed for o in n.output):
            keep.append(n)
            needed.update(i for i in n.input if i)
    kept = list(reversed(keep))
    del g.node[:]
    g.node.extend(kept)
    used = set(needed)
    inits = [t for t in g.initializer if t.name in used]
    del g.initializer[:]
    g.initializer.extend(inits)
    vis = [v for v in g.value_info if v.name in used]
    del g.value_info[:]
    g.value_info.extend(vis)
    onnx.checker.check_model(model)
    onnx.save(model, str(dst))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("src", type=Path)
    ap.add_argument("dst", type=Path)
    a = ap.parse_args()
    cut(a.src, a.dst)
    print(f"wrote {a.dst}", file=sys.stderr)


if __name__ == "__main__":
    main()
