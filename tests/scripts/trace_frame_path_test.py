#!/usr/bin/env python3
"""scripts/trace_frame_path.py on a trace the kernel's tracer recorded (tests/fixtures/trace):
the answers are the recorded events' own times, read off the fixture by hand."""
import os
import subprocess
import sys
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "trace_frame_path.py")
FIXTURE = os.path.join(ROOT, "tests", "fixtures", "trace", "frame_path.trace")

sys.path.insert(0, os.path.dirname(SCRIPT))
import trace_frame_path as tfp  # noqa: E402  (scripts/ is no package)


class TraceFramePathTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.events = tfp.read_events(FIXTURE)
        cls.timeline = tfp.Timeline(cls.events)
        cls.pairs = tfp.find_pairs(cls.events, 10000, "sg-vision")

    # Each pair from its second image's netif_rx to sg-vision's next 130-byte datagram.
    def test_pairs_and_their_latencies(self):
        got = [(round(s, 6), round((p - s) * 1e6)) for s, p, _ in self.pairs]
        self.assertEqual(got, [(27636.281248, 412), (27636.332707, 1230),
                               (27652.643662, 459), (27652.693638, 1981)])

    # The slow pair of the first run: sg-vision's thread ran 619 us between ppoll's return
    # (27636.332742) and its next system call (27636.333361) with no event on its CPU.
    def test_a_running_thread_that_shows_nothing_is_a_silence(self):
        second, position, _ = self.pairs[1]
        causes = tfp.explain(self.timeline, tfp.CpuEvents(self.events), second, position,
                             "sg-vision", 300)
        self.assertIn("CPU 0 silent 619 us while running sg-vision", causes)
        self.assertIn("sg-vision-5711 preempted on CPU 0 by sg-vision-5714", causes)

    # The slow pair of the second run overlapped the VM's DAMON thread on CPU 0 for 785 us.
    def test_kdamond_within_a_pair_is_named(self):
        second, position, _ = self.pairs[3]
        causes = tfp.explain(self.timeline, tfp.CpuEvents(self.events), second, position,
                             "sg-vision", 300)
        self.assertIn("kdamond.0 on CPU 0 for 785 us", causes)

    # A fast pair: no silence of 300 us, no kdamond; only the decode worker, woken on the reading
    # thread's own CPU, preempting it (the sched_switch with prev_state=R at 27636.281333).
    def test_a_fast_pair_has_only_its_worker(self):
        second, position, _ = self.pairs[0]
        self.assertEqual(tfp.explain(self.timeline, tfp.CpuEvents(self.events), second, position,
                                     "sg-vision", 300),
                         ["sg-vision-5711 preempted on CPU 0 by sg-vision-5714"])

    # From each OBJECT_POSITION (130 bytes) into the loopback to sg-vision's next datagram
    # (BLOB_LEFT, 293 bytes): 27636.281660 -> .281739, .333937 -> .333975, 27652.644121 ->
    # .644178, .695619 -> .695843. In the first, sg-predictor, woken by the send on sg-vision's
    # CPU (27636.281666), runs before sg-vision's next system call.
    def test_after_the_send(self):
        self.assertEqual([round(g) for g in tfp.after_send(self.events, self.pairs)],
                         [79, 38, 57, 224])

    # Every wake-up of one sg-vision thread by another in the fixture was on the waker's CPU.
    def test_worker_placement(self):
        self.assertEqual(tfp.worker_placement(self.events, "sg-vision"), (4, 0))

    # The command line: two runs (the pairs 16 s apart), one pair over 1 ms in each.
    def test_analyze_prints_the_runs(self):
        out = subprocess.run([sys.executable, SCRIPT, "analyze", FIXTURE, "--over-us", "1000"],
                             capture_output=True, text=True, check=True).stdout
        self.assertIn("run 1: 2 pairs", out)
        self.assertIn("run 2: 2 pairs", out)
        self.assertEqual(out.count("1 over 1000 us"), 2)

    # Without system calls in the trace a computing thread shows no event either: no silences.
    def test_no_silences_without_system_calls(self):
        events = [e for e in self.events if not e.event.startswith("sys_")]
        second, position, _ = self.pairs[1]
        self.assertEqual(tfp.explain(tfp.Timeline(events), None, second, position, "sg-vision", 300),
                         ["sg-vision-5711 preempted on CPU 0 by sg-vision-5714"])

    # A trace without pairs is one line of error, not a traceback.
    def test_no_pairs_is_a_clear_error(self):
        empty = os.path.join(os.environ.get("TMPDIR", "/tmp"), "trace_frame_path_empty.trace")
        with open(empty, "w") as f:
            f.write("# tracer: nop\n")
        r = subprocess.run([sys.executable, SCRIPT, "analyze", empty], capture_output=True,
                           text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("no stereo pair", r.stderr)
        self.assertNotIn("Traceback", r.stderr)


if __name__ == "__main__":
    unittest.main()
