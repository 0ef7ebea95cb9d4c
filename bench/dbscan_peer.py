#!/usr/bin/env python3
"""The peer of `cargo bench -p umbra-bench --bench method_a`: scikit-learn's DBSCAN on the
same cloud (the study's Python pipeline clustered with it), one thread, eps 0.15 m (what the
study's adaptive rule gives on a dense cloud) and min_samples 10.

Usage: dbscan_peer.py CLOUD.csv  ->  prints `sklearn_dbscan_ms <median> clusters <n>`.
Needs numpy and scikit-learn (`pip install scikit-learn`); not part of the build or tests.
"""
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from sklearn.cluster import DBSCAN


def main() -> None:
    pts = np.loadtxt(sys.argv[1], delimiter=",", dtype=np.float64)
    times = []
    labels = None
    for _ in range(30):
        t0 = time.perf_counter()
        labels = DBSCAN(eps=0.15, min_samples=10, n_jobs=1).fit(pts).labels_
        times.append(time.perf_counter() - t0)
    n = len(set(labels.tolist()) - {-1})
    print(f"sklearn_dbscan_ms {1e3 * float(np.median(times)):.4f} clusters {n} points {len(pts)}")


if __name__ == "__main__":
    main()
