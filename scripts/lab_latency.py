#!/usr/bin/env python3
"""Compares the camera-to-trajectory latency of the lab across hosts with one host's, from
scripts/lab_trial.sh --out DIRs. Latency is a recorder's receive time less the capture time, from
sg-report's CSVs of each run.

Two sets of trials (--a, --b): every run's OBJECT_TRAJECTORY pooled per set; p50 and p99 of each,
their difference, and a bootstrap 95 % interval of it (2,000 resamples, seed 1). That interval
takes the trajectories as independent: it covers the sampling within the sets, not the shift a
machine's state gives a whole trial.

Paired trials (--paired, from lab_trial.sh --paired): in each run the same OBJECT_POSITIONs went
to the predictor on lab2 (OBJECT_TRAJECTORY, recorded on lab2: the path across hosts) and to one
on lab1 beside sg-vision (OBJECT_TRAJECTORY_LOCAL, recorded on lab1: the one-host path), at the
same moments. Trajectories are matched by capture time; p50 and p99 of each path and of the
difference, per run and pooled, and a 95 % interval of the pooled p99 difference from a bootstrap
of 10 s blocks (the machine's state lasts seconds, so neighbouring trajectories are not
independent; both paths of a block are resampled together).

  scripts/lab_latency.py --a /work/lat-one-1 /work/lat-one-2 --b /work/lat-three-1 /work/lat-three-2
  scripts/lab_latency.py --paired /work/lat-paired
"""
import argparse
import csv
import glob
import random
import sys

BLOCK_US = 10_000_000  # the bootstrap's block: 10 s of capture time


def read_csv(path):
    """{source_utime: latency in ms} of one sg-report CSV."""
    try:
        with open(path) as f:
            return {int(r["source_utime"]): (int(r["recv_utime"]) - int(r["source_utime"])) / 1000
                    for r in csv.DictReader(f)}
    except (OSError, KeyError, ValueError) as e:
        sys.exit(f"lab_latency: {path}: not an sg-report trajectory CSV ({e!r})")


def load(dirs):
    ms = []
    for d in dirs:
        for path in sorted(glob.glob(f"{d}/run-*/report/csv/OBJECT_TRAJECTORY.csv")):
            ms += read_csv(path).values()
    return ms


def quantile(values, p):
    v = sorted(values)
    return v[min(len(v) - 1, int(p * len(v)))]


def compare_sets(a_dirs, b_dirs):
    a, b = load(a_dirs), load(b_dirs)
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


def paired_runs(dirs):
    """Per run: [(across hosts ms, one host ms)] matched by capture time, in capture order."""
    runs = {}
    for d in dirs:
        for run in sorted(glob.glob(f"{d}/run-*")):
            across = glob.glob(f"{run}/report/csv/OBJECT_TRAJECTORY.csv")
            local = glob.glob(f"{run}/report-local/csv/OBJECT_TRAJECTORY_LOCAL.csv")
            if not across or not local:
                print(f"lab_latency: {run}: left out, not a --paired run with both CSVs", file=sys.stderr)
                continue
            a, l = read_csv(across[0]), read_csv(local[0])
            runs[run] = [(k, a[k], l[k]) for k in sorted(a.keys() & l.keys())]
    return runs


def line(name, pairs):
    across = [a for _, a, _ in pairs]
    local = [l for _, _, l in pairs]
    diff = [a - l for _, a, l in pairs]
    return (f"{name}: {len(pairs)} pairs; across hosts p50 {quantile(across, 0.5):.2f} p99 "
            f"{quantile(across, 0.99):.2f} ms; one host p50 {quantile(local, 0.5):.2f} p99 "
            f"{quantile(local, 0.99):.2f} ms; p99 across - one host "
            f"{quantile(across, 0.99) - quantile(local, 0.99):+.2f} ms; per trajectory the "
            f"difference p50 {quantile(diff, 0.5):+.2f} p99 {quantile(diff, 0.99):+.2f} ms")


def compare_paired(dirs):
    runs = paired_runs(dirs)
    pooled = [p for pairs in runs.values() for p in pairs]
    if not pooled:
        sys.exit("lab_latency: no matched trajectories (run lab_trial.sh --paired)")
    for run, pairs in runs.items():
        if pairs:
            print(line(run, pairs))
    print(line("pooled", pooled))
    blocks = []
    for pairs in runs.values():
        by_block = {}
        for k, a, l in pairs:
            by_block.setdefault(k // BLOCK_US, []).append((a, l))
        blocks += by_block.values()
    rng = random.Random(1)
    for p in (0.5, 0.99):
        diffs = []
        for _ in range(2000):
            sample = [pair for _ in blocks for pair in rng.choice(blocks)]
            diffs.append(quantile([a for a, _ in sample], p) - quantile([l for _, l in sample], p))
        diffs.sort()
        print(f"p{round(p * 100)} across - one host, 95 % block bootstrap ({len(blocks)} blocks of "
              f"10 s): {diffs[50]:+.2f} to {diffs[1949]:+.2f} ms")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--a", nargs="+", help="the baseline's trial folders")
    parser.add_argument("--b", nargs="+", help="the compared trial folders")
    parser.add_argument("--paired", nargs="+", help="lab_trial.sh --paired folders")
    args = parser.parse_args()
    if args.paired:
        compare_paired(args.paired)
    elif args.a and args.b:
        compare_sets(args.a, args.b)
    else:
        parser.error("give --a and --b, or --paired")


if __name__ == "__main__":
    main()
