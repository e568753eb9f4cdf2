#!/usr/bin/env python3
"""Interface test of the lidar node/nodelet: publishes /clock and the two truth odometries at a few stamps (as the
dynamics node does in the lockstep) and checks that each step is answered with exactly one frame."""
import subprocess
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, Image, PointCloud2

TARGET_ECI = (6.778e6, 1.25e5, -2.5e5)  # an orbit-sized position: precision must survive the subtraction
# Chaser 46.5 m out along the ISS port axis (port at (14.5, 0, 4.5) in the target frame), turned to face it
# (yaw 180 deg): its lidar, 2 m ahead of its centre of mass, is 30 m from the port.
CHASER_OFFSET = (46.5, 0.0, 4.5)
FACING_TARGET = (0.0, 0.0, 1.0, 0.0)  # x y z w
FACING_AWAY = (0.0, 0.0, 0.0, 1.0)
WAIT_S = 60.0  # wall-clock limit for an answer; generous for a loaded 2-core machine


def odometry(stamp, child, position, orientation):
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = 'eci'
    msg.child_frame_id = child
    msg.pose.pose.position.x, msg.pose.pose.position.y, msg.pose.pose.position.z = position
    o = msg.pose.pose.orientation
    o.x, o.y, o.z, o.w = orientation
    return msg


class LidarLockstepTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.received = {'points': [], 'range': [], 'info': []}
        self.subscribers = [
            rospy.Subscriber('lidar/points', PointCloud2, self.store, 'points', queue_size=20),
            rospy.Subscriber('lidar/range', Image, self.store, 'range', queue_size=20),
            rospy.Subscriber('lidar/camera_info', CameraInfo, self.store, 'info', queue_size=20)]
        self.clock = rospy.Publisher('/clock', Clock, queue_size=10, latch=True)
        self.target = rospy.Publisher('truth/target/odom', Odometry, queue_size=10)
        self.chaser = rospy.Publisher('truth/chaser/odom', Odometry, queue_size=10)
        self.wait_for(lambda: self.target.get_num_connections() > 0 and self.chaser.get_num_connections() > 0 and
                      all(s.get_num_connections() > 0 for s in self.subscribers), 'the lidar to connect')

    def store(self, msg, key):
        with self.lock:
            self.received[key].append(msg)

    def wait_for(self, condition, what):
        deadline = time.monotonic() + WAIT_S
        while not condition():
            if rospy.is_shutdown() or time.monotonic() > deadline:
                self.fail('timed out waiting for ' + what)
            time.sleep(0.02)

    def step(self, seconds, orientation, chaser_orientation=None):
        stamp = rospy.Time.from_sec(seconds)
        # Counted before publishing: counted after, a frame that arrived in between (this thread descheduled on a
        # loaded machine) made it wait for one more that never comes (a 60 s timeout in a fresh-clone CI run).
        with self.lock:
            count = len(self.received['points']) + 1
        self.clock.publish(Clock(clock=stamp))
        chaser_position = tuple(t + o for t, o in zip(TARGET_ECI, CHASER_OFFSET))
        self.target.publish(odometry(stamp, 'target', TARGET_ECI, (0.0, 0.0, 0.0, 1.0)))
        self.chaser.publish(odometry(stamp, 'chaser', chaser_position, chaser_orientation or orientation))
        self.wait_for(lambda: all(len(v) >= count for v in self.received.values()), 'the frame at t = %g' % seconds)
        return self.received['points'][-1], self.received['range'][-1], self.received['info'][-1]

    def check_frame(self, points, range_image, info, seconds):
        for msg in (points, range_image, info):
            self.assertEqual(msg.header.stamp, rospy.Time.from_sec(seconds))
            self.assertEqual(msg.header.frame_id, 'lidar_optical')
        self.assertEqual((points.width, points.height), (256, 256))
        self.assertEqual([f.name for f in points.fields], ['x', 'y', 'z', 'intensity'])
        self.assertEqual(range_image.encoding, '32FC1')
        cloud = np.frombuffer(points.data, dtype=np.float32).reshape(256, 256, 4)
        ranges = np.frombuffer(range_image.data, dtype=np.float32).reshape(256, 256)
        np.testing.assert_array_equal(np.isnan(cloud[:, :, 0]), np.isnan(ranges))
        # point = range * unit ray of the pixel, the ray from the camera_info intrinsics
        fx, cx, fy, cy = info.K[0], info.K[2], info.K[4], info.K[5]
        v, u = np.mgrid[0:256, 0:256]
        rays = np.stack([(u - cx) / fx, (v - cy) / fy, np.ones((256, 256))], axis=-1)
        rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
        hit = ~np.isnan(ranges)
        np.testing.assert_allclose(cloud[hit][:, :3], rays[hit] * ranges[hit][:, None], atol=2e-3)
        return int(hit.sum())

    def test_one_frame_per_truth_step(self):
        returns = self.check_frame(*self.step(1.0, FACING_TARGET), 1.0)
        self.assertGreater(returns, 1000, 'the ISS at 30 m should fill much of the view')
        # 30 m to the port (the lidar looks into it): nothing returns from beyond a few tens of metres behind it
        ranges = np.frombuffer(self.received['range'][-1].data, dtype=np.float32)
        self.assertGreater(np.nanmin(ranges), 25.0)
        self.assertEqual(self.check_frame(*self.step(1.1, FACING_AWAY), 1.1), 0, 'out of view: empty frame')
        # Malformed truth (zero quaternion) is answered too, with an empty frame, and the node keeps going.
        self.assertEqual(self.check_frame(*self.step(1.2, FACING_TARGET, (0.0, 0.0, 0.0, 0.0)), 1.2), 0)
        self.assertGreater(self.check_frame(*self.step(1.3, FACING_TARGET), 1.3), 1000)
        time.sleep(0.5)  # any extra frame would have arrived by now; extra frames only make the test stricter
        self.assertEqual([m.header.stamp for m in self.received['points']],
                         [rospy.Time.from_sec(s) for s in (1.0, 1.1, 1.2, 1.3)])

    def test_bad_parameter_stops_the_node_with_a_clear_error(self):
        result = subprocess.run(['rosrun', 'ardsim_lidar', 'lidar_node', '__name:=bad_lidar', '_width:=-3'],
                                capture_output=True, text=True, timeout=WAIT_S)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn('parameter width = -3', result.stdout + result.stderr)


if __name__ == '__main__':
    rospy.init_node('lidar_node_test')
    rostest.rosrun('ardsim_lidar', 'lidar_node_test', LidarLockstepTest)
