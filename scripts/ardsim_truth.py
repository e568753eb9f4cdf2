"""The truth of a recorded run, shared by scripts/report and scripts/run_poses: T_lidar_target from the target's and
the chaser's eci poses (/truth/target/odom, /truth/chaser/odom) and the LIDAR's mount (/tf_static chaser ->
lidar_optical). Rigid transforms as (p, R) numpy pairs; quaternions x y z w as in ROS messages."""
import math

import numpy as np


def rot(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def quaternion(R):
    """(x, y, z, w) of a rotation matrix, w >= 0."""
    w = math.sqrt(max(0.0, 1.0 + R[0, 0] + R[1, 1] + R[2, 2])) / 2.0
    x = math.copysign(math.sqrt(max(0.0, 1.0 + R[0, 0] - R[1, 1] - R[2, 2])) / 2.0, R[2, 1] - R[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1.0 - R[0, 0] + R[1, 1] - R[2, 2])) / 2.0, R[0, 2] - R[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1.0 - R[0, 0] - R[1, 1] + R[2, 2])) / 2.0, R[1, 0] - R[0, 1])
    return (x, y, z, w)


def quat(o):
    return (o.x, o.y, o.z, o.w)


def vec(p):
    return np.array([p.x, p.y, p.z])


def lidar_target(target, chaser, mount):
    """T_lidar_target (p, R) from the target's and the chaser's eci poses (geometry_msgs/Pose) and the mount
    T_chaser_lidar (p, R)."""
    R_eci_t, R_eci_c = rot(quat(target.orientation)), rot(quat(chaser.orientation))
    p_c_t = R_eci_c.T @ (vec(target.position) - vec(chaser.position))  # eci difference first: double precision
    p_cl, R_cl = mount
    return R_cl.T @ (p_c_t - p_cl), R_cl.T @ R_eci_c.T @ R_eci_t
