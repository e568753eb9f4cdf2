"""Shared by the scenario tests: runs scripts/run_scenario (its own roslaunch and master, the product path) into a
fresh directory and reads what it left. The directory is removed when the test passes (passed()), kept otherwise."""
import json
import os
import shutil
import subprocess
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
SCENARIOS = os.path.join(HERE, "scenarios")


def run_scenario(test, scenario, *args, timeout_s=900):
    """Runs a scenario; returns (out_dir, summary.json or else run.json as a dict)."""
    base = os.path.join(ROOT, ".home", "scenario_tests")
    os.makedirs(base, exist_ok=True)
    out = tempfile.mkdtemp(prefix=os.path.splitext(os.path.basename(scenario))[0] + "-", dir=base)
    print("run directory %s (removed when the test passes)" % out)
    proc = subprocess.run([os.path.join(ROOT, "scripts", "run_scenario"), scenario, out] + list(args),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout_s, text=True)
    print(proc.stdout)
    test.assertEqual(proc.returncode, 0, "run_scenario failed (kept %s):\n%s" % (out, proc.stdout[-3000:]))
    name = "summary.json" if os.path.exists(os.path.join(out, "summary.json")) else "run.json"
    with open(os.path.join(out, name)) as f:
        return out, json.load(f)


def scenario_variant(name, base, **run_section):
    """A copy of test scenario `base` named `name` with keys of its `run` section replaced; returns its path."""
    import yaml
    with open(os.path.join(SCENARIOS, base)) as f:
        scenario = yaml.safe_load(f)
    scenario["name"] = name
    scenario["run"].update(run_section)
    path = os.path.join(ROOT, ".home", name + ".yaml")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        yaml.safe_dump(scenario, f)
    return path


def passed(out):
    """Call at the end of a test method: only reached when every assertion held."""
    shutil.rmtree(out, ignore_errors=True)


def bag_info(path):
    """rosbag info --yaml of a bag (fails if the bag was not closed)."""
    import yaml
    text = subprocess.run(["rosbag", "info", "--yaml", path], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, check=True).stdout
    return yaml.safe_load(text)


def returns_in(cloud_msg):
    """Valid points of an organized x y z intensity cloud (float32)."""
    data = np.frombuffer(cloud_msg.data, dtype=np.float32).reshape(-1, cloud_msg.point_step // 4)
    return int(np.isfinite(data[:, 2]).sum())
