#!/usr/bin/env python3
"""Compares the camera-to-trajectory latency of two sets of lab trials (scripts/lab_trial.sh
--out DIRs), pooling every run's trajectories: p50 and p99 of each, their difference, and a
bootstrap 95 % interval of the difference (2,000 resamples, seed 1). Latency is the recorder's
receive time less the capture time, from sg-report's OBJECT_TRAJECTORY.csv of each run. The
interval takes the trajectories as independent: it covers the sampling within the sets, not the
shift a machine's state gives a whole trial (compare the trials pair by pair for that).

  scripts/lab_latency.py --a /work/lat-one-1 /work/lat-one-2 --b /work/lat-three-1 /work/lat-three-2
"""
import argparse
import csv
import glob
import random
import sys


def load(dirs):
    ms = []
    for d in dirs:
        for path in sorted(glob.glob(f"{d}/run-*/report/csv/OBJECT_TRAJECTORY.csv")):
            try:
                with open(path) as f:
                    ms += [(int(r["recv_utime"]) - int(r["source_utime"])) / 1000
                           for r in csv.DictReader(f)]
            except (OSError, KeyError, ValueError) as e:
                sys.exit(f"lab_latency: {path}: not an sg-report OBJECT_TRAJECTORY.csv ({e!r})")
    return ms


def quantile(values, p):
    v = sorted(values)
    return v[min(len(v) - 1, int(p * len(v)))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--a", nargs="+", required=True, help="the baseline's trial folders")
    parser.add_argument("--b", nargs="+", required=True, help="the compared trial folders")
    args = parser.parse_args()
    a, b = load(args.a), load(args.b)
    if not a or not b:
        sys.exit("lab_latency: no OBJECT_TRAJECTORY.csv under one of the sets (run lab_trial.sh)")
    print(f"a: {len(a)} trajectories; b: {len(b)} trajectories")
    rng = random.Random(1)
    for p in (0.5, 0.99):
        diffs = sorted(quantile([rng.choice(b) for _ in b], p) - quantile([rng.choice(a) for _ in a], p)
                       for _ in range(2000))
        print(f"p{round(p * 100)}: a {quantile(a, p):.2f} ms, b {quantile(b, p):.2f} ms, "
              f"b - a {quantile(b, p) - quantile(a, p):+.2f} ms "
              f"(95 % bootstrap {diffs[50]:+.2f} to {diffs[1949]:+.2f} ms)")


if __name__ == "__main__":
    main()
