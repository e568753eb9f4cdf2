#!/usr/bin/env python3
"""A bad value in a scenario's node section ends the run with outcome error, the node and the parameter named, and
run_scenario's exit status 1: the pose nodelet (respawned by docking.launch, so it fails in a loop), the pose and
lidar as plain nodes (use_nodelets:=false), guidance, and a target no node knows. Before ardsim_msgs/startup_error.h the run waited for the
failed node forever (the dynamics waits for every subscriber before its first step). The bag is closed, empty."""
import json
import os
import subprocess
import sys
import unittest

import rosbag
import rostest
import yaml

from scenario_run import ROOT, SCENARIOS, passed

CASES = [  # (name, section, {key: bad value}, run_scenario args, what the reason names)
    ("pose_nodelet", "pose", {"icp": {"tukey_c": -1.0}}, [], ["/pose", "icp/tukey_c", "-1"]),
    ("pose_node", "pose", {"icp": {"max_iterations_tracking": 0}}, ["use_nodelets:=false"],
     ["pose", "icp/max_iterations_tracking"]),
    ("lidar_node", "lidar", {"noise": {"dead_pixel_fraction": 1.5}}, ["use_nodelets:=false"],
     ["lidar", "dead_pixel_fraction", "1.5"]),
    ("guidance", "guidance", {"approach": {"damping_ratio": -1.0}}, [], ["guidance", "approach/damping_ratio"]),
    # Every node reads the target: whichever refuses it first (static_frames here) names it.
    ("target", "target", {"kind": "foo"}, [], ["target", "foo"]),
]


class StartupError(unittest.TestCase):
    def test_bad_parameter_ends_the_run_naming_it(self):
        with open(os.path.join(SCENARIOS, "dock_15m.yaml")) as f:
            base = yaml.safe_load(f)
        for name, section, bad, args, named in CASES:
            with self.subTest(name):
                scenario = dict(base, name="startup_error_" + name)
                scenario[section] = dict(scenario.get(section) or {}, **bad)
                path = os.path.join(ROOT, ".home", "startup_error_%s.yaml" % name)
                out = os.path.join(ROOT, ".home", "scenario_tests", "startup_error_" + name)
                subprocess.run(["rm", "-rf", out], check=True)
                os.makedirs(os.path.dirname(path), exist_ok=True)
                with open(path, "w") as f:
                    yaml.safe_dump(scenario, f)
                # Within the subprocess's limit: a run that waits for the node would end "stalled" only after the
                # monitor's 120 s, and would fail the outcome check below.
                proc = subprocess.run([os.path.join(ROOT, "scripts", "run_scenario"), path, out, "rviz:=none"] + args,
                                      stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=300)
                print(proc.stdout[-2000:])
                self.assertEqual(proc.returncode, 1, proc.stdout[-3000:])
                self.assertIn("run_scenario: the run could not start: ", proc.stdout)
                with open(os.path.join(out, "run.json")) as f:
                    s = json.load(f)
                print("RUN %s %s" % (name, json.dumps(s, sort_keys=True)))
                self.assertEqual(s["outcome"], "error", s["reason"])
                for word in named:
                    self.assertIn(word, s["reason"])
                self.assertFalse(s["docked"] or s["collision"] or s["aborted"])
                self.assertEqual(s["frames"], 0)
                with rosbag.Bag(os.path.join(out, "run.bag")) as bag:  # closed (not left .active)
                    self.assertEqual(bag.get_message_count(), 0)
                passed(out)


if __name__ == "__main__":
    rostest.rosrun("ardsim_bringup", "startup_error", StartupError, sys.argv)
