#!/usr/bin/env python3
"""sg-vision's frame path seen by the kernel's own tracer (issue 19): for every stereo pair, the
time from the second image's arrival on the host to sg-vision's OBJECT_POSITION leaving it, and
what the vCPUs were doing meanwhile. It says which pairs of a run were slow and why: a kernel
thread on the vCPU (the VM's DAMON, kdamond), a thread of sg-vision's preempted or woken late,
or a stretch in which a running thread shows no event at all (its vCPU held by the host).

  record (root; tracefs): runs COMMAND with the scheduler's and the network's events traced
    sudo scripts/trace_frame_path.py record /tmp/fp.trace -- \\
        scripts/multicast.sh run build/bin/frame_path_latency --region-only
    (system calls are traced too, so that a running thread's silences mean something: the trace
    is then ten times larger, --no-syscalls leaves them out; --buffer-mb sets the per-CPU ring,
    which drops the oldest events when full: a long run needs a large one; --softirqs adds the
    softirqs, what a send does on one host before it returns)
  analyze: the pairs of a recorded trace (or of `cat /sys/kernel/tracing/trace`)
    scripts/trace_frame_path.py analyze /tmp/fp.trace [--over-us 1500] [--process sg-vision]

What it reads (tracefs text, `trace_clock` mono): `net:netif_rx` (every datagram on the
loopback: an image is one of --image-bytes or more, OBJECT_POSITION is sg-vision's first smaller
datagram after a pair's second image), `sched:sched_switch`, `sched:sched_wakeup`, and
`raw_syscalls` when recorded. Times are the tracer's: the pair's clock starts when the kernel
takes the second image in (netif_rx), a little before sg-vision's own SO_TIMESTAMP, and stops
when OBJECT_POSITION enters the loopback, a little after sg-vision reads its clock; the two
agree with sg-vision's own figure to some microseconds.
"""
import argparse
import bisect
import collections
import os
import re
import signal
import subprocess
import sys

LINE = re.compile(r"^\s*(?P<comm>.+?)-(?P<pid>\d+)\s+\[(?P<cpu>\d+)\]\s+\S+\s+"
                  r"(?P<t>\d+\.\d+): (?P<event>\w+): (?P<rest>.*)$")
SWITCH = re.compile(r"prev_comm=(?P<prev>.+?) prev_pid=(?P<prev_pid>\d+) .*prev_state=(?P<state>\S+)"
                    r" ==> next_comm=(?P<next>.+?) next_pid=(?P<next_pid>\d+)")
WAKEUP = re.compile(r"comm=(?P<comm>.+?) pid=(?P<pid>\d+) .*target_cpu=(?P<cpu>\d+)")
LENGTH = re.compile(r"len=(\d+)")
TRACEFS = "/sys/kernel/tracing"


class Event:
    __slots__ = ("comm", "pid", "cpu", "t", "event", "rest")

    def __init__(self, m):
        self.comm, self.pid, self.cpu = m["comm"].strip(), int(m["pid"]), int(m["cpu"])
        self.t, self.event, self.rest = float(m["t"]), m["event"], m["rest"]


def read_events(path):
    events = []
    with open(path, errors="replace") as f:
        for line in f:
            m = LINE.match(line)
            if m:
                events.append(Event(m))
    events.sort(key=lambda e: e.t)
    return events


def percentile(values, p):
    s = sorted(values)
    return s[min(len(s) - 1, int(p * len(s)))] if s else 0


class Timeline:
    """Who ran on each CPU when, from sched_switch."""

    def __init__(self, events):
        self.runs = collections.defaultdict(list)  # cpu -> [(start, end, comm, pid)]
        self.preempted = []  # (t, cpu, comm, pid, by comm): switched out while runnable
        current = {}
        for e in events:
            if e.event != "sched_switch":
                continue
            m = SWITCH.search(e.rest)
            if not m:
                continue
            if e.cpu in current:
                start, comm, pid = current[e.cpu]
                self.runs[e.cpu].append((start, e.t, comm, pid))
            if m["state"].startswith("R"):
                self.preempted.append((e.t, e.cpu, m["prev"], int(m["prev_pid"]),
                                       "%s-%s" % (m["next"], m["next_pid"])))
            current[e.cpu] = (e.t, m["next"], int(m["next_pid"]))

    def overlapping(self, start, end, name_prefix):
        """Runs of tasks whose name starts with `name_prefix` that overlap [start, end]."""
        out = []
        for cpu, runs in self.runs.items():
            for s, e, comm, pid in runs:
                if s < end and e > start and comm.startswith(name_prefix):
                    out.append((cpu, s, e, comm))
        return out


def find_pairs(events, image_bytes, process):
    """[second image time, position time, sending task] for each pair with a position.

    OBJECT_POSITION is the first datagram `process` sends after the pair's second image, of the
    length most such first datagrams have (a PROCESS_STATUS sent meanwhile is longer)."""
    pairs, first = [], None
    for e in events:
        if e.event != "netif_rx":
            continue
        m = LENGTH.search(e.rest)
        size = int(m.group(1)) if m else 0
        if size >= image_bytes:
            if first is not None and e.t - first.t < 0.005 and e.pid == first.pid:
                pairs.append([e.t, []])
                first = None
            else:
                first = e
        elif e.comm.startswith(process) and pairs:
            pairs[-1][1].append((size, e.t, e.pid))
    firsts = collections.Counter(sent[0][0] for _, sent in pairs if sent)
    if not firsts:
        return []
    length = firsts.most_common(1)[0][0]
    out = []
    for second, sent in pairs:
        match = [(t, pid) for size, t, pid in sent if size == length]
        if match:
            out.append((second, match[0][0], match[0][1]))
    return out


def after_send(events, pairs):
    """For each pair, the time from its OBJECT_POSITION entering the loopback to the sending
    thread's next datagram (sg-vision's BLOB_LEFT), in us; None when there is none. On one host
    the send delivers the datagram to the host's subscribers in the sender's thread, and one woken
    on its CPU may run before the send returns: sg-vision's own figure stops before that time
    (Bus::last_handed_utime), the "to publish() returning" one after it."""
    sent = [(e.t, e.pid) for e in events if e.event == "netif_rx"]
    times = [t for t, _ in sent]
    out = []
    for _, position, pid in pairs:
        i = bisect.bisect_right(times, position)
        while i < len(sent) and sent[i][1] != pid:
            i += 1
        out.append((sent[i][0] - position) * 1e6 if i < len(sent) else None)
    return out


class CpuEvents:
    """Each CPU's event times, for the silences of a running thread."""

    def __init__(self, events):
        self.times = collections.defaultdict(list)
        for e in events:
            self.times[e.cpu].append(e.t)

    def silences(self, cpu, start, end, min_us):
        times = self.times[cpu]
        i = bisect.bisect_left(times, start)
        out = []
        while i + 1 < len(times) and times[i] < end:
            gap = (min(times[i + 1], end) - times[i]) * 1e6
            if gap >= min_us:
                out.append((times[i], gap))
            i += 1
        return out


def explain(timeline, cpu_events, second, position, process, quiet_us):
    """What held the pair [second, position]; silences only when `cpu_events` is given (a trace
    with system calls: without them a thread that computes shows no event either)."""
    causes = []
    for cpu, s, e, comm in timeline.overlapping(second, position, "kdamond"):
        causes.append("%s on CPU %d for %.0f us" % (
            comm, cpu, (min(e, position) - max(s, second)) * 1e6))
    for t, cpu, comm, pid, by in timeline.preempted:
        if second <= t <= position and comm.startswith(process):
            causes.append("%s-%d preempted on CPU %d by %s" % (comm, pid, cpu, by))
    for cpu, s, e, comm in timeline.overlapping(second, position, process) if cpu_events else []:
        for t, gap in cpu_events.silences(cpu, max(s, second), min(e, position), quiet_us):
            causes.append("CPU %d silent %.0f us while running %s" % (cpu, gap, comm))
    counted = collections.Counter(causes)  # in order of first appearance, repeats counted
    return [c if counted[c] == 1 else "%s (%d times)" % (c, counted[c]) for c in dict.fromkeys(causes)]


def worker_placement(events, process):
    """sched_wakeups of `process` threads by `process` threads: how many on the waker's CPU."""
    same = other = 0
    for e in events:
        if e.event == "sched_wakeup" and e.comm.startswith(process):
            m = WAKEUP.search(e.rest)
            if m and m["comm"].startswith(process):
                if int(m["cpu"]) == e.cpu:
                    same += 1
                else:
                    other += 1
    return same, other


def analyze(args):
    events = read_events(args.trace)
    timeline = Timeline(events)
    pairs = find_pairs(events, args.image_bytes, args.process)
    if not pairs:
        sys.exit("trace_frame_path: no stereo pair with an OBJECT_POSITION in " + args.trace)
    runs, previous = [], None
    for p in pairs:  # a new run after a second without pairs (the benchmark's next row)
        if previous is None or p[0] - previous > 1.0:
            runs.append([])
        runs[-1].append(p)
        previous = p[0]
    syscalls = any(e.event == "sys_enter" for e in events)
    cpu_events = CpuEvents(events) if syscalls else None
    if not syscalls:
        print("(no system calls in the trace: a running thread's silences are not judged;"
              " record without --no-syscalls)")
    for k, run in enumerate(runs):
        lat = [(pos - sec) * 1e6 for sec, pos, _ in run]
        slow = [(l, p) for l, p in zip(lat, run) if l > args.over_us]
        print("run %d: %d pairs, second image -> OBJECT_POSITION p50 %.0f us, p99 %.0f us, max %.0f us;"
              " %d over %.0f us" % (k + 1, len(run), percentile(lat, 0.5), percentile(lat, 0.99),
                                    max(lat), len(slow), args.over_us))
        gaps = [g for g in after_send(events, run) if g is not None]
        if gaps:
            print("  OBJECT_POSITION into the loopback -> the sender's next datagram: p50 %.0f us,"
                  " p99 %.0f us, max %.0f us" % (percentile(gaps, 0.5), percentile(gaps, 0.99),
                                                  max(gaps)))
        for l, (sec, pos, pid) in sorted(slow, reverse=True)[:args.show]:
            causes = explain(timeline, cpu_events, sec, pos, args.process, args.quiet_us)
            print("  %.6f  %6.0f us  %s" % (sec, l, "; ".join(causes) if causes else "no cause seen"))
    bursts = [(s, e - s) for cpu in timeline.runs for s, e, comm, _ in timeline.runs[cpu]
              if comm.startswith("kdamond")]
    if bursts:
        starts = sorted(s for s, _ in bursts)
        gaps = [b - a for a, b in zip(starts, starts[1:]) if 0.1 < b - a < 2]
        print("kdamond: %d runs, median %.0f us, max %.0f us%s" % (
            len(bursts), percentile([d * 1e6 for _, d in bursts], 0.5),
            max(d for _, d in bursts) * 1e6,
            ", every %.0f ms (median)" % (percentile(gaps, 0.5) * 1e3) if gaps else ""))
    same, other = worker_placement(events, args.process)
    if same + other:
        print("%s woke its own threads %d times: %d on the waker's CPU, %d on another" % (
            args.process, same + other, same, other))


def write(path, text):
    with open(os.path.join(TRACEFS, path), "w") as f:
        f.write(text)


def record(args):
    if not os.path.isdir(os.path.join(TRACEFS, "events")):
        subprocess.run(["mount", "-t", "tracefs", "nodev", TRACEFS], check=False)
    if not os.access(os.path.join(TRACEFS, "tracing_on"), os.W_OK):
        sys.exit("trace_frame_path: cannot write %s (root, and tracefs mounted, are needed)" % TRACEFS)
    command = args.command
    if not command:
        command = ["scripts/multicast.sh", "run", "build/bin/frame_path_latency", "--region-only"]
    events = ["sched:sched_switch", "sched:sched_wakeup", "net:netif_rx"]
    if not args.no_syscalls:
        events += ["raw_syscalls:sys_enter", "raw_syscalls:sys_exit"]
    if args.softirqs:
        events += ["irq:softirq_entry", "irq:softirq_exit"]
    write("tracing_on", "0")
    write("trace", "")
    write("trace_clock", "mono")
    write("buffer_size_kb", str(args.buffer_mb * 1024))
    write("set_event", "\n".join(events) + "\n")
    write("tracing_on", "1")
    try:
        status = subprocess.run(command).returncode
    finally:
        write("tracing_on", "0")
        with open(os.path.join(TRACEFS, "trace")) as src, open(args.out, "w") as dst:
            for line in src:
                dst.write(line)
        write("set_event", "")
    print("trace_frame_path: the trace is in %s; scripts/trace_frame_path.py analyze %s" % (
        args.out, args.out))
    return status


def main():
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `analyze ... | head` ends quietly
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n\n", 1)[1])
    sub = parser.add_subparsers(dest="mode", required=True)
    r = sub.add_parser("record", help="run a command with the frame path traced (root)")
    r.add_argument("out", help="where the trace goes (text)")
    r.add_argument("--buffer-mb", type=int, default=256, help="per-CPU ring buffer (MiB)")
    r.add_argument("--softirqs", action="store_true",
                   help="the softirqs too (what a send does before it returns)")
    r.add_argument("--no-syscalls", action="store_true",
                   help="leave system calls out (a smaller trace; silences are then not judged)")
    r.epilog = "then -- COMMAND (default: frame_path_latency --region-only)"
    a = sub.add_parser("analyze", help="the pairs of a recorded trace")
    a.add_argument("trace")
    a.add_argument("--over-us", type=float, default=1500, help="a pair slower than this is listed")
    a.add_argument("--show", type=int, default=10, help="slow pairs listed per run")
    a.add_argument("--process", default="sg-vision", help="the program whose latency it is")
    a.add_argument("--image-bytes", type=int, default=10000,
                   help="a datagram this long or longer is a camera image")
    a.add_argument("--quiet-us", type=float, default=300,
                   help="a running thread's silence this long is listed")
    argv = sys.argv[1:]
    command = argv[argv.index("--") + 1:] if "--" in argv else []
    args = parser.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    args.command = command
    return analyze(args) if args.mode == "analyze" else record(args)


if __name__ == "__main__":
    sys.exit(main())
