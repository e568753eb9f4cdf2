"""A run directory's frames as the scripts that judge a run read them (scripts/run_bands, worst_over_rms,
covariance_consistency): the run's /pose/error messages up to the run's end, LOST frames left out, as its
summary.json counts them. The graph runs on for a while after the end (roslaunch shutting down), and an aborted
run's bag holds its retreat past it."""
import json
import os

LOST = 2  # PoseEstimate.STATUS_LOST


def run_end_s(run_dir):
    """The run's last counted sim time: summary.json's sim_time_s."""
    with open(os.path.join(run_dir, 'summary.json')) as f:
        return json.load(f)['sim_time_s']


def counted(pose_error, end_s):
    """Whether a /pose/error message counts: not LOST, stamped no later than the run's end."""
    return pose_error.status != LOST and pose_error.header.stamp.to_sec() <= end_s + 1e-6
