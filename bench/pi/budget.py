#!/usr/bin/env python3
"""Count each frame stage's instructions on the Pis' instruction sets under qemu, and project
the stage times on a Pi 5 and a Pi 3 (docs/pi-budget.md says how and how far to trust it).

    python3 bench/pi/budget.py [--frames 3,13] [--json OUT.json] [--int8 MODEL.onnx]

Needs gcc, qemu-user (qemu-aarch64, qemu-arm) and the cross-built static binaries of the CI's
cross stage (target/<triple>/release/umbra, features method-b). For every board it runs
`umbra run --speed max --quiet` on the simulated robot with each stage set switched on in turn
(none, Method A, Method B, Method B with the int8 file, both; deadlines relaxed so that no stage is ever skipped) under
`qemu-<arch> -cpu <core> -plugin libinsn.so` (`insn.c`), at two frame counts: the difference
divided by the frames between is one steady-state frame, start-up (model loading, tract's
optimisation) cancelling out. A stage is its set's count less the "none" run's (the simulator,
LiDAR decoding, pose, world model and output, reported as "base").

With `--check BASELINE.json` it fails (exit 1) when a stage's count on any board is more than
`--tolerance` (15 %) above the recorded one, or below half of it (a stage that stopped running);
`.ci/run cross` runs it so that a slower export or kernel choice fails loudly (counts are
deterministic, unlike times on a shared machine). `--update BASELINE.json` records new counts.

Only the standard library: runs with any python3.
"""

import argparse
import concurrent.futures
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# (board, qemu, -cpu model, target triple, clock GHz, environment). The Pi 3 on its 32-bit OS
# runs the A53 in AArch32; qemu-arm's cortex-a15 is the ARMv7-A core with the NEON/VFPv4 that
# tract's armv7 kernels need (qemu-arm has no AArch32 A53 model). qemu 7.2 hands the guest the
# host's /proc/cpuinfo, where tract reads the CPU part and (armv7) NEON: the environment tells
# tract what the real board's /proc/cpuinfo would (a Pi 5's A76, part 0xd0b, is tract's
# "generic" kind as it is here; a Pi 3's A53, part 0xd03, its "a53" kind; armv7 NEON is there).
# Dot-product (int8) and other features come from the emulated core's HWCAP, as on the board.
BOARDS = [
    ("Pi 5 (A76, 64-bit)", "qemu-aarch64", "cortex-a76", "aarch64-unknown-linux-gnu", 2.4, {}),
    ("Pi 3 (A53, 64-bit OS)", "qemu-aarch64", "cortex-a53", "aarch64-unknown-linux-gnu", 1.2,
     {"TRACT_CPU_AARCH64_KIND": "a53"}),
    ("Pi 3 (A53, 32-bit OS)", "qemu-arm", "cortex-a15", "armv7-unknown-linux-gnueabihf", 1.2,
     {"TRACT_CPU_ARM32_NEON": "true"}),
]

# Instructions per cycle assumed for each core on this code, low and high (docs/pi-budget.md).
IPC = {"cortex-a76": (1.2, 2.4), "cortex-a53": (0.35, 0.9), "cortex-a15": (0.35, 0.9)}

# Stage sets: (Method A on, Method B on, Method B's model file or None for the compiled-in fp32).
INT8 = ROOT / "models" / "yolo" / "umbra-yolov8n-int8.onnx"
SETS = {"none": (False, False, None), "a": (True, False, None), "b": (False, True, None),
        "ab": (True, True, None), "b_int8": (False, True, INT8)}
# The stages reported, each the steady count of a set less the "none" set's ("base": none's own).
STAGES = {"base": "none", "method_a": "a", "method_b": "b", "method_b_int8": "b_int8",
          "both": "ab"}

CONFIG = """# bench/pi/budget.py: no deadline pressure, so every stage runs every frame.
[runtime]
deadline_ms = 10000

[runtime.budget_ms]
ingest = 1000
pose = 1000
method_a = 3000
method_b = 4000
output = 1000

[method_a]
enabled = {a}

[method_b]
enabled = {b}
{model}"""


def umbra(triple: str) -> Path:
    """The cross-built static binary for `triple`."""
    return ROOT / "target" / triple / "release" / "umbra"


def plugin(work: Path) -> Path:
    so = work / "libinsn.so"
    subprocess.run(["gcc", "-shared", "-fPIC", "-O2", "-o", str(so),
                    str(Path(__file__).with_name("insn.c"))], check=True)
    return so


def loads_plugin(qemu: str, so: Path, binary: Path, out: Path) -> bool:
    """Whether `qemu` runs `binary --version` with the plugin and the plugin counts."""
    r = subprocess.run([qemu, "-plugin", str(so), str(binary), "--version"],
                       env=dict(os.environ, INSN_OUT=str(out)), stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, check=False)
    return r.returncode == 0 and out.exists() and "insns " in out.read_text()


def count(qemu: str, cpu: str, board_env: dict, so: Path, binary: Path, config: Path,
          frames: int, out: Path) -> int:
    out.unlink(missing_ok=True)
    env = dict(os.environ, INSN_OUT=str(out), **board_env)
    cmd = [qemu, "-cpu", cpu, "-plugin", str(so), str(binary), "run", "--speed", "max",
           "--quiet", "--frames", str(frames), "--config", str(config)]
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    # qemu may call the plugin's exit hook more than once (a thread's exit, then the
    # process's); the last and largest count is the whole run's.
    return max(int(line.split()[1]) for line in out.read_text().splitlines()
               if line.startswith("insns "))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", default="3,13", help="the two frame counts (Method B starts "
                    "at the third frame: both must be at least 3)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--check", type=Path, metavar="BASELINE.json")
    ap.add_argument("--update", type=Path, metavar="BASELINE.json")
    ap.add_argument("--tolerance", type=float, default=0.15)
    ap.add_argument("--int8", type=Path, metavar="MODEL.onnx",
                    help="count this file for the int8 stage instead of the shipped one")
    a = ap.parse_args()
    sets = {**SETS, "b_int8": (False, True, a.int8.resolve())} if a.int8 else SETS
    f0, f1 = (int(x) for x in a.frames.split(","))
    if not 3 <= f0 < f1:
        sys.exit("--frames: need 3 <= first < second")
    work = Path(tempfile.mkdtemp(prefix="umbra-pi-budget-"))
    so = plugin(work)
    probe = umbra(BOARDS[0][3])
    if probe.exists() and not loads_plugin(BOARDS[0][1], so, probe, work / "probe.txt"):
        # A QEMU whose plugin API no longer takes version 1 (QEMU >= 9): say so, do not fail.
        print(f"skipped: {BOARDS[0][1]} cannot load the counting plugin (insn.c is written "
              "for QEMU 7.2's plugin API version 1)")
        return
    configs = {}
    for name, (ma, mb, model) in sets.items():
        configs[name] = work / f"{name}.toml"
        configs[name].write_text(CONFIG.format(a=str(ma).lower(), b=str(mb).lower(),
                                               model=f'model = "{model}"\n' if model else ""))
    jobs = {}
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        for board, qemu, cpu, triple, _, board_env in BOARDS:
            binary = umbra(triple)
            if not binary.exists():
                sys.exit(f"{binary}: build it first (.ci/run cross)")
            for s in sets:
                for n in (f0, f1):
                    out = work / f"{cpu}-{triple}-{s}-{n}.txt"
                    jobs[(board, s, n)] = pool.submit(count, qemu, cpu, board_env, so,
                                                      binary, configs[s], n, out)
    per_frame = {}
    for board, *_ in BOARDS:
        steady = {s: (jobs[(board, s, f1)].result() - jobs[(board, s, f0)].result()) / (f1 - f0)
                  for s in sets}
        per_frame[board] = {
            stage: steady[s] - (steady["none"] if s != "none" else 0.0)
            for stage, s in STAGES.items()
        }
        per_frame[board]["startup_b"] = jobs[(board, "b", f0)].result() - f0 * steady["b"]
    print("| board | stage | M instructions / frame | projected ms (IPC low–high) |")
    print("|---|---|---|---|")
    rows = []
    for board, _, cpu, _, ghz, _ in BOARDS:
        lo, hi = IPC[cpu]
        for stage in STAGES:
            n = per_frame[board][stage]
            slow, fast = n / (lo * ghz * 1e6), n / (hi * ghz * 1e6)
            rows.append(dict(board=board, stage=stage, instructions=n, ms_low_ipc=slow,
                             ms_high_ipc=fast, ghz=ghz, ipc=[lo, hi]))
            print(f"| {board} | {stage} | {n / 1e6:.1f} | {fast:.0f}–{slow:.0f} |")
        print(f"| {board} | Method B start-up (once) | "
              f"{per_frame[board]['startup_b'] / 1e6:.0f} | |")
    if a.json:
        a.json.write_text(json.dumps(dict(frames=[f0, f1], rows=rows, raw={
            f"{b}|{s}|{n}": j.result() for (b, s, n), j in jobs.items()}), indent=1))
    counts = {b: {k: round(v) for k, v in st.items() if k != "startup_b"}
              for b, st in per_frame.items()}
    if a.update:
        a.update.write_text(json.dumps(counts, indent=1) + "\n")
    if a.check:
        sys.exit(check(json.loads(a.check.read_text()), counts, a.tolerance))


def check(baseline: dict, counts: dict, tolerance: float) -> int:
    """1 when a stage's count left [0.5, 1 + tolerance] of its baseline, else 0."""
    bad = 0
    for board, stages in baseline.items():
        for stage, want in stages.items():
            got = counts.get(board, {}).get(stage)
            if got is None or want < 1e5:
                continue  # a board not run, or a stage too small to judge
            ratio = got / want
            ok = 0.5 <= ratio <= 1 + tolerance
            bad |= not ok
            print(f"{'ok ' if ok else 'BAD'} {board} {stage}: {got / 1e6:.1f} M instructions, "
                  f"{ratio:.2f} x the baseline's {want / 1e6:.1f} M")
    return int(bad)


if __name__ == "__main__":
    main()
