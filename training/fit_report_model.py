#!/usr/bin/env python3
"""Fits the world model's report model and writes it into `models/src/report_model.rs`.

The report model (`perception/src/tracks/report_model.rs`) is a logistic model of how likely
a track that earned its report is a phantom, from the features `umbra --track-log` writes for
every such track in every frame. Its labels come from the runs' truth, by the rule the
evaluation counts phantoms with (`umbra-lab eval-world`): a piece of furniture is a phantom
in a frame when no piece stood within 0.3 m of its centre (the footprint's edge) in that frame.
Door frames are left out: the map's walls judge them.

Fit on the tuning seeds only, never on the held-out ones (9001-9003) or the annex:

    umbra-lab eval-world --family sim --world on --seed S --track-logs --dir runs/sim-S ...
    python training/fit_report_model.py runs/sim-4242 runs/varied-4242 ... \
        --out models/src/report_model.rs

The fit is plain Newton steps on the L2-penalised log-likelihood over standardised features
(numpy only, deterministic); the standardisation is folded into the weights written out. A
cross-check holds each seed's runs out in turn (the directories' names end in the seed) and
prints the share of phantom and of real track-frames each threshold would hold back.
"""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

import numpy as np

PIECE = re.compile(
    r"furniture (\d+) \(piece (\d+)\): (\w+) (.*?) at \(([-\d.]+), ([-\d.]+)\), "
    r"frames (\d+)\.\.(\w+), (\d+) returns, footprint (.*)"
)
POINT = re.compile(r"\(([-\d.]+), ([-\d.]+)\)")
# The evaluation's reach: a detection within this of a piece's footprint stands on it, m.
ON_PIECE_M = 0.3
# Frames after a piece leaves during which a report of it is not yet a phantom.
LEAVE_GRACE = 10


def edge_distance(poly: list[tuple[float, float]], x: float, y: float) -> float:
    """Distance from (x, y) to the polygon (0 inside)."""
    inside, best, n = False, math.inf, len(poly)
    for i in range(n):
        (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < (x2 - x1) * (y - y1) / (y2 - y1) + x1:
            inside = not inside
        dx, dy = x2 - x1, y2 - y1
        ll = dx * dx + dy * dy
        t = max(0.0, min(1.0, ((x - x1) * dx + (y - y1) * dy) / ll)) if ll else 0.0
        best = min(best, math.hypot(x - x1 - t * dx, y - y1 - t * dy))
    return 0.0 if inside else best


def pieces(truth: Path) -> list[tuple[list[tuple[float, float]], int, float]]:
    """Each piece's footprint and the frames it stood there."""
    out = []
    for line in truth.read_text().splitlines()[1:]:
        m = PIECE.match(line)
        if m:
            fp = [(float(a), float(b)) for a, b in POINT.findall(m.group(10))]
            end = math.inf if m.group(8) == "end" else int(m.group(8))
            out.append((fp, int(m.group(7)), end))
    return out


def read_run(run: Path) -> tuple[list[str], np.ndarray, np.ndarray]:
    """A run's furniture track-frames: feature names, features, labels (1 = phantom)."""
    lines = (run / "tracks.txt").read_text().splitlines()
    names = lines[0].lstrip("# ").split()[6:]
    truth = pieces(run / "truth.txt")
    rows, labels = [], []
    for line in lines[1:]:
        c = line.split()
        if len(c) != 6 + len(names) or c[2] == "door_frame":
            continue
        frame, x, y = int(c[0]), float(c[3]), float(c[4])
        on = any(
            a <= frame < b + LEAVE_GRACE and edge_distance(fp, x, y) <= ON_PIECE_M
            for fp, a, b in truth
        )
        rows.append([float(v) for v in c[6:]])
        labels.append(0 if on else 1)
    return names, np.array(rows, dtype=np.float64).reshape(-1, len(names)), np.array(labels)


def fit(x: np.ndarray, y: np.ndarray, l2: float) -> tuple[np.ndarray, float, np.ndarray, np.ndarray]:
    """Penalised logistic regression on standardised features (Newton steps)."""
    mean = x.mean(axis=0)
    scale = x.std(axis=0)
    scale[scale < 1e-6] = 1.0
    z = np.hstack([(x - mean) / scale, np.ones((len(x), 1))])
    w = np.zeros(z.shape[1])
    pen = np.full(z.shape[1], l2)
    pen[-1] = 0.0
    for _ in range(50):
        p = 1.0 / (1.0 + np.exp(-np.clip(z @ w, -30, 30)))
        grad = z.T @ (p - y) + pen * w
        hess = (z * (p * (1 - p))[:, None]).T @ z + np.diag(pen + 1e-9)
        step = np.linalg.solve(hess, grad)
        w -= step
        if np.abs(step).max() < 1e-8:
            break
    return w[:-1], float(w[-1]), mean, scale


def raw_weights(w: np.ndarray, b: float, mean: np.ndarray, scale: np.ndarray) -> tuple[np.ndarray, float]:
    """The standardisation folded into the weights: the same model on raw features."""
    return w / scale, b - float((w * mean / scale).sum())


def prob(x: np.ndarray, w: np.ndarray, b: float) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.clip(x @ w + b, -30, 30)))


def f32(v: float) -> str:
    """The shortest literal that reads back as the same f32."""
    return np.format_float_scientific(np.float32(v), unique=True, exp_digits=1).replace(".e", ".0e")


def rust(w: np.ndarray, b: float, threshold: float, max_hits: int, names: list[str],
         note: str) -> str:
    weights = "\n".join(f"        {f32(v)}, // {n}" for v, n in zip(w, names))
    return f"""//! The report model compiled into umbra (`perception::tracks::ReportModel`), generated by
//! `training/fit_report_model.py`; do not edit by hand.
//! {note}

use perception::tracks::ReportModel;

/// The fitted model.
pub const REPORT_MODEL: Option<ReportModel> = Some(ReportModel {{
    weights: [
{weights}
    ],
    bias: {f32(b)},
    threshold: {threshold},
    max_hits: {max_hits},
}});
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs", nargs="+", type=Path, help="eval-world --dir folders (--track-logs)")
    ap.add_argument("--out", type=Path, help="write the Rust module here")
    ap.add_argument("--threshold", type=float, default=0.5)
    ap.add_argument("--l2", type=float, default=1.0)
    ap.add_argument("--max-hits", type=int, default=50,
                    help="the model judges tracks with fewer hits only (and is fitted on them)")
    ap.add_argument("--drop", default="", help="features left out (weight 0), comma-separated")
    a = ap.parse_args()
    names, xs, ys, groups = None, [], [], []
    for d in a.dirs:
        seed = re.search(r"(\d+)$", d.name)
        for run in sorted(p for p in d.iterdir() if (p / "tracks.txt").exists()):
            names, x, y = read_run(run)
            xs.append(x)
            ys.append(y)
            groups.append(np.full(len(y), int(seed.group(1)) if seed else 0))
    if not xs:
        raise SystemExit("no tracks.txt under the folders given (eval-world --track-logs)")
    x, y, g = np.vstack(xs), np.concatenate(ys), np.concatenate(groups)
    dropped = [n for n in a.drop.split(",") if n]
    unknown = [n for n in dropped if n not in names]
    if unknown:
        raise SystemExit(f"--drop: no feature {unknown}; the features are {names}")
    x[:, [names.index(n) for n in dropped]] = 0.0
    print(f"{len(y)} track-frames, {int(y.sum())} phantom ({y.mean():.3f})")
    young = np.expm1(x[:, names.index("ln_hits")]) < a.max_hits - 0.5
    x, y, g = x[young], y[young], g[young]
    print(f"{len(y)} of them with fewer than {a.max_hits} hits, {int(y.sum())} phantom")
    held = np.zeros(len(y))
    seeds = sorted(set(g.tolist()))
    for s in seeds if len(seeds) > 1 else []:
        te = g == s
        w, b, mean, scale = fit(x[~te], y[~te], a.l2)
        held[te] = prob(x[te], *raw_weights(w, b, mean, scale))
    if len(seeds) > 1:
        print("each seed held out in turn: share held back at a phantom probability of")
        for t in (0.3, 0.4, 0.5, 0.6, 0.7):
            v = held >= t
            print(f"  {t:.1f}: phantoms {v[y == 1].mean():.3f}, real {v[y == 0].mean():.4f}")
    w, b, mean, scale = fit(x, y, a.l2)
    for n, v in sorted(zip(names, w), key=lambda t: -abs(t[1]))[:8]:
        print(f"  {n:14s} {v:+.2f} (standardised)")
    rw, rb = raw_weights(w, b, mean, scale)
    if a.out:
        note = (f"Fitted on {len(y)} track-frames ({int(y.sum())} phantom) of "
                f"{len(a.dirs)} tuning folders, L2 {a.l2}.")
        a.out.write_text(rust(rw, rb, a.threshold, a.max_hits, names, note))
        print("wrote", a.out)


if __name__ == "__main__":
    main()
