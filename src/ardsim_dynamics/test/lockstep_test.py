#!/usr/bin/env python3
"""Plays guidance against dynamics_node and checks the lockstep protocol."""
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

STEP_S = 0.1
THRUST_N = 100.0
CHASER_MASS_KG = 12519.0  # free_drift.yaml


class Lockstep(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Condition()
        self.chaser, self.relative, self.applied, self.clock = {}, {}, {}, {}
        rospy.Subscriber("truth/chaser/odom", Odometry, self.store(self.chaser), queue_size=100)
        rospy.Subscriber("truth/relative", Odometry, self.store(self.relative), queue_size=100)
        rospy.Subscriber("dynamics/applied_wrench", WrenchStamped, self.store(self.applied), queue_size=100)
        rospy.Subscriber("/clock", Clock, self.on_clock, queue_size=100)
        self.command_pub = rospy.Publisher("guidance/command", WrenchStamped, queue_size=10, latch=True)

    def on_clock(self, msg):
        with self.lock:
            self.clock[msg.clock.to_nsec()] = msg
            self.lock.notify_all()

    def store(self, table):
        def callback(msg):
            with self.lock:
                table[msg.header.stamp.to_nsec()] = msg
                self.lock.notify_all()
        return callback

    def wait_for(self, table, stamp_ns, timeout_s=60.0):
        with self.lock:
            ok = self.lock.wait_for(lambda: stamp_ns in table, timeout=timeout_s)
        self.assertTrue(ok, "no message stamped %.1f s" % (stamp_ns * 1e-9))
        return table[stamp_ns]

    def test_protocol(self):
        steps = 30  # duration_s = 3.0
        for k in range(steps):
            stamp = rospy.Time(k * STEP_S)
            truth = self.wait_for(self.chaser, stamp.to_nsec())
            self.assertEqual(truth.header.frame_id, "eci")
            self.assertEqual(truth.child_frame_id, "chaser")
            self.wait_for(self.relative, stamp.to_nsec())
            # The clock says t_k while the step is open (topics arrive in any order: wait for it, then check nothing
            # later came).
            self.wait_for(self.clock, stamp.to_nsec())
            with self.lock:
                self.assertEqual(max(self.clock), stamp.to_nsec())
            if k < 3:
                # It must wait for the command: nothing newer appears in the meantime.
                time.sleep(0.5)
                with self.lock:
                    self.assertEqual(max(self.chaser), stamp.to_nsec(), "dynamics advanced without a command")
            command = WrenchStamped()
            command.header.stamp = stamp
            command.header.frame_id = "chaser"
            command.wrench.force.x = THRUST_N if k < 10 else 0.0
            self.command_pub.publish(command)
        # The last step is published (t = 3.0 s) and the applied wrench of every step came back.
        self.wait_for(self.chaser, rospy.Time(steps * STEP_S).to_nsec())
        for k in range(steps):
            applied = self.wait_for(self.applied, rospy.Time(k * STEP_S).to_nsec())
            self.assertAlmostEqual(applied.wrench.force.x, THRUST_N if k < 10 else 0.0, places=9)
        # 1 s of 100 N along the chaser port axis closes the ports at 100 / m m/s (the port axes are anti-parallel).
        v0 = self.relative[0].twist.twist.linear.x
        v1 = self.relative[rospy.Time(1.0).to_nsec()].twist.twist.linear.x
        self.assertAlmostEqual(v1 - v0, -THRUST_N / CHASER_MASS_KG, delta=2e-4)


if __name__ == "__main__":
    rospy.init_node("lockstep_test")
    rostest.rosrun("ardsim_dynamics", "lockstep", Lockstep)
