#!/usr/bin/env python3
"""Self-test of the instruction-count gate (.ci/perf-gate): that it can fail.

  perf_gate_selftest.py [BUILD_DIR]

1. The comparison function on synthetic counts: +5 % against a 2 % threshold is a regression whose
   message names the workload and the change; -5 % passes as "improved" with "baseline stale";
   +1 % passes.
2. The whole script on given counts (--counts) against a doctored baseline in a temp dir: exit 1
   and a stderr line naming only the regressed workload; a tool-version difference gives a note;
   a malformed baseline gives exit 2 and one line naming the file.
3. With BUILD_DIR (and valgrind): one real workload under callgrind, against a baseline written
   by the gate itself (exit 0: the count repeats exactly) and against the same baseline lowered
   by 5 % (exit 1 naming the workload).
"""
import importlib.machinery
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GATE = os.path.join(ROOT, ".ci", "perf-gate")
BUILD = sys.argv.pop(1) if len(sys.argv) > 1 else None


def load_gate():
    loader = importlib.machinery.SourceFileLoader("perf_gate", GATE)
    spec = importlib.util.spec_from_loader("perf_gate", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


gate = load_gate()


def run_gate(*args):
    return subprocess.run([sys.executable, GATE, *args], capture_output=True, text=True)


class Compare(unittest.TestCase):
    def test_rise_above_threshold_is_a_regression_naming_workload_and_change(self):
        verdict, change, message = gate.compare("meadow-fx32-k1", 1_000_000, 1_050_000, 2.0)
        self.assertEqual(verdict, "regression")
        self.assertAlmostEqual(change, 5.0, places=9)
        self.assertIn("meadow-fx32-k1", message)
        self.assertIn("+5.00 %", message)

    def test_drop_beyond_threshold_passes_but_says_stale(self):
        verdict, change, message = gate.compare("w", 1_000_000, 950_000, 2.0)
        self.assertEqual(verdict, "improved")
        self.assertAlmostEqual(change, -5.0, places=9)
        self.assertIn("baseline stale", message)

    def test_within_threshold_passes(self):
        self.assertEqual(gate.compare("w", 1_000_000, 1_010_000, 2.0)[0], "ok")
        self.assertEqual(gate.compare("w", 1_000_000, 1_020_000, 2.0)[0], "ok")  # the threshold itself passes
        self.assertEqual(gate.compare("w", 1_000_000, 1_020_001, 2.0)[0], "regression")

    def test_new_and_missing_workloads_pass_with_a_note(self):
        self.assertEqual(gate.compare("w", None, 5, 2.0)[0], "new")
        self.assertEqual(gate.compare("w", 5, None, 2.0)[0], "missing")


class Script(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="perf-gate-selftest-")
        self.baseline = os.path.join(self.tmp, "baseline.json")
        self.counts = os.path.join(self.tmp, "counts.json")
        tools = {"valgrind": "valgrind-3.19.0", "build": "b", "compiler": "c", "cpu": "x"}
        with open(self.baseline, "w") as f:
            json.dump({"thresholdPercent": 2.0, "tools": tools,
                       "workloads": {"alpha": {"instructions": 1_000_000}, "beta": {"instructions": 2_000_000}}}, f)
        self.tools = tools

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def write_counts(self, alpha, beta, tools=None):
        with open(self.counts, "w") as f:
            json.dump({"alpha": alpha, "beta": beta, "_tools": tools or self.tools}, f)

    def test_regression_exits_1_naming_the_workload(self):
        self.write_counts(1_050_000, 2_000_000)
        p = run_gate("--counts", self.counts, "--baseline", self.baseline)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        self.assertIn("alpha: +5.00 %", p.stderr)
        self.assertNotIn("beta", p.stderr)

    def test_json_output(self):
        self.write_counts(1_050_000, 2_000_000)
        p = run_gate("--counts", self.counts, "--baseline", self.baseline, "--json")
        self.assertEqual(p.returncode, 1)
        data = json.loads(p.stdout)
        verdicts = {w["name"]: w["verdict"] for w in data["workloads"]}
        self.assertEqual(verdicts, {"alpha": "regression", "beta": "ok"})
        self.assertFalse(data["ok"])

    def test_improvement_passes_and_says_stale(self):
        self.write_counts(900_000, 2_000_000)
        p = run_gate("--counts", self.counts, "--baseline", self.baseline)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("baseline stale", p.stdout)

    def test_version_difference_is_noted_and_still_compared(self):
        self.write_counts(1_050_000, 2_000_000, dict(self.tools, compiler="other"))
        p = run_gate("--counts", self.counts, "--baseline", self.baseline)
        self.assertEqual(p.returncode, 1)
        self.assertIn("note: compiler differs", p.stdout)

    def test_other_particle_kernel_skips_all_but_the_scalar_workloads(self):
        # Baseline taken where the AVX2 kernel ran; this CPU runs the reference: the default-kernel
        # counts are of other code and are not compared, the "-scalar" ones still are.
        with open(self.baseline, "w") as f:
            json.dump({"thresholdPercent": 2.0, "tools": dict(self.tools, particleKernel="avx2"),
                       "workloads": {"alpha": {"instructions": 1_000_000},
                                     "beta-scalar": {"instructions": 2_000_000}}}, f)
        with open(self.counts, "w") as f:
            json.dump({"alpha": 3_000_000, "beta-scalar": 2_000_000,
                       "_tools": dict(self.tools, particleKernel="scalar")}, f)
        p = run_gate("--counts", self.counts, "--baseline", self.baseline, "--json")
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        data = json.loads(p.stdout)
        self.assertEqual({w["name"]: w["verdict"] for w in data["workloads"]}, {"alpha": "skipped", "beta-scalar": "ok"})
        self.assertTrue(any("default particle kernel differs" in n for n in data["notes"]), data["notes"])
        with open(self.counts, "w") as f:  # the scalar workloads still fail on a rise
            json.dump({"alpha": 3_000_000, "beta-scalar": 2_100_000,
                       "_tools": dict(self.tools, particleKernel="scalar")}, f)
        p = run_gate("--counts", self.counts, "--baseline", self.baseline)
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        self.assertIn("beta-scalar: +5.00 %", p.stderr)

    def test_malformed_baseline_exits_2_with_one_line(self):
        with open(self.baseline, "w") as f:
            f.write('{"workloads": {"alpha": {"instructions": "many"}}}')
        self.write_counts(1, 1)
        p = run_gate("--counts", self.counts, "--baseline", self.baseline)
        self.assertEqual(p.returncode, 2)
        self.assertEqual(len(p.stderr.strip().splitlines()), 1)
        self.assertIn(self.baseline, p.stderr)

    def test_missing_build_exits_2(self):
        p = run_gate("--build", os.path.join(self.tmp, "nothing"), "--baseline", self.baseline)
        self.assertEqual(p.returncode, 2)
        self.assertIn("simgrass_perf_workloads", p.stderr)


@unittest.skipUnless(BUILD and shutil.which("valgrind"), "needs a build directory and valgrind")
class RealWorkload(unittest.TestCase):
    def test_gate_passes_on_its_own_count_and_fails_on_a_lowered_baseline(self):
        with tempfile.TemporaryDirectory(prefix="perf-gate-selftest-") as tmp:
            baseline = os.path.join(tmp, "baseline.json")
            only = ("--build", BUILD, "--baseline", baseline, "--only", "meadow-fx32-k2")
            p = run_gate(*only, "--write-baseline")
            self.assertEqual(p.returncode, 0, p.stderr)
            p = run_gate(*only)
            self.assertEqual(p.returncode, 0, p.stdout + p.stderr)  # the same count again: +0.00 %
            with open(baseline) as f:
                data = json.load(f)
            data["workloads"]["meadow-fx32-k2"]["instructions"] = data["workloads"]["meadow-fx32-k2"]["instructions"] * 95 // 100
            with open(baseline, "w") as f:
                json.dump(data, f)
            p = run_gate(*only)
            self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
            self.assertIn("REGRESSION meadow-fx32-k2: +5.2", p.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
