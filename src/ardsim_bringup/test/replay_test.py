#!/usr/bin/env python3
"""A recorded run (dock_15m cut at 40 s: the estimator in the loop) replayed through launch/replay.launch reproduces
every recorded estimate exactly (the same parameters, the same code): a regression test of the pose algorithms."""
import json
import os
import socket
import subprocess
import sys
import unittest

import rosbag
import rostest

from scenario_run import ROOT, bag_info, passed, run_scenario, scenario_variant


class Replay(unittest.TestCase):
    def test_replay_reproduces_the_estimates(self):
        scenario = scenario_variant("replay_40s", "dock_15m.yaml", time_limit_s=40.0)
        # At most 5x real time: the live run's recorder is outside the lockstep, and a cloud it drops on a loaded
        # machine breaks the replay's sequence (unthrottled, ~16x, it writes ~100 MB/s).
        out, s = run_scenario(self, scenario, "rviz:=none", "record:=true", "pose_source:=estimator",
                              "real_time_factor:=5")
        self.assertEqual(s["outcome"], "time_limit")
        recorded = {t["topic"]: t["messages"] for t in bag_info(os.path.join(out, "run.bag"))["topics"]}
        with rosbag.Bag(os.path.join(out, "run.bag")) as bag:
            # The header stamp from the serialized cloud (seq, then secs and nsecs): no need to decode the points.
            stamps = [int.from_bytes(m[1][4:8], "little") + 1e-9 * int.from_bytes(m[1][8:12], "little")
                      for _, m, _ in bag.read_messages(topics=["/lidar/points"], raw=True)]
        periods = {round(b - a, 3) for a, b in zip(stamps, stamps[1:])}
        self.assertEqual(len(periods), 1, "the live run's recorder lost clouds (periods %s s)" % sorted(periods))
        with socket.socket() as probe:  # a free port for a master of our own
            probe.bind(("127.0.0.1", 0))
            port = probe.getsockname()[1]
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port)
        proc = subprocess.run(["roslaunch", "-p", str(port), os.path.join(ROOT, "launch", "replay.launch"),
                               "bag:=" + os.path.join(out, "run.bag")], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, timeout=1200)
        print(proc.stdout[-3000:])
        self.assertEqual(proc.returncode, 0, proc.stdout[-3000:])
        with open(os.path.join(out, "replay.json")) as f:
            r = json.load(f)
        self.assertEqual(r["missing"], 0)
        self.assertGreater(r["compared"], 390)
        self.assertEqual(r["compared"], r["recorded_estimates"])
        # Every recorded cloud is replayed; every recorded estimate is compared (the bag may lack the estimates of the
        # first cloud, recorded before the estimator had advertised, and of the last, made after the recorder stopped).
        self.assertEqual(r["frames"], recorded["/lidar/points"])
        self.assertEqual(r["identical"], r["compared"], r["first_mismatch"])
        info = bag_info(os.path.join(out, "replay.bag"))
        topics = {t["topic"]: t["messages"] for t in info["topics"]}
        self.assertEqual(topics["/replay/pose/estimate"], r["frames"])
        self.assertIn("/replay/pose/error", topics)
        passed(out)


if __name__ == "__main__":
    rostest.rosrun("ardsim_bringup", "replay", Replay, sys.argv)
