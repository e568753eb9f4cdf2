#!/usr/bin/env python3
"""Closed-loop checker for the guidance scenario rostests (dynamics + truth_pose + guidance).

The outcome of a docking is the dynamics' verdict on the first contact (dynamics/contact, ardsim_msgs/ContactEvent:
Bullet shapes of both vehicles, conditions of the chaser port in the target port, the capture envelope of the
scenario).
~expect: "capture": one ContactEvent, verdict CAPTURE, every condition within the envelope, guidance never retreated.
~expect: "collision": one ContactEvent, verdict COLLISION.
~expect: "retreat": guidance/state reaches RETREAT with a reason naming LOST, and no contact happens.
~sim_time_limit_s: fail if the outcome has not happened by this simulation time.

Also measured and printed (CONTACT line): the commanded delta-v (GuidanceState.delta_v_used_mps) and the RMS of the
commanded force magnitude over the last 10 m (true port x <= 10 m, from truth/relative: evaluation only).
"""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from ardsim_msgs.msg import ContactEvent, GuidanceState
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry

LAST_RANGE_M = 10.0


class ClosedLoop(unittest.TestCase):
    def setUp(self):
        self.expect = rospy.get_param("~expect")
        self.limit = rospy.get_param("~sim_time_limit_s")
        self.lock = threading.Lock()
        self.contacts = []
        self.retreat = None
        self.last_state = None
        self.last_time = 0.0
        self.port_x = {}  # truth/relative x by stamp (ns), until matched with the command of that stamp
        self.commands = {}  # |force| by stamp (ns), until matched with the truth of that stamp
        self.force_sq_sum = 0.0
        self.force_samples = 0
        rospy.Subscriber("dynamics/contact", ContactEvent, self.on_contact, queue_size=10)
        rospy.Subscriber("truth/relative", Odometry, self.on_relative, queue_size=1000)
        rospy.Subscriber("guidance/command", WrenchStamped, self.on_command, queue_size=1000)
        rospy.Subscriber("guidance/state", GuidanceState, self.on_state, queue_size=1000)
        # Counted by the dynamics' wait_for_subscribers, so that the run starts only once this checker listens.
        rospy.Subscriber("truth/chaser/odom", Odometry, lambda msg: None, queue_size=1)

    def on_contact(self, msg):
        with self.lock:
            self.contacts.append(msg)

    def add_force_sample(self, stamp_ns):
        if stamp_ns in self.port_x and stamp_ns in self.commands:
            if self.port_x.pop(stamp_ns) <= LAST_RANGE_M:
                self.force_sq_sum += self.commands[stamp_ns] ** 2
                self.force_samples += 1
            del self.commands[stamp_ns]

    def on_relative(self, msg):
        stamp_ns = msg.header.stamp.to_nsec()
        with self.lock:
            self.last_time = msg.header.stamp.to_sec()
            self.port_x[stamp_ns] = msg.pose.pose.position.x
            self.add_force_sample(stamp_ns)

    def on_command(self, msg):
        f = msg.wrench.force
        stamp_ns = msg.header.stamp.to_nsec()
        with self.lock:
            self.commands[stamp_ns] = math.sqrt(f.x ** 2 + f.y ** 2 + f.z ** 2)
            self.add_force_sample(stamp_ns)

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

    def report(self, c):
        with self.lock:
            delta_v = self.last_state.delta_v_used_mps if self.last_state else float("nan")
            rms = math.sqrt(self.force_sq_sum / self.force_samples) if self.force_samples else float("nan")
        figures = {
            "verdict": "CAPTURE" if c.verdict == ContactEvent.VERDICT_CAPTURE else "COLLISION",
            "t": round(c.header.stamp.to_sec(), 3),
            "closing_mps": round(c.closing_speed_mps, 4),
            "lateral_m": round(c.lateral_misalignment_m, 4),
            "lateral_rate_mps": round(c.lateral_rate_mps, 5),
            "angular_deg": round(math.degrees(c.angular_misalignment_rad), 3),
            "angular_rate_deg_s": round(math.degrees(c.angular_rate_rad_s), 4),
            "within_envelope": c.within_envelope,
            "parts": "%s/%s" % (c.chaser_part, c.target_part),
            "delta_v_mps": round(delta_v, 3),
            "rms_force_last_10m_n": round(rms, 2),
            "reason": c.reason,
        }
        rospy.loginfo("closed loop contact: %s", figures)
        print("CONTACT %s" % figures)

    def test_outcome(self):
        if self.expect in ("capture", "collision"):
            self.wait(lambda: self.contacts)
            with self.lock:
                contacts, r = list(self.contacts), self.retreat
            self.assertTrue(contacts, "no dynamics/contact by t = %.1f s (last truth at %.1f s)"
                            % (self.limit, self.last_time))
            self.assertEqual(len(contacts), 1)
            c = contacts[0]
            self.report(c)
            self.assertIsNone(r, "guidance retreated: %s" % (r,))
            if self.expect == "capture":
                self.assertEqual(c.verdict, ContactEvent.VERDICT_CAPTURE, c.reason)
                self.assertTrue(c.within_envelope, c.reason)
            else:
                self.assertEqual(c.verdict, ContactEvent.VERDICT_COLLISION, c.reason)
        else:
            self.wait(lambda: self.retreat is not None)
            with self.lock:
                contacts, r = list(self.contacts), self.retreat
            self.assertIsNotNone(r, "no RETREAT by t = %.1f s" % self.limit)
            self.assertIn("LOST", r[1])
            self.assertEqual(contacts, [], "contact although the estimate was lost")
            print("RETREAT at %.1f s: %s" % r)


if __name__ == "__main__":
    rospy.init_node("closed_loop_checker")
    rostest.rosrun("ardsim_guidance", "closed_loop_checker", ClosedLoop, sys.argv)
