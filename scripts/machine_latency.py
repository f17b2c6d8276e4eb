#!/usr/bin/env python3
"""This machine's own wake-up latency, the floor under any latency figure measured on it
(issue 19): cyclictest (Debian's rt-tests) wakes one thread per CPU every --interval-us and
records how late each wake-up was; this prints each thread's percentiles and how many wake-ups
were later than the thresholds that matter here (0.5 and 1 ms: sg-vision's own p99 goal is 1.5 ms
for about 0.5 ms of work a pair). A thread woken 1 ms late in 1 % of wake-ups puts any process
woken once a pair at its p50 + 1 ms at p99, whatever its code does.

  run (root: SCHED_FIFO and locked memory; cyclictest's own rights): the machine alone, or
  while a command runs (the benchmark's own load), the histogram kept in OUT
    sudo scripts/machine_latency.py run /tmp/idle.hist --seconds 60 [--priority 50]
    sudo scripts/machine_latency.py run /tmp/load.hist -- \\
        scripts/multicast.sh run build/bin/frame_path_latency --region-only
  summarize: a histogram cyclictest wrote (`cyclictest -q -h MAX_US ...` standard output)
    scripts/machine_latency.py summarize /tmp/idle.hist

--priority 0 (the default) measures the ordinary scheduler, as sg-vision runs by default; 50 is
vision.realtime_priority's usual value. cyclictest counts a wake-up later than the histogram's
last bucket (--max-us) as an overflow: it is counted here as later than every threshold.
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys

THRESHOLDS_US = (500, 1000)


class Histogram:
    """cyclictest's histogram: counts[t][us] for thread t, overflows[t] beyond the last bucket."""

    def __init__(self, counts, overflows, max_us, maxima):
        self.counts, self.overflows, self.max_us = counts, overflows, max_us
        self.maxima = maxima  # cyclictest's own maximum per thread (us), or None each

    def wakeups(self, t):
        return sum(self.counts[t]) + self.overflows[t]

    def percentile(self, t, q):
        """The bucket (us) at or below which a share q of thread t's wake-ups fell; None when
        that share lies among the overflows."""
        need, seen = q * self.wakeups(t), 0
        for us, n in enumerate(self.counts[t]):
            seen += n
            if n and seen >= need:
                return us
        return None

    def later_than(self, t, us):
        """Wake-ups of thread t at least `us` late (overflows included)."""
        return sum(self.counts[t][us:]) + self.overflows[t]


def parse(text):
    """A Histogram from cyclictest's -q -h output; ValueError when the text is not one."""
    rows, overflows, maxima = [], None, None
    for line in text.splitlines():
        fields = line.split()
        if not fields:
            continue
        if fields[0].isdigit():
            rows.append([int(f) for f in fields])
        elif line.startswith("# Histogram Overflows:"):
            overflows = [int(f) for f in fields[3:]]
        elif line.startswith("# Max Latencies:"):
            maxima = [int(f) for f in fields[3:]]
    if not rows or overflows is None:
        raise ValueError("no cyclictest histogram (run it with -q -h MAX_US)")
    threads = len(rows[0]) - 1
    if any(len(r) != threads + 1 for r in rows) or len(overflows) != threads:
        raise ValueError("a histogram row or the overflow line has the wrong number of threads")
    counts = [[0] * len(rows) for _ in range(threads)]
    for r in rows:
        if r[0] >= len(rows):
            raise ValueError("histogram buckets are not 0, 1, 2, ... us")
        for t in range(threads):
            counts[t][r[0]] = r[t + 1]
    if maxima is not None and len(maxima) != threads:
        raise ValueError("the maximum line has the wrong number of threads")
    return Histogram(counts, overflows, len(rows), maxima or [None] * threads)


def summary(h):
    lines = []
    for t in range(len(h.counts)):
        n = h.wakeups(t)
        p = [h.percentile(t, q) for q in (0.5, 0.99, 0.999)]
        text = ["thread %d: %d wake-ups, late by p50 %s, p99 %s, p99.9 %s us" %
                (t, n, *[("> %d" % h.max_us) if v is None else v for v in p])]
        for us in THRESHOLDS_US:
            k = h.later_than(t, us)
            text.append("%.2f %% >= %g ms" % (100.0 * k / n if n else 0.0, us / 1000))
        if h.maxima[t] is not None:
            text.append("max %d us" % h.maxima[t])
        lines.append(", ".join(text))
    return "\n".join(lines)


def cyclictest_command(args):
    cpus = os.cpu_count() or 1
    cmd = ["cyclictest", "-q", "-m", "-t", str(cpus), "-a", ",".join(map(str, range(cpus))),
           "-i", str(args.interval_us), "-h", str(args.max_us)]
    if args.priority > 0:
        cmd += ["-p", str(args.priority)]
    if not args.command:
        cmd += ["-D", str(args.seconds)]
    return cmd


def run(args):
    if shutil.which("cyclictest") is None:
        sys.exit("machine_latency: no cyclictest (Debian's rt-tests: scripts/bootstrap.sh)")
    with open(args.out, "w") as out:
        probe = subprocess.Popen(cyclictest_command(args), stdout=out, stderr=subprocess.PIPE,
                                 text=True)
        status = 0
        if args.command:
            try:
                status = subprocess.call(args.command)
            except OSError as e:
                probe.kill()
                probe.wait()
                sys.exit("machine_latency: %s: %s" % (args.command[0], e.strerror))
            except KeyboardInterrupt:  # the command had it too: the histogram so far
                status = 130
            probe.send_signal(signal.SIGINT)  # cyclictest then prints its histogram
        _, err = probe.communicate()
    if probe.returncode != 0:
        sys.exit("machine_latency: cyclictest failed (%d): %s" %
                 (probe.returncode, err.strip().splitlines()[-1] if err.strip() else "no message"))
    with open(args.out) as f:
        print(summary(parse(f.read())))
    print("machine_latency: the histogram is in %s" % args.out)
    return status


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 1)[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="what", required=True)
    r = sub.add_parser("run", help="run cyclictest, alone or while a command runs",
                       usage="%(prog)s OUT [options] [-- COMMAND ...]")
    r.add_argument("out", help="where cyclictest's histogram goes")
    r.add_argument("--seconds", type=int, default=60, help="how long, with no command")
    r.add_argument("--priority", type=int, default=0, help="SCHED_FIFO priority (0: ordinary)")
    r.add_argument("--interval-us", type=int, default=1000, help="between wake-ups")
    r.add_argument("--max-us", type=int, default=10000, help="the histogram's last bucket")
    s = sub.add_parser("summarize", help="a histogram cyclictest wrote")
    s.add_argument("histogram")
    argv = sys.argv[1:]
    command = argv[argv.index("--") + 1:] if "--" in argv else []
    args = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    args.command = command
    if args.what == "run" and "--" in argv and not command:
        sys.exit("machine_latency: nothing after --")
    if args.what == "run":
        for name in ("seconds", "interval_us", "max_us"):
            if getattr(args, name) <= 0:
                sys.exit("machine_latency: --%s must be positive" % name.replace("_", "-"))
        if not 0 <= args.priority <= 99:
            sys.exit("machine_latency: --priority must be 0-99")
        return run(args)
    try:
        with open(args.histogram) as f:
            print(summary(parse(f.read())))
    except (OSError, ValueError) as e:
        sys.exit("machine_latency: %s: %s" % (args.histogram, e))
    return 0


if __name__ == "__main__":
    sys.exit(main())
