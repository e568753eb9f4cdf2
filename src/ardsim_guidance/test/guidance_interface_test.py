#!/usr/bin/env python3
"""Interface test of guidance_node: one command per estimate with the estimate's stamp (a repeated estimate, as a
latched message delivered twice, is not answered again); LOST -> hold command, then
RETREAT after the limit; NaN / zero quaternions -> hold command and the node keeps running. No dynamics: the test
publishes truth/chaser/odom (the chaser's own state) and pose/estimate itself, with consistent geometry (chaser
port 20 m out on the ISS docking axis, docking attitude)."""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from ardsim_msgs.msg import GuidanceState, PoseEstimate
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry

R_ORBIT = 6793137.0
V_ORBIT = math.sqrt(3.986004415e14 / R_ORBIT)


def chaser_odom(stamp):
    m = Odometry()
    m.header.stamp = stamp
    m.header.frame_id = "eci"
    m.child_frame_id = "chaser"
    m.pose.pose.position.x = R_ORBIT
    m.twist.twist.linear.y = V_ORBIT
    # Docking attitude at (R, 0, 0) moving along +y: body x = -y_eci, body y = +z_eci, body z = -x_eci.
    # Rotation matrix [[0,0,-1],[-1,0,0],[0,1,0]] -> quaternion (w, x, y, z) = (0.5, 0.5, -0.5, -0.5).
    m.pose.pose.orientation.w, m.pose.pose.orientation.x = 0.5, 0.5
    m.pose.pose.orientation.y, m.pose.pose.orientation.z = -0.5, -0.5
    return m


def estimate(stamp, status=PoseEstimate.STATUS_TRACKING, q=(0.5, -0.5, 0.5, 0.5)):
    # Target body in lidar_optical with the chaser port 20 m out on the axis: translation (0, -4.5, 35.5),
    # rotation [[0,-1,0],[0,0,1],[-1,0,0]] -> quaternion (w, x, y, z) = (0.5, -0.5, 0.5, 0.5).
    m = PoseEstimate()
    m.header.stamp = stamp
    m.header.frame_id = "lidar_optical"
    m.method = PoseEstimate.METHOD_TRUTH
    m.status = status
    m.pose.pose.position.y, m.pose.pose.position.z = -4.5, 35.5
    o = m.pose.pose.orientation
    o.w, o.x, o.y, o.z = q
    return m


class GuidanceInterface(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.commands, self.states = [], []
        rospy.Subscriber("guidance/command", WrenchStamped, self.on_command, queue_size=1000)
        rospy.Subscriber("guidance/state", GuidanceState, self.on_state, queue_size=1000)
        self.odom_pub = rospy.Publisher("truth/chaser/odom", Odometry, queue_size=1000)
        self.est_pub = rospy.Publisher("pose/estimate", PoseEstimate, queue_size=1000)
        deadline = time.monotonic() + 30.0
        while (self.odom_pub.get_num_connections() < 1 or self.est_pub.get_num_connections() < 1) and \
                time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)
        self.t = 100.0

    def on_command(self, msg):
        with self.lock:
            self.commands.append(msg)

    def on_state(self, msg):
        with self.lock:
            self.states.append(msg)

    def send(self, status=PoseEstimate.STATUS_TRACKING, q=(0.5, -0.5, 0.5, 0.5)):
        self.t += 0.1
        stamp = rospy.Time.from_sec(round(self.t, 1))
        self.odom_pub.publish(chaser_odom(stamp))
        self.est_pub.publish(estimate(stamp, status, q))
        return stamp

    def wait_for(self, count):
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            with self.lock:
                if len(self.commands) >= count and len(self.states) >= count:
                    return
            time.sleep(0.02)

    def test_interface(self):
        stamps = []
        # Tracking, then malformed quaternions, then LOST for longer than the 3 s limit.
        for i in range(20):
            stamps.append(self.send())
            if i in (0, 7):  # the same step again: no second command
                self.est_pub.publish(estimate(stamps[-1]))
        stamps.append(self.send(q=(float("nan"), 0.0, 0.0, 0.0)))
        stamps.append(self.send(q=(0.0, 0.0, 0.0, 0.0)))
        for _ in range(40):
            stamps.append(self.send(status=PoseEstimate.STATUS_LOST))
            time.sleep(0.002)
        self.wait_for(len(stamps))
        time.sleep(0.5)  # a second answer, if any, would have come by now
        with self.lock:
            commands, states = list(self.commands), list(self.states)
        # One command per estimate, same stamps, in order, frame "chaser".
        self.assertEqual([c.header.stamp for c in commands], stamps)
        self.assertTrue(all(c.header.frame_id == "chaser" for c in commands))
        for c in commands:
            f, tq = c.wrench.force, c.wrench.torque
            self.assertTrue(all(math.isfinite(v) for v in (f.x, f.y, f.z, tq.x, tq.y, tq.z)))
        # Tracking at 20 m on the axis: near-field approach.
        self.assertIn(states[19].phase, (GuidanceState.PHASE_APPROACH, GuidanceState.PHASE_HOLD))
        self.assertAlmostEqual(states[19].range_m, 20.0, delta=0.5)
        # Malformed quaternions: hold.
        for i in (20, 21):
            self.assertEqual(states[i].phase, GuidanceState.PHASE_HOLD, states[i].reason)
            self.assertIn("malformed", states[i].reason)
        # LOST: hold within the limit, RETREAT after it (the last usable estimate was at index 19).
        self.assertEqual(states[22].phase, GuidanceState.PHASE_HOLD)
        t_last_good = stamps[19].to_sec()
        for s, stamp in zip(states[22:], stamps[22:]):
            if stamp.to_sec() - t_last_good > 3.0 + 1e-6:
                self.assertEqual(s.phase, GuidanceState.PHASE_RETREAT, s.reason)
            elif stamp.to_sec() - t_last_good < 3.0 - 1e-6:
                self.assertEqual(s.phase, GuidanceState.PHASE_HOLD, s.reason)
        self.assertIn("LOST", states[-1].reason)


if __name__ == "__main__":
    rospy.init_node("guidance_interface_test")
    rostest.rosrun("ardsim_guidance", "guidance_interface", GuidanceInterface, sys.argv)
