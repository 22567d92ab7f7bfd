#!/usr/bin/env python3
"""The thesis' CPU-against-GPU figure, redone (issue 19, docs/gpu-physics.md).

  bench/gpu_thesis_comparison.py [--simgrass PATH] [--ticks N] [--repeats R] [--scalar fx32|fx16] [--json]

For the thesis' particle counts (22,801 / 62,500 / 122,500 / 250,000: meadows of 151, 250, 350 and
500 tufts a side, one particle each), runs `simgrass run --json` on the CPU (1 and 2 threads), on
the device with the particles resident (`--physics gpu`) and with the thesis' upload-step-readback
design (`--physics gpu-readback`), interleaved: every repetition runs each configuration once, in
turn, so a change in the machine's load touches all of them alike. Prints the median ms per tick
of each with its spread (min-max over the repetitions), the readback's share of the readback
path's tick ((readback - resident) / readback) and the device that ran (on this project's
machines, llvmpipe: a CPU rasteriser, not a GPU), and the load average before and after.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

SIDES = [151, 250, 350, 500]
CONFIGS = [("cpu, 1 thread", "cpu", 1), ("cpu, 2 threads", "cpu", 2), ("gpu (resident)", "gpu", 1),
           ("gpu-readback", "gpu-readback", 1)]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--simgrass", default=os.path.join(root, "build/release/replay/simgrass"))
    ap.add_argument("--ticks", type=int, default=120)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--scalar", default="fx32", choices=["fx32", "fx16"])
    ap.add_argument("--json", action="store_true", help="machine-readable output")
    a = ap.parse_args()
    with open(os.path.join(root, "scenarios/thesis-meadow.json")) as f:
        base = json.load(f)
    load_before = os.getloadavg()[0]
    results = {}
    device = None
    with tempfile.TemporaryDirectory() as tmp:
        files = {}
        for side in SIDES:
            s = dict(base)
            s["field"] = dict(base["field"], patchesX=side, patchesZ=side)
            files[side] = os.path.join(tmp, f"meadow-{side}.json")
            with open(files[side], "w") as f:
                json.dump(s, f)
        for rep in range(a.repeats):
            for side in SIDES:
                for name, physics, threads in CONFIGS:
                    cmd = [a.simgrass, "run", files[side], "--ticks", str(a.ticks), "--scalar", a.scalar,
                           "--physics", physics, "--threads", str(threads), "--json"]
                    out = subprocess.run(cmd, capture_output=True, text=True)
                    if out.returncode != 0:
                        sys.exit(f"gpu_thesis_comparison: {' '.join(cmd)} failed (exit {out.returncode}): "
                                 f"{out.stderr.strip()}")
                    j = json.loads(out.stdout)
                    results.setdefault((side, name), []).append(j["timing"]["msPerTick"])
                    results.setdefault((side, name, "hash"), set()).add(j["finalHash"])
                    if physics == "gpu":
                        device = j["physics"]
            print(f"repetition {rep + 1}/{a.repeats} done", file=sys.stderr)
    load_after = os.getloadavg()[0]
    rows = []
    for side in SIDES:
        hashes = set().union(*(results[(side, name, "hash")] for name, _, _ in CONFIGS))
        row = {"side": side, "particles": side * side, "identicalHashes": len(hashes) == 1}
        for name, _, _ in CONFIGS:
            v = results[(side, name)]
            row[name] = {"median": statistics.median(v), "min": min(v), "max": max(v)}
        resident, readback = row["gpu (resident)"]["median"], row["gpu-readback"]["median"]
        row["readbackShare"] = (readback - resident) / readback if readback > 0 else 0.0
        rows.append(row)
    report = {"scalar": a.scalar, "ticks": a.ticks, "repeats": a.repeats, "device": device,
              "loadAverage": [load_before, load_after], "rows": rows}
    if a.json:
        print(json.dumps(report, indent=2))
        return
    print(f"{a.scalar}, {a.ticks} ticks, median of {a.repeats} interleaved runs (min-max), ms per tick; "
          f"load average {load_before:.2f} before, {load_after:.2f} after")
    print(f"device: {device}")
    head = "| particles | " + " | ".join(n for n, _, _ in CONFIGS) + " | readback share | same hash |"
    print(head)
    print("|" + "---|" * (len(CONFIGS) + 3))
    for r in rows:
        cells = [f"{r[n]['median']:.3f} ({r[n]['min']:.3f}-{r[n]['max']:.3f})" for n, _, _ in CONFIGS]
        print(f"| {r['particles']:,} | " + " | ".join(cells) +
              f" | {100 * r['readbackShare']:.0f} % | {'yes' if r['identicalHashes'] else 'NO'} |")


if __name__ == "__main__":
    main()
