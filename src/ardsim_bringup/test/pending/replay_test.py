#!/usr/bin/env python3
"""PENDING (needs ardsim_pose): a recorded run replayed through launch/replay.launch reproduces every estimate
exactly (the same parameters, the same code)."""
import json
import os
import subprocess
import sys
import unittest

import rostest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from scenario_run import ROOT, SCENARIOS, bag_info, passed, run_scenario  # noqa: E402


class Replay(unittest.TestCase):
    def test_replay_reproduces_the_estimates(self):
        out, s = run_scenario(self, os.path.join(SCENARIOS, "dock_15m.yaml"), "rviz:=none", "record:=true",
                              "pose_source:=estimator")
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:11891")
        proc = subprocess.run(["roslaunch", "-p", "11891", os.path.join(ROOT, "launch", "replay.launch"),
                               "bag:=" + os.path.join(out, "run.bag")], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, timeout=1200)
        print(proc.stdout[-3000:])
        with open(os.path.join(out, "replay.json")) as f:
            r = json.load(f)
        self.assertEqual(r["missing"], 0)
        self.assertGreater(r["compared"], 1000)
        self.assertEqual(r["compared"], r["recorded_estimates"])
        self.assertEqual(r["identical"], r["compared"], r["first_mismatch"])
        info = bag_info(os.path.join(out, "replay.bag"))
        topics = {t["topic"]: t["messages"] for t in info["topics"]}
        self.assertEqual(topics["/replay/pose/estimate"], r["compared"])
        self.assertIn("/replay/pose/error", topics)
        passed(out)


if __name__ == "__main__":
    rostest.rosrun("ardsim_bringup", "replay", Replay, sys.argv)
