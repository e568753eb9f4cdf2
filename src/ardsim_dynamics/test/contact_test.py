#!/usr/bin/env python3
"""Plays a scripted guidance against dynamics_node and checks how the run ends at the first contact.

The chaser starts 0.5 m in front of the ISS port (scenarios/contact_0p5m.yaml). The test answers every step with a
command that pushes it at 400 N along its port axis (and, with ~push = off_port, also sideways) for the first
~push_s seconds, then coasts: about 0.074 m/s closing at contact.
~expect: CAPTURE or COLLISION, the verdict of the single dynamics/contact message (off_port: the petals meet with the
lateral misalignment and lateral rate outside the envelope).
"""
import threading
import time
import unittest

import rospy
import rostest
from ardsim_msgs.msg import ContactEvent
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

PUSH_FORCE_N = 400.0  # the scenario's actuator limit


class ContactRun(unittest.TestCase):
    def setUp(self):
        self.push = rospy.get_param("~push")
        self.push_s = rospy.get_param("~push_s", 2.3)
        self.expect = rospy.get_param("~expect")
        self.lock = threading.Condition()
        self.contacts = []
        self.truth_stamps = []
        self.clock_ns = 0
        self.command_pub = rospy.Publisher("guidance/command", WrenchStamped, queue_size=10, latch=True)
        rospy.Subscriber("dynamics/contact", ContactEvent, self.on_contact, queue_size=10)
        rospy.Subscriber("/clock", Clock, self.on_clock, queue_size=100)
        # Also counted by the node's wait_for_subscribers: the run starts once this test answers.
        rospy.Subscriber("truth/chaser/odom", Odometry, self.on_truth, queue_size=100)

    def on_truth(self, msg):
        command = WrenchStamped()
        command.header.stamp = msg.header.stamp
        command.header.frame_id = "chaser"
        if msg.header.stamp.to_sec() < self.push_s - 1e-6:
            command.wrench.force.x = PUSH_FORCE_N  # chaser x: out of its port, towards the target port
            if self.push == "off_port":
                command.wrench.force.y = PUSH_FORCE_N
        self.command_pub.publish(command)
        with self.lock:
            self.truth_stamps.append(msg.header.stamp.to_nsec())
            self.lock.notify_all()

    def on_clock(self, msg):
        with self.lock:
            self.clock_ns = max(self.clock_ns, msg.clock.to_nsec())

    def on_contact(self, msg):
        with self.lock:
            self.contacts.append(msg)
            self.lock.notify_all()

    def test_run_ends_at_first_contact(self):
        with self.lock:
            self.assertTrue(self.lock.wait_for(lambda: self.contacts, timeout=180.0), "no dynamics/contact")
            contact = self.contacts[0]
            contact_ns = contact.header.stamp.to_nsec()
            # The state at the contact time is published as the last step.
            self.assertTrue(self.lock.wait_for(lambda: self.truth_stamps and self.truth_stamps[-1] >= contact_ns,
                                               timeout=60.0), "no truth at the contact time")
        # The node stops advancing: nothing newer comes while the test keeps answering (a missed stop shows as a
        # newer stamp within a few steps' wall time).
        time.sleep(2.0)
        with self.lock:
            self.assertEqual(len(self.contacts), 1)
            self.assertEqual(self.truth_stamps[-1], contact_ns)
            self.assertEqual(self.clock_ns, contact_ns)
        rospy.loginfo("contact: %s", contact)
        print("CONTACT t=%.3f %s" % (contact.header.stamp.to_sec(), contact))
        self.assertEqual(contact.header.frame_id, "target_port")
        # Capture at ~8 s (the ports' faces meet); sideways, the petals meet at ~3 s.
        self.assertGreater(contact.header.stamp.to_sec(), 2.0)
        self.assertLess(contact.header.stamp.to_sec(), 12.0)
        self.assertGreater(contact.closing_speed_mps, 0.07)
        self.assertLess(contact.closing_speed_mps, 0.08)
        if self.expect == "CAPTURE":
            self.assertEqual(contact.verdict, ContactEvent.VERDICT_CAPTURE, contact.reason)
            self.assertTrue(contact.within_envelope)
            self.assertLess(contact.lateral_misalignment_m, 0.01)
            self.assertIn(contact.target_part, ("soft_capture_ring", "guide_petals"))
            self.assertIn(contact.chaser_part, ("soft_capture_ring", "guide_petals"))
        else:
            self.assertEqual(contact.verdict, ContactEvent.VERDICT_COLLISION)
            self.assertFalse(contact.within_envelope)
            self.assertGreater(contact.lateral_misalignment_m, 0.1)
            self.assertIn("lateral misalignment", contact.reason)
            self.assertIn("lateral rate", contact.reason)


if __name__ == "__main__":
    rospy.init_node("contact_test")
    rostest.rosrun("ardsim_dynamics", "contact", ContactRun)
