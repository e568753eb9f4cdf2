#!/usr/bin/env python3
"""The pose node killed 20 s into a run (dock_15m, the estimator as a node) is respawned (docking.launch
respawn="true") and the run still ends in capture or a safe abort (10 s of retreat), never a collision."""
import json
import os
import socket
import subprocess
import sys
import threading
import time
import unittest

import rostest

from scenario_run import ROOT, passed, scenario_variant



class PoseRespawn(unittest.TestCase):
    def test_killed_pose_node_is_respawned(self):
        out = os.path.join(ROOT, ".home", "scenario_tests", "pose_respawn")
        subprocess.run(["rm", "-rf", out], check=True)
        with socket.socket() as probe:  # a free port for a master of our own
            probe.bind(("127.0.0.1", 0))
            port = probe.getsockname()[1]
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port)
        launch = subprocess.Popen(["roslaunch", "-p", str(port), os.path.join(ROOT, "launch", "docking.launch"),
                                   "scenario:=" + scenario_variant("respawn", "dock_15m.yaml", abort_settle_s=10.0),
                                   "out:=" + out,
                                   "pose_source:=estimator", "record:=true", "use_nodelets:=false"],
                                  env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        log = []
        threading.Thread(target=lambda: log.extend(launch.stdout), daemon=True).start()
        # Kill the pose node once the simulation is 20 s in (sim time read from /clock).
        killed = False
        deadline = time.monotonic() + 600
        while not killed and time.monotonic() < deadline and launch.poll() is None:
            try:
                t = float(subprocess.run(["rostopic", "echo", "-n", "1", "/clock/clock/secs"], env=env, text=True,
                                         stdout=subprocess.PIPE, timeout=20).stdout.split()[0])
            except (subprocess.TimeoutExpired, IndexError, ValueError):
                continue
            if t >= 20:
                subprocess.run(["rosnode", "kill", "/pose"], env=env, check=True)
                killed = True
        self.assertTrue(killed, "never reached 20 s of sim time; roslaunch said:\n" + "".join(log)[-3000:])
        launch.wait(timeout=900)
        text = "".join(log)
        self.assertIn("[pose-", text)
        self.assertIn("] restarting process", text)  # roslaunch respawned it
        with open(os.path.join(out, "run.json")) as f:
            s = json.load(f)
        print("RUN %s" % json.dumps(s, sort_keys=True))
        self.assertFalse(s["collision"], s["reason"])
        self.assertTrue(s["docked"] or s["aborted"], "%s: %s" % (s["outcome"], s["reason"]))
        passed(out)


if __name__ == "__main__":
    rostest.rosrun("ardsim_bringup", "pose_respawn", PoseRespawn, sys.argv)
