#!/usr/bin/env python3
"""The peer of `cargo bench -p umbra-bench --bench method_b`: onnxruntime on the same ONNX file
and the same input tensor, one thread, all graph optimisations on.

Usage: yolo_peer.py MODEL.onnx INPUT.f32 [TRACT_OUTPUT.f32]
  -> prints `ort_ms <median of 100> max_abs_diff <vs tract's output, or nan>`.
INPUT.f32 is the raw little-endian 1x3x64x384 tensor, TRACT_OUTPUT.f32 tract's 1x8x504 output
for it. Needs numpy and onnxruntime (`pip install onnxruntime`); not part of the build or tests.
"""
import sys
import time

import numpy as np
import onnxruntime as ort


def main() -> None:
    so = ort.SessionOptions()
    so.intra_op_num_threads = 1
    so.inter_op_num_threads = 1
    so.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    so.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    sess = ort.InferenceSession(sys.argv[1], so, providers=["CPUExecutionProvider"])
    x = np.fromfile(sys.argv[2], dtype="<f4").reshape(1, 3, 64, 384)
    name = sess.get_inputs()[0].name
    for _ in range(10):
        out = sess.run(None, {name: x})[0]
    times = []
    for _ in range(100):
        t0 = time.perf_counter()
        out = sess.run(None, {name: x})[0]
        times.append(time.perf_counter() - t0)
    diff = float("nan")
    if len(sys.argv) > 3:
        ref = np.fromfile(sys.argv[3], dtype="<f4").reshape(out.shape)
        diff = float(np.abs(ref - out).max())
    print(f"ort_ms {1e3 * float(np.median(times)):.4f} max_abs_diff {diff:.3g} "
          f"onnxruntime {ort.__version__}")


if __name__ == "__main__":
    main()
