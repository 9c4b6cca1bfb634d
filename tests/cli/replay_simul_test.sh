#!/bin/sh
# Issue 14's own log: MRPT's simul-landmarks with odometry sd 0.08 m a step, 70 landmarks,
# 6 m range, seed 7. `slamo replay` reads simul-landmarks' truth files as they are written
# (the robot path paired step by step, the landmark map by id), with the filter's options
# from a YAML file, and holds: ATE and landmark RMSE under 2 cm (MRPT's own EKF: 0.009 m ATE),
# at most 10 % of the known-id measurements refused. A path of another length exits 2.
set -eu
slamo="$1"
dir="$2"
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
cat > gen.ini <<'INI'
[Params]
random_seed = 7
nSteps = 250
circularPath = 0
squarePathLength = 50
loadLandmarksFromFile =
odometryNoiseXY_std = 0.08
minSensorDistance = 0
maxSensorDistance = 6
fieldOfView_deg = 180
stdRange = 0.01
stdYaw_deg = 0.1
stdPitch_deg = 0
outFile = gen.rawlog
outDir = OUT
show_in_3d = false

[RANDOMSET_1]
nLandmarks = 70
min_x = -4
max_x = 12
min_y = -3
max_y = 12
min_z = 0
max_z = 0
INI
simul-landmarks gen.ini > simul-landmarks.log 2>&1
printf 'known_ids: true\ngate_probability: 0.99\nmax_range_m: 6\n' > filter.yaml
"$slamo" replay --log OUT/gen.rawlog --filter-config filter.yaml \
  --truth OUT/gen.rawlog_ground_truth_robot_path.txt \
  --landmarks-truth OUT/gen.rawlog_ground_truth.txt > replay.txt
cat replay.txt
awk '/^ATE / { ate = $2 }
     /^landmark RMSE / { lm = $3; over = $6 }
     /known ids:/ { match($0, /[0-9.]+ %\)/); refused = substr($0, RSTART, RLENGTH - 3) }
     END {
       if (ate == "" || lm == "" || refused == "") { print "missing ATE, landmark RMSE or refusals"; exit 1 }
       if (!(ate < 0.02)) { print "ATE " ate " m"; bad = 1 }
       if (!(lm < 0.02) || over != 70) { print "landmark RMSE " lm " m over " over; bad = 1 }
       if (!(refused <= 10)) { print refused " % of the known-id measurements refused"; bad = 1 }
       exit bad
     }' replay.txt
head -n 100 OUT/gen.rawlog_ground_truth_robot_path.txt > short_path.txt
if "$slamo" replay --log OUT/gen.rawlog --truth short_path.txt > short.txt 2> short.err; then
  echo "a short path was accepted"; exit 1
else
  test $? -eq 2
fi
grep -q "short_path.txt: 96 poses, but simul-landmarks writes one per odometry step of the log: 250" short.err || { cat short.err; exit 1; }
