#!/usr/bin/env python3
"""Interface test of the pose node/nodelet: drives the lidar with truth steps (the chaser on the ISS docking axis,
its port 29 m out) and publishes bad clouds of its own (NaN-filled, empty, unorganized, truncated, without a z
field, in another frame, one whose header's size passes 2^32), skips a frame, then steps time back; every cloud
must be answered by exactly one pose/estimate with its stamp, and every estimate with its truth by one pose/error,
after time went back too."""
import math
import struct
import subprocess
import threading
import time
import unittest

import rospy
import rostest
from ardsim_msgs.msg import PoseError, PoseEstimate
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock, Log
from sensor_msgs.msg import PointCloud2, PointField

TARGET_ECI = (6.778e6, 1.25e5, -2.5e5)
# ISS port at (14.5, 0, 4.5) in the target frame, x out of the port; the chaser faces it (yaw 180 deg) with its
# port (3 m ahead of its centre of mass) 29 m out.
CHASER_OFFSET = (14.5 + 29.0 + 3.0, 0.0, 4.5)
FACING_TARGET = (0.0, 0.0, 1.0, 0.0)
WAIT_S = 90.0


def odometry(stamp, child, position, orientation):
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = 'eci'
    msg.child_frame_id = child
    msg.pose.pose.position.x, msg.pose.pose.position.y, msg.pose.pose.position.z = position
    o = msg.pose.pose.orientation
    o.x, o.y, o.z, o.w = orientation
    return msg


def cloud(stamp, width, height, value):
    msg = PointCloud2()
    msg.header.stamp = stamp
    msg.header.frame_id = 'lidar_optical'
    msg.width, msg.height = width, height
    msg.fields = [PointField(n, 4 * i, PointField.FLOAT32, 1) for i, n in enumerate(('x', 'y', 'z', 'intensity'))]
    msg.point_step = 16
    msg.row_step = 16 * width
    msg.data = struct.pack('<4f', value, value, value, value) * (width * height)
    return msg


class PoseInterfaceTest(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.estimates = []
        self.errors = []
        self.logs = []
        self.subscribers = [rospy.Subscriber('pose/estimate', PoseEstimate, self.store, self.estimates, queue_size=50),
                            rospy.Subscriber('pose/error', PoseError, self.store, self.errors, queue_size=50),
                            rospy.Subscriber('/rosout', Log, self.store, self.logs, queue_size=200)]
        self.clock = rospy.Publisher('/clock', Clock, queue_size=10, latch=True)
        self.target = rospy.Publisher('truth/target/odom', Odometry, queue_size=10)
        self.chaser = rospy.Publisher('truth/chaser/odom', Odometry, queue_size=10)
        self.points = rospy.Publisher('lidar/points', PointCloud2, queue_size=10)
        self.wait_for(lambda: self.target.get_num_connections() >= 2 and self.chaser.get_num_connections() >= 2 and
                      self.points.get_num_connections() > 0 and
                      all(s.get_num_connections() > 0 for s in self.subscribers), 'the nodes to connect')

    def store(self, msg, where):
        with self.lock:
            where.append(msg)

    def wait_for(self, condition, what):
        deadline = time.monotonic() + WAIT_S
        while not condition():
            if rospy.is_shutdown() or time.monotonic() > deadline:
                self.fail('timed out waiting for ' + what)
            time.sleep(0.02)

    def answer(self, seconds, publish):
        count = len(self.estimates) + 1
        stamp = rospy.Time.from_sec(seconds)
        self.clock.publish(Clock(clock=stamp))
        publish(stamp)
        self.wait_for(lambda: len(self.estimates) >= count, 'the estimate at t = %g' % seconds)
        estimate = self.estimates[-1]
        self.assertEqual(len(self.estimates), count, 'one estimate per cloud')
        self.assertEqual(estimate.header.stamp, stamp)
        self.assertEqual(estimate.header.frame_id, 'lidar_optical')
        return estimate

    @staticmethod
    def truncated(msg):
        msg.data = msg.data[:1000]
        return msg

    @staticmethod
    def renamed_z(msg):
        msg.fields[2].name = 'w'
        return msg

    @staticmethod
    def overflowing(msg):
        # width x point_step = 2^32 with no data: wrapped to 32 bits it passed the size checks (the node crashed).
        msg.width, msg.height, msg.point_step, msg.row_step = 65536, 2, 65536, 0
        return msg

    @staticmethod
    def in_chaser_frame(msg):
        msg.header.frame_id = 'chaser'
        return msg

    def truth_step(self, stamp):
        position = tuple(t + o for t, o in zip(TARGET_ECI, CHASER_OFFSET))
        self.target.publish(odometry(stamp, 'target', TARGET_ECI, (0.0, 0.0, 0.0, 1.0)))
        self.chaser.publish(odometry(stamp, 'chaser', position, FACING_TARGET))

    def test_one_estimate_per_cloud(self):
        for k in range(1, 4):
            estimate = self.answer(float(k), self.truth_step)
            self.assertNotEqual(estimate.status, PoseEstimate.STATUS_LOST, estimate.reason)
            self.assertEqual(estimate.method, PoseEstimate.METHOD_ICP)
        self.wait_for(lambda: len(self.errors) >= 3, 'three pose errors')
        error = self.errors[-1]
        self.assertEqual(error.header.stamp, rospy.Time.from_sec(3.0))
        self.assertLess(error.port_position_error_m, 0.05)
        self.assertLess(error.attitude_error_rad, math.radians(0.1))
        self.assertAlmostEqual(error.range_m, 30.0, delta=0.01)

        nan_estimate = self.answer(4.0, lambda s: self.points.publish(cloud(s, 256, 256, float('nan'))))
        self.assertEqual(nan_estimate.status, PoseEstimate.STATUS_LOST)
        self.assertIn('empty', nan_estimate.reason)
        empty_estimate = self.answer(5.0, lambda s: self.points.publish(cloud(s, 0, 0, 0.0)))
        self.assertEqual(empty_estimate.status, PoseEstimate.STATUS_LOST)
        unorganized = self.answer(6.0, lambda s: self.points.publish(cloud(s, 100, 1, 1.0)))
        self.assertEqual(unorganized.status, PoseEstimate.STATUS_LOST)
        self.assertIn('organized', unorganized.reason)
        truncated = self.answer(6.5, lambda s: self.points.publish(self.truncated(cloud(s, 256, 256, 1.0))))
        self.assertEqual(truncated.status, PoseEstimate.STATUS_LOST)
        self.assertIn('shorter', truncated.reason)
        overflowing = self.answer(6.6, lambda s: self.points.publish(self.overflowing(cloud(s, 0, 0, 0.0))))
        self.assertEqual(overflowing.status, PoseEstimate.STATUS_LOST)
        self.assertIn('row_step 0 is shorter than width x point_step', overflowing.reason)
        no_z = self.answer(6.7, lambda s: self.points.publish(self.renamed_z(cloud(s, 256, 256, 1.0))))
        self.assertEqual(no_z.status, PoseEstimate.STATUS_LOST)
        self.assertIn('no field z', no_z.reason)
        other_frame = self.answer(6.8, lambda s: self.points.publish(self.in_chaser_frame(cloud(s, 256, 256, 1.0))))
        self.assertEqual(other_frame.status, PoseEstimate.STATUS_LOST)
        self.assertIn("frame 'chaser'", other_frame.reason)

        # The node kept running and tracks again. After frames 0.1 s apart (6.7, 6.8) this one comes a frame
        # late: the frame between is logged as missing (a player outrunning the node's queue drops frames).
        estimate = self.answer(7.0, self.truth_step)
        self.assertNotEqual(estimate.status, PoseEstimate.STATUS_LOST, estimate.reason)
        self.wait_for(lambda: any('1 frame(s) missing before t = 7.000000' in m.msg for m in self.logs),
                      'the missing frame logged')

        # Frames with no truth: their estimates wait in the evaluator (buffer_size 3) for a truth that never comes.
        for seconds in (8.0, 9.0, 10.0):
            self.answer(seconds, lambda s: self.points.publish(cloud(s, 256, 256, float('nan'))))

        # Time back 9 s (a bag played again): logged, the estimator starts again from the initial estimate, and the
        # evaluator starts a new time line: in one with the three waiting estimates, being newer, they would push
        # the new one out (a bounded buffer drops its oldest) and leave t = 1 without an error.
        estimate = self.answer(1.0, self.truth_step)
        self.assertNotEqual(estimate.status, PoseEstimate.STATUS_LOST, estimate.reason)
        self.wait_for(lambda: any('time went back, started again' in m.msg for m in self.logs),
                      'the time jump logged by the pose node')
        self.wait_for(lambda: any(e.header.stamp == rospy.Time.from_sec(1.0) for e in self.errors[3:]),
                      'the pose error at t = 1 after time went back')
        self.wait_for(lambda: any('time went back, matching starts again' in m.msg for m in self.logs),
                      'the time jump logged by the evaluator')

    def test_bad_parameter_stops_the_node_with_a_clear_error(self):
        # One node name per case: a _param:= setting stays on the parameter server after its node exits.
        cases = [('_icp/max_points:=3', 'icp/max_points = 3'),
                 ('_cloud_queue_size:=0', 'cloud_queue_size = 0'),
                 ('_icp/crop_reuse_px:=9.0', 'icp/crop_reuse_px = 9'),
                 ('_icp/near_depth_m:=-1.0', 'icp/near_depth_m = -1'),
                 ('_mode/close_method:=laser', "mode/close_method = 'laser'"),
                 ('_mode/close_exit_range_m:=5.0', 'mode/close_exit_range_m = 5'),
                 ('_estimator/composite_max_port_range_m:=-5.0', 'estimator/composite_max_port_range_m = -5'),
                 ('_estimator/composite_icp_roll_max_sigma_deg:=-1.0',
                  'estimator/composite_icp_roll_max_sigma_deg = -1'),
                 ('_icp/acquisition_boresight_gate_deg:=-1.0', 'icp/acquisition_boresight_gate_deg = -1'),
                 ('_icp/boresight_prior_max_information:=2.0', 'icp/boresight_prior_max_information = 2'),
                 ('_icp/boresight_prior_frames:=-3', 'icp/boresight_prior_frames = -3'),
                 ('_icp/contour_consensus_min_depth_m:=-25.0', 'icp/contour_consensus_min_depth_m = -25'),
                 ('_icp/lateral_history_frames:=-1', 'icp/lateral_history_frames = -1'),
                 ('_icp/lateral_gate_frames:=0', 'icp/lateral_gate_frames = 0'),
                 ('_icp/lateral_acceleration_chi2:=-1.0', 'icp/lateral_acceleration_chi2 = -1'),
                 ('_icp/lateral_line_frames:=2', 'icp/lateral_line_frames = 2'),
                 ('_icp/lateral_line_sigma_m:=-0.001', 'icp/lateral_line_sigma_m = -0.001'),
                 ('_icp/lateral_vote_weight:=-3.0', 'icp/lateral_vote_weight = -3'),
                 ('_panels/window:=4', 'panels/window = 4'),
                 ('_panels/first_window:=2', 'panels/first_window = 2'),
                 ('_panels/enabled:=true', 'panels/enabled is not allowed for target iss'),
                 ('_width:=0', 'parameter width = 0')]
        runs = [('pose_node', 'bad_pose_%d' % case, setting, named) for case, (setting, named) in enumerate(cases)]
        runs += [('pose_evaluator', 'bad_evaluator_0', '_restart_time_jump_s:=-1.0', 'restart_time_jump_s = -1'),
                 ('pose_evaluator', 'bad_evaluator_1', '_buffer_size:=0', 'buffer_size = 0')]
        for node_type, name, setting, named in runs:
            result = subprocess.run(['rosrun', 'ardsim_pose', node_type, '__name:=' + name, setting],
                                    capture_output=True, text=True, timeout=120)
            self.assertNotEqual(result.returncode, 0, setting)
            self.assertIn(named, result.stdout + result.stderr, setting)
            self.assertNotIn('parameter parameter', result.stdout + result.stderr, setting)


if __name__ == '__main__':
    rospy.init_node('pose_node_test')
    rostest.rosrun('ardsim_pose', 'pose_node_test', PoseInterfaceTest)
