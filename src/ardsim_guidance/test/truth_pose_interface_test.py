#!/usr/bin/env python3
"""Interface test of the truth_pose test tool: one METHOD_TRUTH estimate per stamp at which both truth odometries
arrived, equal to the truth T_lidar_target (no noise configured), LOST inside a scripted interval, nothing for a
stamp with only one odometry."""
import sys
import threading
import time
import unittest

import rospy
import rostest
from ardsim_msgs.msg import PoseEstimate
from nav_msgs.msg import Odometry

R_ORBIT = 6793137.0


def odom(stamp, child, position, q):
    m = Odometry()
    m.header.stamp = stamp
    m.header.frame_id = "eci"
    m.child_frame_id = child
    m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z = position
    o = m.pose.pose.orientation
    o.w, o.x, o.y, o.z = q
    m.twist.twist.linear.y = 7660.0
    return m


class TruthPoseInterface(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.estimates = []
        rospy.Subscriber("pose/estimate", PoseEstimate, self.on_estimate, queue_size=1000)
        self.target_pub = rospy.Publisher("truth/target/odom", Odometry, queue_size=100)
        self.chaser_pub = rospy.Publisher("truth/chaser/odom", Odometry, queue_size=100)
        deadline = time.monotonic() + 30.0
        while (self.target_pub.get_num_connections() < 1 or self.chaser_pub.get_num_connections() < 1) and \
                time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)

    def on_estimate(self, msg):
        with self.lock:
            self.estimates.append(msg)

    def test_interface(self):
        # Target at (R, 0, 0) in LVLH attitude; chaser in docking attitude with its port 20 m out on the ISS axis:
        # T_lidar_target = translation (0, -4.5, 35.5).
        target_q = (0.5, -0.5, -0.5, 0.5)
        chaser_q = (0.5, 0.5, -0.5, -0.5)
        stamps = [rospy.Time.from_sec(0.1 * k) for k in range(1, 8)]
        for s in stamps:
            self.chaser_pub.publish(odom(s, "chaser", (R_ORBIT - 4.5, 37.5, 0.0), chaser_q))
            self.target_pub.publish(odom(s, "target", (R_ORBIT, 0.0, 0.0), target_q))
            time.sleep(0.01)
        # Only the chaser at this stamp: no estimate.
        self.chaser_pub.publish(odom(rospy.Time.from_sec(0.8), "chaser", (R_ORBIT - 4.5, 37.5, 0.0), chaser_q))
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline:
            with self.lock:
                if len(self.estimates) >= len(stamps):
                    break
            time.sleep(0.05)
        time.sleep(0.5)
        with self.lock:
            est = list(self.estimates)
        self.assertEqual([e.header.stamp for e in est], stamps)
        for e in est:
            self.assertEqual(e.method, PoseEstimate.METHOD_TRUTH)
            self.assertEqual(e.header.frame_id, "lidar_optical")
            lost = 0.35 <= e.header.stamp.to_sec() <= 0.45
            self.assertEqual(e.status, PoseEstimate.STATUS_LOST if lost else PoseEstimate.STATUS_TRACKING)
            if not lost:
                p = e.pose.pose.position
                self.assertAlmostEqual(p.x, 0.0, delta=1e-6)
                self.assertAlmostEqual(p.y, -4.5, delta=1e-6)
                self.assertAlmostEqual(p.z, 35.5, delta=1e-6)
                q = e.pose.pose.orientation
                # Expected rotation [[0,-1,0],[0,0,1],[-1,0,0]]: quaternion +-(0.5, -0.5, 0.5, 0.5).
                dot = abs(0.5 * q.w - 0.5 * q.x + 0.5 * q.y + 0.5 * q.z)
                self.assertAlmostEqual(dot, 1.0, delta=1e-9)


if __name__ == "__main__":
    rospy.init_node("truth_pose_interface_test")
    rostest.rosrun("ardsim_guidance", "truth_pose_interface", TruthPoseInterface, sys.argv)
