#!/usr/bin/env python3
"""dynamics_node with recorder_lag_steps 3: step k waits for record/progress at step k - 3; a recorder that does
not catch up within recorder_timeout_s (2 s) is no longer waited for."""
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

STEP_S = 0.1
LAG = 3


class RecorderLag(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Condition()
        self.chaser = {}
        rospy.Subscriber("truth/chaser/odom", Odometry, self.on_chaser, queue_size=100)
        self.command_pub = rospy.Publisher("guidance/command", WrenchStamped, queue_size=10, latch=True)
        self.progress_pub = rospy.Publisher("record/progress", Clock, queue_size=10, latch=True)

    def on_chaser(self, msg):
        with self.lock:
            self.chaser[msg.header.stamp.to_nsec()] = msg
            self.lock.notify_all()

    def wait_for_step(self, k, timeout_s=60.0):
        stamp_ns = rospy.Time(k * STEP_S).to_nsec()
        with self.lock:
            ok = self.lock.wait_for(lambda: stamp_ns in self.chaser, timeout=timeout_s)
        self.assertTrue(ok, "step %d never published" % k)

    def latest_step(self):
        with self.lock:
            return int(round(max(self.chaser) * 1e-9 / STEP_S))

    def command(self, k):
        msg = WrenchStamped()
        msg.header.stamp = rospy.Time(k * STEP_S)
        msg.header.frame_id = "chaser"
        self.command_pub.publish(msg)

    def test_waits_for_the_recorder_then_gives_up(self):
        # Steps 0 .. LAG need no progress.
        for k in range(LAG + 1):
            self.wait_for_step(k)
            self.command(k)
        # Step LAG + 1 needs step 1 recorded: it waits (well within recorder_timeout_s).
        time.sleep(0.5)
        self.assertEqual(self.latest_step(), LAG, "ran ahead of the recorder")
        self.progress_pub.publish(Clock(clock=rospy.Time(0.0)))  # step 0 is not enough
        time.sleep(0.5)
        self.assertEqual(self.latest_step(), LAG, "ran ahead of the recorder")
        self.progress_pub.publish(Clock(clock=rospy.Time(1 * STEP_S)))
        self.wait_for_step(LAG + 1, timeout_s=1.0)
        # The recorder stops: step LAG + 2 comes only after recorder_timeout_s (2 s), and from then on no step waits.
        started = time.monotonic()
        self.command(LAG + 1)
        self.wait_for_step(LAG + 2, timeout_s=30.0)
        self.assertGreater(time.monotonic() - started, 1.5)
        for k in range(LAG + 2, 10):
            started = time.monotonic()
            self.command(k)
            self.wait_for_step(k + 1, timeout_s=30.0)
            self.assertLess(time.monotonic() - started, 1.5, "waited for a recorder given up")


if __name__ == "__main__":
    rospy.init_node("recorder_lag_test")
    rostest.rosrun("ardsim_dynamics", "recorder_lag", RecorderLag)
