#!/usr/bin/env python3
"""scripts/machine_latency.py on a histogram cyclictest wrote (tests/fixtures/cyclictest): the
answers are counted off the fixture's rows by hand (its README lists them)."""
import os
import subprocess
import sys
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "machine_latency.py")
FIXTURE = os.path.join(ROOT, "tests", "fixtures", "cyclictest", "idle_ordinary.hist")

sys.path.insert(0, os.path.dirname(SCRIPT))
import machine_latency as ml  # noqa: E402  (scripts/ is no package)


class MachineLatencyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(FIXTURE) as f:
            cls.h = ml.parse(f.read())

    # Wake-ups are the histogram's rows plus its overflows: 9953 + 4 and 9981 + 4.
    def test_wakeups_count_the_overflows(self):
        self.assertEqual(self.h.max_us, 2000)
        self.assertEqual([self.h.wakeups(0), self.h.wakeups(1)], [9957, 9985])
        self.assertEqual(self.h.maxima, [15103, 2256])

    # Thread 0 has 22 wake-ups in the rows at 1000 us or more and 4 beyond the last bucket.
    def test_late_wakeups_include_the_overflows(self):
        self.assertEqual([self.h.later_than(0, 1000), self.h.later_than(1, 1000)], [26, 11])
        self.assertEqual([self.h.later_than(0, 500), self.h.later_than(1, 500)], [44, 19])

    # Thread 0's 10 latest wake-ups are 1562 us or later (6 rows from 1562 on, 4 overflows):
    # 9947 lie before 1562, fewer than 0.999 x 9957, so p99.9 is 1562.
    def test_percentiles_are_buckets(self):
        self.assertEqual(self.h.percentile(0, 0.999), 1562)
        self.assertEqual(self.h.percentile(1, 0.999), 1159)
        self.assertEqual(self.h.percentile(0, 0.5), 91)

    # A share that lies among the overflows has no bucket.
    def test_a_percentile_beyond_the_last_bucket_is_none(self):
        h = ml.parse("000000 000001\n000001 000000\n# Histogram Overflows: 00003\n")
        self.assertEqual(h.wakeups(0), 4)
        self.assertEqual(h.percentile(0, 0.25), 0)
        self.assertIsNone(h.percentile(0, 0.5))
        self.assertIn("p50 > 2", ml.summary(h))

    # Text that is not a histogram, or rows of different widths, are refused.
    def test_other_text_is_refused(self):
        for text in ("", "hello\n", "000000 000001\n",
                     "000000 000001 000002\n000001 000001\n# Histogram Overflows: 0 0\n",
                     "000005 000001\n# Histogram Overflows: 0\n"):
            with self.assertRaises(ValueError, msg=repr(text)):
                ml.parse(text)

    # The command line: the summary of the fixture; one line and exit 1 for a file that is not.
    def test_summarize_on_the_command_line(self):
        out = subprocess.run([sys.executable, SCRIPT, "summarize", FIXTURE],
                             capture_output=True, text=True)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("thread 0: 9957 wake-ups, late by p50 91, p99 185, p99.9 1562 us, "
                      "0.44 % >= 0.5 ms, 0.26 % >= 1 ms, max 15103 us", out.stdout)
        bad = subprocess.run([sys.executable, SCRIPT, "summarize", SCRIPT],
                             capture_output=True, text=True)
        self.assertEqual(bad.returncode, 1)
        self.assertEqual(len(bad.stderr.strip().splitlines()), 1)


if __name__ == "__main__":
    unittest.main()
