#!/usr/bin/env python3
"""A missing command times out to a zero wrench with a warning; bad and stale commands change nothing."""
import math
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log

STEP_S = 0.1
TIMEOUT_S = 1.0  # command_timeout_s in missing_command.test


class MissingCommand(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Condition()
        self.chaser, self.applied, self.arrival, self.warnings = {}, {}, {}, []
        rospy.Subscriber("truth/chaser/odom", Odometry, self.on_truth, queue_size=100)
        rospy.Subscriber("dynamics/applied_wrench", WrenchStamped, self.on_applied, queue_size=100)
        rospy.Subscriber("/rosout_agg", Log, self.on_log, queue_size=100)
        rospy.Subscriber("/rosout", Log, self.on_log, queue_size=100)
        self.command_pub = rospy.Publisher("guidance/command", WrenchStamped, queue_size=10, latch=True)

    def on_truth(self, msg):
        with self.lock:
            self.chaser[msg.header.stamp.to_nsec()] = msg
            self.arrival[msg.header.stamp.to_nsec()] = time.monotonic()
            self.lock.notify_all()

    def on_applied(self, msg):
        with self.lock:
            self.applied[msg.header.stamp.to_nsec()] = msg
            self.lock.notify_all()

    def on_log(self, msg):
        if msg.level >= Log.WARN:
            self.warnings.append(msg.msg)

    def wait_for(self, table, stamp_ns, timeout_s=60.0):
        with self.lock:
            ok = self.lock.wait_for(lambda: stamp_ns in table, timeout=timeout_s)
        self.assertTrue(ok, "no message stamped %.1f s" % (stamp_ns * 1e-9))
        return table[stamp_ns]

    def command(self, t, force_x, frame="chaser"):
        msg = WrenchStamped()
        msg.header.stamp = rospy.Time(t)
        msg.header.frame_id = frame
        msg.wrench.force.x = force_x
        self.command_pub.publish(msg)

    def test_timeouts_and_bad_commands(self):
        for k in range(10):
            t = k * STEP_S
            self.wait_for(self.chaser, rospy.Time(t).to_nsec())
            if k == 3:
                continue  # guidance "crashed" for this step
            if k == 5:
                self.command(t, float("nan"))  # malformed: applied as zero
            elif k == 6:
                self.command(t - STEP_S, 50.0)  # stale: ignored...
                time.sleep(0.2)
                self.command(t, 20.0)  # ...and the right one still counts
            else:
                self.command(t, 10.0)
        self.wait_for(self.chaser, rospy.Time(1.0).to_nsec())
        gap = self.arrival[rospy.Time(0.4).to_nsec()] - self.arrival[rospy.Time(0.3).to_nsec()]
        self.assertGreaterEqual(gap, 0.9 * TIMEOUT_S, "step 4 came before the command timeout")
        expected = {3: 0.0, 5: 0.0, 6: 20.0}
        for k in range(10):
            applied = self.wait_for(self.applied, rospy.Time(k * STEP_S).to_nsec())
            self.assertTrue(math.isfinite(applied.wrench.force.x))
            self.assertAlmostEqual(applied.wrench.force.x, expected.get(k, 10.0), places=9, msg="step %d" % k)
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline and not (
            any("no guidance/command" in w for w in self.warnings) and any("non-finite" in w for w in self.warnings)
        ):
            time.sleep(0.1)
        self.assertTrue(any("no guidance/command for t = 0.300" in w for w in self.warnings), self.warnings)
        self.assertTrue(any("non-finite guidance/command" in w for w in self.warnings), self.warnings)


if __name__ == "__main__":
    rospy.init_node("missing_command_test")
    rostest.rosrun("ardsim_dynamics", "missing_command", MissingCommand)
