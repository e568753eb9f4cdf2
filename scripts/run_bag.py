"""How the scripts that judge a run read its bag (scripts/report, run_bands, worst_over_rms,
covariance_consistency): the method names, and which messages count. The graph runs on for a while after the run's
end (roslaunch shutting down), and an aborted run's bag holds its retreat past it, so messages stamped after the
end (run.json's sim_time_s) are left out; a /pose/error frame counts where it is not LOST either, as summary.json
counts them."""
import json
import os

METHODS = {0: 'none', 1: 'icp', 2: 'pyramid', 3: 'ring', 4: 'truth'}  # PoseEstimate.METHOD_*
LOST = 2  # PoseEstimate.STATUS_LOST


def run_end_s(run_dir):
    """The run's end in sim time: run.json's sim_time_s (the run monitor writes it when the run ends)."""
    with open(os.path.join(run_dir, 'run.json')) as f:
        return json.load(f)['sim_time_s']


def past_end(stamp_s, end_s):
    return stamp_s > end_s + 1e-6


def counted(pose_error, end_s):
    """Whether a /pose/error message counts: not LOST, not stamped after the run's end."""
    return pose_error.status != LOST and not past_end(pose_error.header.stamp.to_sec(), end_s)
