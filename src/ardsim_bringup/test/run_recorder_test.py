#!/usr/bin/env python3
"""run_recorder on its own master (rostest): every message of a burst lands in the bag, latched topics keep their
latching, record/progress is the oldest of the progress topics' latest stamps (of those with a publisher), SIGINT closes the bag (BAG.active
renamed); a bad parameter stops it at start naming the parameter, its value and what is allowed (exit status 1)."""
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import rosbag
import rospy
import rostest
from geometry_msgs.msg import PointStamped
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String

BURST = 3000


def recorder(*args):
    return ["rosrun", "ardsim_bringup", "run_recorder"] + list(args)


class RunRecorder(unittest.TestCase):
    def test_bad_parameters(self):
        for name, value, allowed in [("buffer_mb", "-1", "0 .. 65536"),
                                     ("progress_topics", "/elsewhere", "topics among ~topics")]:
            p = subprocess.run(recorder("__name:=bad_" + name, "_bag:=/tmp/never.bag", "_topics:=/a /b",
                                        "_%s:=%s" % (name, value)), capture_output=True, text=True, timeout=60)
            out = p.stdout + p.stderr
            self.assertEqual(p.returncode, 1, out)
            self.assertIn("~" + name, out)
            self.assertIn(value, out)
            self.assertIn(allowed, out)
        p = subprocess.run(recorder("__name:=bad_topics", "_bag:=/tmp/never.bag"), capture_output=True, text=True,
                           timeout=60)
        self.assertEqual(p.returncode, 1)
        self.assertIn("~topics", p.stdout + p.stderr)

    def test_burst_recorded_whole(self):
        rospy.init_node("run_recorder_test")
        clock = rospy.Publisher("/clock", Clock, queue_size=10, latch=True)
        fast = rospy.Publisher("burst/fast", PointStamped, queue_size=BURST + 10)
        slow = rospy.Publisher("burst/slow", PointStamped, queue_size=10)
        latched = rospy.Publisher("burst/latched", String, queue_size=1, latch=True)
        clock.publish(Clock(clock=rospy.Time(1.0)))
        latched.publish(String(data="latched"))
        out = tempfile.mkdtemp(prefix="run_recorder_test_")
        bag_path = os.path.join(out, "run.bag")
        proc = subprocess.Popen(recorder("__name:=record", "_bag:=" + bag_path,
                                         "_topics:=/burst/latched /burst/fast /burst/slow /burst/none /clock",
                                         "_progress_topics:=/burst/fast /burst/slow /burst/none"),
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        progress = []
        rospy.Subscriber("record/progress", Clock, lambda m: progress.append(m.clock.to_sec()))
        try:
            deadline = time.monotonic() + 30
            while (fast.get_num_connections() < 1 or slow.get_num_connections() < 1) and time.monotonic() < deadline:
                time.sleep(0.05)
            self.assertGreaterEqual(fast.get_num_connections(), 1, "the recorder did not subscribe")
            time.sleep(0.5)  # its other subscriptions connect too
            # The burst, in one go, far beyond rosbag record's queue of 100.
            for k in range(BURST):
                msg = PointStamped()
                msg.header.stamp = rospy.Time(1.0 + 0.001 * (k + 1))
                msg.point.x = k
                fast.publish(msg)
            # Progress is the oldest of the progress topics' latest stamps: the slow topic holds it back (/burst/none,
            # with no publisher, does not: a node that died).
            time.sleep(1.0)
            self.assertTrue(all(p < 1.0 + 1e-9 for p in progress), progress[-3:])
            slow_msg = PointStamped()
            slow_msg.header.stamp = rospy.Time(1.0 + 0.001 * BURST)
            slow.publish(slow_msg)
            deadline = time.monotonic() + 30
            while (not progress or progress[-1] < 1.0 + 0.001 * BURST - 1e-6) and time.monotonic() < deadline:
                time.sleep(0.05)
            self.assertAlmostEqual(progress[-1], 1.0 + 0.001 * BURST, places=6)
        finally:
            proc.send_signal(signal.SIGINT)
            log, _ = proc.communicate(timeout=30)
        self.assertEqual(proc.returncode, 0, log)
        self.assertIn("messages recorded", log)
        self.assertTrue(os.path.exists(bag_path), log)
        self.assertFalse(os.path.exists(bag_path + ".active"))
        with rosbag.Bag(bag_path) as bag:
            xs = [m.point.x for _, m, _ in bag.read_messages(topics=["/burst/fast"])]
            self.assertEqual(xs, [float(k) for k in range(BURST)])
            latched_msgs = list(bag.read_messages(topics=["/burst/latched"], return_connection_header=True))
            self.assertEqual(len(latched_msgs), 1)
            header = latched_msgs[0].connection_header  # keys and values are bytes or str by rosbag version
            self.assertIn(header.get(b"latching", header.get("latching")), (b"1", "1"))
            # Receipt times on the sim clock.
            times = [t.to_sec() for _, _, t in bag.read_messages(topics=["/burst/fast"])]
            self.assertAlmostEqual(min(times), 1.0, places=6)


if __name__ == "__main__":
    rostest.rosrun("ardsim_bringup", "run_recorder", RunRecorder, sys.argv)
