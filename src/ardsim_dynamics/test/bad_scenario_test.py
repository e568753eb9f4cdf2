#!/usr/bin/env python3
"""dynamics_node stops at start, non-zero, naming the key or parameter, its value and the allowed range."""
import os
import subprocess
import tempfile
import unittest

import rospkg
import rostest

SCENARIOS = os.path.join(rospkg.RosPack().get_path("ardsim_dynamics"), "scenarios")


def run_node(name, *params):
    args = ["rosrun", "ardsim_dynamics", "dynamics_node", "__name:=" + name] + ["_%s:=%s" % p for p in params]
    result = subprocess.run(args, capture_output=True, text=True, timeout=60)
    return result.returncode, result.stdout + result.stderr


class BadScenario(unittest.TestCase):
    def test_bad_key_in_scenario_file(self):
        with open(os.path.join(SCENARIOS, "free_drift.yaml")) as f:
            text = f.read().replace("mass_kg: 12519.0", "mass_kg: -5")
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            f.write(text)
        code, output = run_node("bad_mass", ("scenario", f.name))
        self.assertNotEqual(code, 0)
        self.assertIn("chaser.mass_kg", output)
        self.assertIn("-5", output)
        self.assertIn("(0, 1e+07]", output)

    def test_bad_parameter(self):
        code, output = run_node(
            "bad_rtf", ("scenario", os.path.join(SCENARIOS, "free_drift.yaml")), ("real_time_factor", "-1.0")
        )
        self.assertNotEqual(code, 0)
        self.assertIn("~real_time_factor", output)
        self.assertIn("-1.0", output)
        self.assertIn("[0.0", output)

    def test_missing_file(self):
        code, output = run_node("missing_file", ("scenario", "/nonexistent/scenario.yaml"))
        self.assertNotEqual(code, 0)
        self.assertIn("/nonexistent/scenario.yaml", output)


if __name__ == "__main__":
    rostest.rosrun("ardsim_dynamics", "bad_scenario", BadScenario)
