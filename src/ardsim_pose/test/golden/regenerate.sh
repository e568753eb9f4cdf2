#!/usr/bin/env bash
# Regenerates the golden regression data of test_pose_golden: ISS, noise on (seed 1), 128 x 128 frames (the
# estimator takes the size from the frames), two consecutive frames (0.5 m apart) at 100, 30 and 10 m (lidar
# to port), and the estimates of evaluate_dataset --init truth over each pair (expected_estimates.csv).
# Run from the workspace root after `make build`:  src/ardsim_pose/test/golden/regenerate.sh
# Regenerate only on purpose (a deliberate change of the estimator's output), and say why in the commit.
# --estimates-only keeps the committed frames and recomputes only expected_estimates.csv (the estimator changed,
# the frames did not).
set -euo pipefail
estimates_only=false
[ "${1:-}" = "--estimates-only" ] && estimates_only=true
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here/../../../.."
. scripts/env.sh
bin=devel/lib
for range in 100 30 10; do
  dir="$here/iss_$range"
  if [ "$estimates_only" = false ]; then
    rm -rf "$dir"
    mkdir -p "$dir"
    # approach_poses takes the chaser port distance: the lidar is 1 m behind the port.
    "$bin/ardsim_pose/approach_poses" --target iss --from $((range - 1)) --to "$(echo "$range - 1.5" | bc)" \
      --frames 2 > "$dir/poses.csv"
    "$bin/ardsim_lidar/render_dataset" --target iss --poses "$dir/poses.csv" --out "$dir" --noise on --seed 1 \
      --width 128 --height 128 > /dev/null
    rm -f "$dir"/*.png "$dir/poses.csv"
  fi
  "$bin/ardsim_pose/evaluate_dataset" --dataset "$dir" --init truth --out "$dir/estimates.csv.tmp" | tail -1
  # Timings differ run to run: drop them from the expected file.
  cut -d, -f1-17 "$dir/estimates.csv.tmp" > "$dir/expected_estimates.csv"
  rm "$dir/estimates.csv.tmp"
done
du -sh "$here"
