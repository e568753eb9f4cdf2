#!/usr/bin/env python3
"""rviz:=headless: a short run (the dock_15m scenario cut at 30 s of sim time, paced at 2x real time) leaves a complete,
non-empty rviz.mp4 (ffprobe reads its duration and frames) and screenshots that are not blank (pixel variance)."""
import glob
import json
import os
import subprocess
import sys
import unittest

import matplotlib.image
import numpy as np
import rostest

from scenario_run import passed, run_scenario, scenario_variant


def probe(path):
    text = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                           "stream=nb_read_frames,width,height:format=duration", "-of", "json", path],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=True).stdout
    info = json.loads(text)
    return float(info["format"]["duration"]), int(info["streams"][0]["nb_read_frames"]), info["streams"][0]


class HeadlessRviz(unittest.TestCase):
    def test_video_and_screenshots(self):
        short = scenario_variant("headless_30s", "dock_15m.yaml", time_limit_s=30.0)
        out, s = run_scenario(self, short, "rviz:=headless", "record:=false", "real_time_factor:=2",
                              "pose_source:=truth", "png_every_s:=3")
        self.assertEqual(s["outcome"], "time_limit")
        duration, frames, stream = probe(os.path.join(out, "rviz.mp4"))
        self.assertGreater(duration, 10.0)
        self.assertGreater(frames, 50)
        self.assertEqual((stream["width"], stream["height"]), (1280, 720))
        shots = sorted(glob.glob(os.path.join(out, "rviz_[0-9]*.png"))) + [os.path.join(out, "rviz_final.png")]
        self.assertGreaterEqual(len(shots), 4)
        for path in shots[1:]:  # the first may show rviz starting up
            image = matplotlib.image.imread(path)[:, :, :3]
            self.assertGreater(float(np.var(image)), 1e-3, "blank screenshot " + path)
        passed(out)


if __name__ == "__main__":
    rostest.rosrun("ardsim_bringup", "headless_rviz", HeadlessRviz, sys.argv)
