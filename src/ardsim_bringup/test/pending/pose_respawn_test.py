#!/usr/bin/env python3
"""PENDING (needs ardsim_pose): the pose node killed mid-run is respawned (docking.launch respawn="true") and the
run still ends in capture or a safe abort, never a collision."""
import json
import os
import subprocess
import sys
import threading
import time
import unittest

import rostest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from scenario_run import ROOT, SCENARIOS, passed  # noqa: E402

PORT = 11893


class PoseRespawn(unittest.TestCase):
    def test_killed_pose_node_is_respawned(self):
        out = os.path.join(ROOT, ".home", "scenario_tests", "pose_respawn")
        subprocess.run(["rm", "-rf", out], check=True)
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % PORT)
        launch = subprocess.Popen(["roslaunch", "-p", str(PORT), os.path.join(ROOT, "launch", "docking.launch"),
                                   "scenario:=" + os.path.join(SCENARIOS, "dock_15m.yaml"), "out:=" + out,
                                   "pose_source:=estimator", "record:=true", "use_nodelets:=false"],
                                  env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        log = []
        threading.Thread(target=lambda: log.extend(launch.stdout), daemon=True).start()
        # Kill the pose node once the simulation is 40 s in (sim time read from /clock).
        killed = False
        deadline = time.monotonic() + 600
        while not killed and time.monotonic() < deadline and launch.poll() is None:
            try:
                t = float(subprocess.run(["rostopic", "echo", "-n", "1", "/clock/clock/secs"], env=env, text=True,
                                         stdout=subprocess.PIPE, timeout=20).stdout.split()[0])
            except (subprocess.TimeoutExpired, IndexError, ValueError):
                continue
            if t >= 40:
                subprocess.run(["rosnode", "kill", "/pose"], env=env, check=True)
                killed = True
        self.assertTrue(killed, "never reached 40 s of sim time")
        launch.wait(timeout=900)
        text = "".join(log)
        self.assertIn("[pose-", text)
        self.assertIn("] restarting process", text)  # roslaunch respawned it
        with open(os.path.join(out, "run.json")) as f:
            s = json.load(f)
        self.assertFalse(s["collision"], s["reason"])
        self.assertTrue(s["docked"] or s["aborted"], "%s: %s" % (s["outcome"], s["reason"]))
        passed(out)


if __name__ == "__main__":
    rostest.rosrun("ardsim_bringup", "pose_respawn", PoseRespawn, sys.argv)
