"""Quick look at the world model on the simulator's recordings (held-out seed): per frame,
reported `objects` (tracks) against the frame's `detections` (what `objects` was before), each
scored against the recording's truth: right (a true object of the same class within 0.3 m),
wrong class (a true object of another class within 0.3 m), phantom (none within 0.3 m); and
how often a track id moves to another true object. Not the issue's evaluator (that is
`umbra-lab eval-world`, to come): our own simulator only, which tuned the methods.

    printf '[world]\nenabled = true\n' > world.toml
    umbra-sim dataset --out DATASET_DIR --scenarios 12 --frames 100 --seed 78 --no-images --no-method-a --pictures 0
    python3 lab/scripts/quick_world.py DATASET_DIR UMBRA_BINARY world.toml
"""
import json, math, subprocess, sys
from pathlib import Path

ds, umbra, config = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
tot = {k: {"right": 0, "wrong": 0, "phantom": 0} for k in ("objects", "detections")}
frames = 0
switches = pairs = 0
for rec in sorted((ds / "recordings").iterdir()):
    out = subprocess.run([umbra, "replay", str(rec / "capture.bin"), "--odom", str(rec / "odom.jsonl"),
                          "--jsonl", "-", "--quiet", "--config", config], capture_output=True, text=True, check=True).stdout
    lines = [json.loads(l) for l in out.splitlines() if l.startswith("{")]
    truth = [json.loads(l) for l in (rec / "truth.jsonl").read_text().splitlines()]
    last_match = {}
    for line, t in list(zip(lines, truth))[10:]:
        frames += 1
        gt = t["objects"] + [dict(o, **{"class": "door_frame"}) for o in t.get("doors", [])]
        for key in ("objects", "detections"):
            for o in line[key]:
                near = [(math.hypot(g["x"] - o["x"], g["y"] - o["y"]), g) for g in gt]
                near = [n for n in near if n[0] <= 0.3]
                if not near:
                    tot[key]["phantom"] += 1
                    continue
                g = min(near, key=lambda n: n[0])[1]
                tot[key]["right" if g["class"] == o["class"] else "wrong"] += 1
                if key == "objects":
                    gid = (g["class"], g.get("id", (g["x"], g["y"])))
                    if o["id"] in last_match:
                        pairs += 1
                        switches += last_match[o["id"]] != gid
                    last_match[o["id"]] = gid
for key, v in tot.items():
    print(f"{key:10s} per frame: right {v['right']/frames:.2f}, wrong class {v['wrong']/frames:.2f}, "
          f"phantom {v['phantom']/frames:.2f}")
print(f"{frames} frames; track ids that moved to another true object: {switches}/{pairs} consecutive sightings")
