#!/usr/bin/env python3
"""Wall-clock A/B timing for local use (docs/performance.md, "A/B timing").

Runs a base and a candidate command interleaved, N pairs, the order flipping from pair to pair
(AB BA AB BA ..., so neither side always runs second; --shuffle-pairs: a random order per pair),
and reports the median of the per-pair time ratios candidate/base with its interquartile range,
and a verdict. Interleaving puts both sides under the same machine load
drift; the per-pair ratio cancels most of it.

  bench/ab.py [options] BASE_CMD... -- CAND_CMD...
  bench/ab.py --base-dir ../base/build/release --candidate-dir build/release -- ARGS...

The second form runs DIR/replay/simgrass ARGS for both (e.g. `run --ticks 300 --threads 2`).
A command's time is its wall-clock time, or with --metric, a number it prints in JSON (a dotted
path into its --json output, e.g. timing.msPerTick: then startup is not counted).

Verdict: "faster"/"slower" when the whole interquartile range of the ratios lies below/above
1 - threshold / 1 + threshold (default 2 %), else "no significant difference".
Exit status: 0 done (whatever the verdict), 1 a command failed, 2 bad usage.
"""
import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import time


def quartiles(values):
    """(q1, median, q3) by linear interpolation between order statistics."""
    s = sorted(values)

    def at(q):
        pos = q * (len(s) - 1)
        lo = int(pos)
        hi = min(lo + 1, len(s) - 1)
        return s[lo] + (s[hi] - s[lo]) * (pos - lo)

    return at(0.25), at(0.5), at(0.75)


def verdict(q1, q3, threshold):
    if q3 < 1.0 - threshold:
        return "faster"
    if q1 > 1.0 + threshold:
        return "slower"
    return "no significant difference"


def dig(data, path):
    for key in path.split("."):
        data = data[key]
    return float(data)


def timed(cmd, metric):
    """One run: seconds of wall clock, or the metric the command printed."""
    start = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if p.returncode != 0:
        tail = (p.stderr.strip().splitlines() or ["(no output)"])[-1]
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {tail}")
    if not metric:
        return seconds
    try:
        return dig(json.loads(p.stdout), metric)
    except (json.JSONDecodeError, KeyError, TypeError, ValueError) as e:
        raise RuntimeError(f"{' '.join(cmd)}: --metric {metric}: expected a number at that path of its JSON output ({e!r})")


def main(argv):
    ap = argparse.ArgumentParser(prog="bench/ab.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-n", "--pairs", type=int, default=10, help="base/candidate pairs (default 10)")
    ap.add_argument("--warmup", type=int, default=1, help="unreported pairs first (default 1)")
    ap.add_argument("--threshold", type=float, default=2.0, help="percent for the verdict (default 2)")
    ap.add_argument("--metric", help="dotted JSON path to time from the command's output instead of wall clock")
    ap.add_argument("--shuffle-pairs", action="store_true", help="random order within each pair (seeded by --seed)")
    ap.add_argument("--seed", type=int, default=1, help="seed for --shuffle-pairs")
    ap.add_argument("--base-dir", help="build directory of the base (runs DIR/replay/simgrass ARGS)")
    ap.add_argument("--candidate-dir", help="build directory of the candidate")
    ap.add_argument("--json", action="store_true", help="machine-readable output")
    ap.add_argument("commands", nargs=argparse.REMAINDER, help="BASE_CMD... -- CAND_CMD...  or  -- ARGS...")
    args = ap.parse_args(argv)

    rest = args.commands
    if "--" not in rest:
        ap.error("expected BASE_CMD... -- CAND_CMD... (or --base-dir/--candidate-dir -- ARGS...)")
    cut = rest.index("--")
    if args.base_dir or args.candidate_dir:
        if not (args.base_dir and args.candidate_dir) or cut != 0:
            ap.error("--base-dir and --candidate-dir go together, followed by -- ARGS...")
        tool = os.path.join("replay", "simgrass")
        base = [os.path.join(args.base_dir, tool)] + rest[1:]
        cand = [os.path.join(args.candidate_dir, tool)] + rest[1:]
        for c in (base[0], cand[0]):
            if not os.access(c, os.X_OK):
                ap.error(f"{c}: no such executable (build that directory first)")
    else:
        base, cand = rest[:cut], rest[cut + 1:]
        if not base or not cand:
            ap.error("expected BASE_CMD... -- CAND_CMD..., both non-empty")
    if args.pairs < 3 or args.warmup < 0 or args.threshold <= 0:
        ap.error("--pairs: expected at least 3; --warmup: >= 0; --threshold: > 0")

    rng = random.Random(args.seed)
    ratios, base_t, cand_t = [], [], []
    try:
        for i in range(args.warmup + args.pairs):
            order = [("base", base), ("cand", cand)]
            if (rng.random() < 0.5) if args.shuffle_pairs else (i % 2 == 1):
                order.reverse()
            t = {name: timed(cmd, args.metric) for name, cmd in order}
            if i < args.warmup:
                continue
            base_t.append(t["base"])
            cand_t.append(t["cand"])
            ratios.append(t["cand"] / t["base"])
            if not args.json:
                print(f"pair {len(ratios):3d}: base {t['base']:.4g}  candidate {t['cand']:.4g}  ratio {ratios[-1]:.4f}",
                      file=sys.stderr)
    except RuntimeError as e:
        print(f"ab: {e}", file=sys.stderr)
        return 1

    q1, med, q3 = quartiles(ratios)
    result = {
        "base": base, "candidate": cand, "pairs": len(ratios), "metric": args.metric or "wall seconds",
        "baseMedian": statistics.median(base_t), "candidateMedian": statistics.median(cand_t),
        "ratioMedian": med, "ratioQ1": q1, "ratioQ3": q3, "ratioMin": min(ratios), "ratioMax": max(ratios),
        "ratios": ratios, "thresholdPercent": args.threshold,
        "verdict": verdict(q1, q3, args.threshold / 100.0),
    }
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        print(f"base      median {result['baseMedian']:.4g} ({result['metric']})")
        print(f"candidate median {result['candidateMedian']:.4g}")
        print(f"ratio candidate/base: median {med:.4f}, interquartile range {q1:.4f} .. {q3:.4f} "
              f"(min {result['ratioMin']:.4f}, max {result['ratioMax']:.4f}, {len(ratios)} pairs)")
        print(f"verdict: {result['verdict']} (threshold {args.threshold:g} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
