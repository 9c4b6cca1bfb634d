#!/bin/sh
# slamo dry-run and tune from the command line: files written, exit statuses.
set -eu
slamo="$1"
dir="$2"
rm -rf "$dir"
mkdir -p "$dir"

"$slamo" dry-run --seed 3 --quiet --out "$dir/run" > "$dir/run.txt"
for f in report.json map.png trajectory.tum groundtruth.tum objects.bt replay.avi; do
  test -s "$dir/run/$f" || { echo "missing $dir/run/$f"; exit 1; }
done
for key in '"season"' '"seed"' '"strategy"' '"points"' '"duration_s"' '"deadline_s"' '"pose_ate_m"' '"objects"' '"timeline"' '"class"' '"est_x"' '"true_x"' '"t_s"' '"action"'; do
  grep -q "$key" "$dir/run/report.json" || { echo "report.json lacks $key"; exit 1; }
done
grep -q "overrun 0.00 s" "$dir/run.txt" || { echo "overrun reported"; cat "$dir/run.txt"; exit 1; }

# Bad input: exit 2.
set +e
"$slamo" dry-run --strategy random --out "$dir/bad" > /dev/null 2>&1; test $? -eq 2 || { echo "bad strategy: not 2"; exit 1; }
"$slamo" dry-run --frames fixed:x --out "$dir/bad" > /dev/null 2>&1; test $? -eq 2 || { echo "bad frames: not 2"; exit 1; }
"$slamo" tune --matches 1 --param warp=1 --out "$dir/bad" > /dev/null 2>&1; test $? -eq 2 || { echo "bad param: not 2"; exit 1; }
"$slamo" tune --matches 1 --scenario wobbly --out "$dir/bad" > /dev/null 2>&1; test $? -eq 2 || { echo "bad scenario: not 2"; exit 1; }
"$slamo" dry-run --scenario wobbly --out "$dir/bad" > /dev/null 2>&1; test $? -eq 2 || { echo "dry-run bad scenario: not 2"; exit 1; }
set -e

# SLAM-O on a recording: the report files; a folder that is no recording exits 2.
"$slamo" record --sim --seed 1 --script "forward 0.3; turn 45" --format tum --out "$dir/rec" > /dev/null
"$slamo" dry-run --from-recording "$dir/rec" --out "$dir/fromrec" > "$dir/fromrec.txt"
for f in report.json map.png trajectory.tum groundtruth.tum objects.bt; do
  test -s "$dir/fromrec/$f" || { echo "missing $dir/fromrec/$f"; exit 1; }
done
grep -q '"strategy": "recording"' "$dir/fromrec/report.json" || { echo "not a recording report"; exit 1; }
set +e
"$slamo" dry-run --from-recording "$dir/no_such_recording" --out "$dir/bad" > /dev/null 2> "$dir/fromrec_bad.txt"
test $? -eq 2 || { echo "bad recording: not 2"; exit 1; }
set -e
grep -q "error: " "$dir/fromrec_bad.txt"

# A small sweep on two processes, then the same as two shards merged: the same ranking.
"$slamo" tune --matches 2 --param strategy=scripted,greedy --jobs 2 --out "$dir/tune" > "$dir/tune.txt" 2>/dev/null
test -s "$dir/tune/tune.csv" && test -s "$dir/tune/tune.json"
test "$(grep -c scripted "$dir/tune/tune.csv")" -eq 1
# Every pick and release of those matches, judged, in attempts.csv.
head -1 "$dir/tune/attempts.csv" | grep -q "^combo,seed,t_s,action,kind,colour,goal_index,range_m,bearing_deg,sigma_m,error_m,target_error_m,outcome,taken_kind,taken_colour$"
test "$(grep -c ',SCORE,' "$dir/tune/attempts.csv")" -ge 1
# Success models from those attempts, read back by a dry run; refused for another season.
"$slamo" tune calibrate "$dir/tune/tune.json" --out "$dir/cal.json" > "$dir/cal.txt"
grep -q "reliability, PICK" "$dir/cal.txt"
grep -q '"robot": "thesis_robot"' "$dir/cal.json"
"$slamo" dry-run --seed 1 --calibration "$dir/cal.json" --no-video --quiet --out "$dir/calrun" > /dev/null
set +e
"$slamo" dry-run --season high_stakes --calibration "$dir/cal.json" --out "$dir/bad" > /dev/null 2>&1; test $? -eq 2 || { echo "calibration of another season: not 2"; exit 1; }
"$slamo" tune calibrate "$dir/no_such.json" > /dev/null 2>&1; test $? -eq 2 || { echo "calibrate a missing file: not 2"; exit 1; }
set -e
# Both layouts in one table.
"$slamo" tune --matches 1 --param strategy=scripted --scenario nominal,disturbed --out "$dir/scen" > /dev/null 2>&1
grep -q '"strategy=scripted scenario=nominal"' "$dir/scen/tune.csv"
grep -q '"strategy=scripted scenario=disturbed"' "$dir/scen/tune.csv"
"$slamo" dry-run --seed 2 --strategy scripted --scenario disturbed --no-video --quiet --out "$dir/dist" > /dev/null
grep -q '"scenario": "disturbed"' "$dir/dist/report.json"
"$slamo" tune --matches 2 --param strategy=scripted,greedy --shard 1/2 --out "$dir/shards" > /dev/null 2>&1
"$slamo" tune --matches 2 --param strategy=scripted,greedy --shard 2/2 --out "$dir/shards" > /dev/null 2>&1
"$slamo" tune merge "$dir/shards/shard-1-of-2.json" "$dir/shards/shard-2-of-2.json" --out "$dir/merged" > /dev/null
cmp "$dir/tune/tune.csv" "$dir/merged/tune.csv" || {
  # Wall times differ between runs; compare everything but the last column.
  cut -d, -f1-19 "$dir/tune/tune.csv" > "$dir/a.csv"
  cut -d, -f1-19 "$dir/merged/tune.csv" > "$dir/b.csv"
  cmp "$dir/a.csv" "$dir/b.csv"
}
echo "dry-run and tune CLI checks passed"
