#!/usr/bin/python3
"""dataset_bands.py ESTIMATES.csv...

Per evaluate_dataset run (its --out CSV), each range band of evaluate_dataset's table that has frames, farthest
first: RMS / worst frame of the port position error and of the attitude error over the frames that are not LOST,
and the worst frame over the RMS (the issue's "no breakdown" rule: within 3x); then a summary over all the runs,
with how many runs' RMS meet the issue's goals in each band.
scripts/approach_datasets calls it."""
import csv
import math
import os
import sys

BANDS = ((75.0, math.inf), (50.0, 75.0), (30.0, 50.0), (20.0, 30.0), (10.0, 20.0), (0.0, 10.0))
BREAKDOWN_RATIO = 3.0
# The RMS goals: position (m) and attitude (deg), inside GOAL_SPLIT_M and beyond (dataset_figure too).
GOAL_SPLIT_M = 30.0
POSITION_GOAL_M = (0.02, 0.05)
ATTITUDE_GOAL_DEG = (0.05, 0.1)


def band_goals(low_m):
    """(position m, attitude deg) RMS goals of the band starting at low_m."""
    beyond = low_m >= GOAL_SPLIT_M
    return POSITION_GOAL_M[beyond], ATTITUDE_GOAL_DEG[beyond]


def band_errors(rows, low_m, high_m):
    """(position errors m, attitude errors deg) of the frames in [low_m, high_m) that are not LOST."""
    frames = [r for r in rows if low_m <= float(r['range_m']) < high_m and r['status'] != 'LOST']
    return [float(r['pos_err_m']) for r in frames], [float(r['att_err_deg']) for r in frames]


def band_label(low_m, high_m):
    return f"{low_m:g}-{high_m:g}" if high_m < math.inf else f">={low_m:g}"


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else float('nan')


def main():
    if len(sys.argv) < 2 or any(a.startswith('-') for a in sys.argv[1:]):
        sys.exit(__doc__)
    summary = {band: {'pos_rms': [], 'att_rms': [], 'pos_worst': 0.0, 'att_worst': 0.0, 'pos_ok': 0,
                      'att_ok': 0, 'goal_ok': 0} for band in BANDS}
    lost = 0
    print(f"{'run':28s} {'band m':7s} {'pos RMS / worst mm':>19s} {'/RMS':>6s} {'att RMS / worst deg':>20s} "
          f"{'/RMS':>6s}")
    for path in sys.argv[1:]:
        with open(path, newline='') as f:
            rows = list(csv.DictReader(f))
        lost += sum(r['status'] == 'LOST' for r in rows)
        name = os.path.splitext(os.path.basename(path))[0]
        for low_m, high_m in BANDS:
            pos, att = band_errors(rows, low_m, high_m)
            if not pos:
                continue
            s = summary[(low_m, high_m)]
            pos_rms, att_rms = rms(pos), rms(att)
            s['pos_rms'].append(pos_rms)
            s['att_rms'].append(att_rms)
            s['pos_worst'] = max(s['pos_worst'], max(pos))
            s['att_worst'] = max(s['att_worst'], max(att))
            s['pos_ok'] += max(pos) <= BREAKDOWN_RATIO * pos_rms
            s['att_ok'] += max(att) <= BREAKDOWN_RATIO * att_rms
            pos_goal_m, att_goal_deg = band_goals(low_m)
            s['goal_ok'] += pos_rms <= pos_goal_m and att_rms <= att_goal_deg
            print(f"{name:28s} {band_label(low_m, high_m):7s} {1e3 * pos_rms:8.2f} / {1e3 * max(pos):6.2f}"
                  f" {max(pos) / pos_rms:5.2f}x {att_rms:9.3f} / {max(att):6.3f} {max(att) / att_rms:5.2f}x")
    runs = len(sys.argv) - 1
    print(f"summary runs={runs} lost_frames={lost}")
    for (low_m, high_m), s in summary.items():
        if not s['pos_rms']:
            continue
        pos_goal_m, att_goal_deg = band_goals(low_m)
        print(f"  {band_label(low_m, high_m)} m: position RMS {1e3 * min(s['pos_rms']):.2f}-"
              f"{1e3 * max(s['pos_rms']):.2f} mm, worst frame {1e3 * s['pos_worst']:.2f} mm, within "
              f"{BREAKDOWN_RATIO:g}x the RMS in {s['pos_ok']} of {len(s['pos_rms'])}; attitude RMS "
              f"{min(s['att_rms']):.3f}-{max(s['att_rms']):.3f} deg, worst frame {s['att_worst']:.3f} deg, within "
              f"{BREAKDOWN_RATIO:g}x the RMS in {s['att_ok']} of {len(s['att_rms'])}; both RMS within the goals "
              f"({1e3 * pos_goal_m:g} mm, {att_goal_deg:g} deg) in {s['goal_ok']} of {len(s['pos_rms'])}")


if __name__ == '__main__':
    main()
