#!/usr/bin/env python3
"""A bad parameter stops guidance_node and truth_pose at start with a message naming the parameter, its value and
the allowed range (exit status 1)."""
import subprocess
import sys
import unittest

import rostest


def run(node, name, arg):
    p = subprocess.run(["rosrun", "ardsim_guidance", node, "__name:=" + name, arg], capture_output=True, text=True,
                       timeout=60)
    return p.returncode, p.stdout + p.stderr


class BadParameter(unittest.TestCase):
    def test_guidance_contact_speed(self):
        rc, out = run("guidance_node", "bad_guidance_1", "_approach/contact_speed_mps:=-0.5")
        self.assertEqual(rc, 1, out)
        self.assertIn("approach/contact_speed_mps", out)
        self.assertIn("-0.5", out)
        self.assertIn("allowed range", out)

    def test_guidance_velocity_source(self):
        rc, out = run("guidance_node", "bad_guidance_2", "_navigator/velocity_source:=magic")
        self.assertEqual(rc, 1, out)
        self.assertIn("magic", out)
        self.assertIn("kalman", out)

    def test_truth_pose_dropout(self):
        rc, out = run("truth_pose", "bad_truth_pose", "_dropout_probability:=2.0")
        self.assertEqual(rc, 1, out)
        self.assertIn("dropout_probability", out)
        self.assertIn("[0, 1]", out)


if __name__ == "__main__":
    rostest.rosrun("ardsim_guidance", "bad_parameter", BadParameter, sys.argv)
