#!/usr/bin/env python3
"""Closed-loop checker for the guidance scenario rostests (dynamics + truth_pose + guidance).

~expect: "capture": the chaser port reaches the target port plane (truth/relative x <= 0) with contact conditions
inside the capture envelope. The dynamics' Bullet contact detection is not used: the conditions are read from
truth/relative at the first message with x <= 0 (evaluation only; guidance never sees it).
~expect: "retreat": guidance/state reaches RETREAT with a reason naming LOST, and no contact happens.
~sim_time_limit_s: fail if the outcome has not happened by this simulation time.
"""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from ardsim_msgs.msg import GuidanceState
from nav_msgs.msg import Odometry

# Capture envelope (shared reference iss_geometry.md, IDSS initial contact conditions [memory]).
CLOSING_MIN_MPS, CLOSING_MAX_MPS = 0.05, 0.10
LATERAL_MAX_M = 0.10
LATERAL_RATE_MAX_MPS = 0.04
ANGULAR_MAX_RAD = math.radians(4.0)
ANGULAR_RATE_MAX_RAD_S = math.radians(0.15)


def quat_angle_from_docked(q):
    # Docked: chaser port = target port turned half a turn about z, i.e. quaternion (w, x, y, z) = (0, 0, 0, 1).
    # Angle of q relative to it: 2 acos(|<q, q_docked>|).
    dot = abs(q.z)
    return 2.0 * math.acos(min(1.0, dot))


class ClosedLoop(unittest.TestCase):
    def setUp(self):
        self.expect = rospy.get_param("~expect")
        self.limit = rospy.get_param("~sim_time_limit_s")
        self.lock = threading.Lock()
        self.contact = None
        self.retreat = None
        self.last_state = None
        self.last_time = 0.0
        self.prev_x = None
        rospy.Subscriber("truth/relative", Odometry, self.on_relative, queue_size=1000)
        rospy.Subscriber("guidance/state", GuidanceState, self.on_state, queue_size=1000)
        # Counted by the dynamics' wait_for_subscribers, so that the run starts only once this checker listens.
        rospy.Subscriber("truth/chaser/odom", Odometry, lambda msg: None, queue_size=1)

    def on_relative(self, msg):
        p, v, w = msg.pose.pose.position, msg.twist.twist.linear, msg.twist.twist.angular
        with self.lock:
            self.last_time = msg.header.stamp.to_sec()
            if self.contact is None and p.x <= 0.0 and (self.prev_x is None or self.prev_x > 0.0):
                self.contact = {
                    "t": msg.header.stamp.to_sec(),
                    "closing_mps": -v.x,
                    "lateral_m": math.hypot(p.y, p.z),
                    "lateral_rate_mps": math.hypot(v.y, v.z),
                    "angular_rad": quat_angle_from_docked(msg.pose.pose.orientation),
                    "angular_rate_rad_s": math.sqrt(w.x ** 2 + w.y ** 2 + w.z ** 2),
                    "delta_v_mps": self.last_state.delta_v_used_mps if self.last_state else float("nan"),
                }
            self.prev_x = p.x

    def on_state(self, msg):
        with self.lock:
            self.last_state = msg
            if self.retreat is None and msg.phase == GuidanceState.PHASE_RETREAT:
                self.retreat = (msg.header.stamp.to_sec(), msg.reason)

    def wait(self, done):
        # Decided on simulation time; the wall-clock guard only turns a stalled run into a failure.
        wall_deadline = rospy.get_param("~wall_time_limit_s", 170.0)
        t0 = time.monotonic()
        while not rospy.is_shutdown() and time.monotonic() - t0 < wall_deadline:
            with self.lock:
                if done() or self.last_time > self.limit:
                    return
            time.sleep(0.05)

    def test_outcome(self):
        if self.expect == "capture":
            self.wait(lambda: self.contact is not None)
            with self.lock:
                c, r = self.contact, self.retreat
            self.assertIsNone(r, "guidance retreated: %s" % (r,))
            self.assertIsNotNone(c, "no contact by t = %.1f s (last truth at %.1f s)" % (self.limit, self.last_time))
            rospy.loginfo("closed loop contact: t %.1f s, closing %.4f m/s, lateral %.4f m, lateral rate %.4f m/s, "
                          "angular %.3f deg, angular rate %.4f deg/s, delta-v %.3f m/s", c["t"], c["closing_mps"],
                          c["lateral_m"], c["lateral_rate_mps"], math.degrees(c["angular_rad"]),
                          math.degrees(c["angular_rate_rad_s"]), c["delta_v_mps"])
            print("CONTACT %s" % c)
            self.assertGreaterEqual(c["closing_mps"], CLOSING_MIN_MPS)
            self.assertLessEqual(c["closing_mps"], CLOSING_MAX_MPS)
            self.assertLessEqual(c["lateral_m"], LATERAL_MAX_M)
            self.assertLessEqual(c["lateral_rate_mps"], LATERAL_RATE_MAX_MPS)
            self.assertLessEqual(c["angular_rad"], ANGULAR_MAX_RAD)
            self.assertLessEqual(c["angular_rate_rad_s"], ANGULAR_RATE_MAX_RAD_S)
        else:
            self.wait(lambda: self.retreat is not None)
            with self.lock:
                c, r = self.contact, self.retreat
            self.assertIsNotNone(r, "no RETREAT by t = %.1f s" % self.limit)
            self.assertIn("LOST", r[1])
            self.assertIsNone(c, "contact although the estimate was lost")
            print("RETREAT at %.1f s: %s" % r)


if __name__ == "__main__":
    rospy.init_node("closed_loop_checker")
    rostest.rosrun("ardsim_guidance", "closed_loop_checker", ClosedLoop, sys.argv)
