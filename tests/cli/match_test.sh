#!/bin/sh
# slamo match with no robot: the fake board on a pseudo-terminal (the whole serial stack over
# it) and a recorded camera stream, on a 15 s copy of Toss Up; with the simulated camera and
# --record, replayed by dry-run --from-recording; slamo record on the fake board; a noisy link
# with the cable pulled mid-match; and the exit statuses for bad input.
set -eu
slamo="$1"
dir="$2"
seasons="$3"
rm -rf "$dir"
mkdir -p "$dir"
sed 's/^\(  autonomous_s:\) *45/\1 15/' "$seasons/toss_up.yaml" > "$dir/toss_up_15.yaml"
grep -q "autonomous_s: 15" "$dir/toss_up_15.yaml"

"$slamo" record --sim --script "wait 3" --fps 5 --format tum --out "$dir/rec" > /dev/null

"$slamo" match --fake-board --recording "$dir/rec" --loop --season "$dir/toss_up_15.yaml" \
  --out "$dir/run" --quiet > "$dir/run.txt"
for f in report.json map.png trajectory.tum objects.bt replay.avi; do
  test -s "$dir/run/$f" || { echo "missing $dir/run/$f"; cat "$dir/run.txt"; exit 1; }
done
test ! -e "$dir/run/groundtruth.tum" || { echo "groundtruth.tum without a truth"; exit 1; }
# No referee: points unknown; motors stopped by the deadline, on the host's and the board's account.
grep -q '"truth_known": false' "$dir/run/report.json" || { echo "truth_known"; exit 1; }
grep -q '"points": null' "$dir/run/report.json" || { echo "points not null"; exit 1; }
grep -q '"overrun_s": 0.0' "$dir/run/report.json" || { echo "overrun"; cat "$dir/run.txt"; exit 1; }
grep -q '"link_losses": 0.0' "$dir/run/report.json" || { echo "link lost"; cat "$dir/run.txt"; exit 1; }
grep -q 'PWM now 90/90' "$dir/run.txt" || { echo "motors not stopped"; cat "$dir/run.txt"; exit 1; }
grep -q '"action": "NAVIGATE"' "$dir/run/report.json" || { echo "never drove"; cat "$dir/run.txt"; exit 1; }

# The fake board with the simulated field's camera rendered from its motors, recorded; SLAM-O
# over that recording again with dry-run --from-recording, against the motors' truth.
"$slamo" match --fake-board --camera sim --season "$dir/toss_up_15.yaml" --record "$dir/matchrec" \
  --out "$dir/sim" --quiet --no-video > "$dir/sim.txt"
for f in rgb.txt depth.txt encoders.txt groundtruth.txt recording.json; do
  test -s "$dir/matchrec/$f" || { echo "match recording lacks $f"; exit 1; }
done
"$slamo" dry-run --from-recording "$dir/matchrec" --out "$dir/replayed" > "$dir/replayed.txt"
python3 - "$dir/sim/report.json" "$dir/replayed/report.json" <<'PY'
import json, sys
live, replayed = (json.load(open(p)) for p in sys.argv[1:3])
assert live["pose_ate_m"] is not None and live["pose_ate_m"] < 0.2, live["pose_ate_m"]
assert replayed["pose_ate_m"] is not None and replayed["pose_ate_m"] < 0.2, replayed["pose_ate_m"]
assert replayed["frames_taken"] == live["frames_taken"], (replayed["frames_taken"], live["frames_taken"])
PY

# slamo record on the fake board: the board drives the script over the serial link, its
# encoder ticks are recorded with the frames (both formats), and SLAM-O replays them.
"$slamo" record --fake-board --script "forward 0.3; turn 45" --out "$dir/boardrec" > "$dir/boardrec.txt"
test -s "$dir/boardrec/recording.rawlog" || { echo "no rawlog"; exit 1; }
test "$(grep -vc '^#' "$dir/boardrec/encoders.txt")" -gt 100 || { echo "few encoder readings"; exit 1; }
for rec in "$dir/boardrec" "$dir/boardrec/recording.rawlog"; do
  "$slamo" dry-run --from-recording "$rec" --out "$dir/boardreplay" > /dev/null
  python3 - "$dir/boardreplay/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["pose_ate_m"] is not None and r["pose_ate_m"] < 0.1, r["pose_ate_m"]
assert r["frames_taken"] > 20, r["frames_taken"]
PY
done

# A noisy link and the cable out for half a second: the match goes on and ends stopped.
"$slamo" match --fake-board --recording "$dir/rec" --loop --season "$dir/toss_up_15.yaml" \
  --drop 0.02 --garbage 0.02 --duplicate 0.02 --unplug-at 4 --replug-at 4.5 \
  --out "$dir/faults" --quiet --no-video > "$dir/faults.txt"
grep -q "fake board unplugged" "$dir/faults.txt" || { echo "no unplug"; exit 1; }
grep -q "plugged in again" "$dir/faults.txt" || { echo "no replug"; exit 1; }
python3 - "$dir/faults/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
b = r["board"]
assert b["link_losses"] >= 1, b
assert b["port_opens"] >= 2, b
assert r["overrun_s"] == 0.0, r["overrun_s"]
assert r["timeline"][-1]["end_s"] > 10.0, r["timeline"][-1]
PY
grep -q 'PWM now 90/90' "$dir/faults.txt" || { echo "motors not stopped"; cat "$dir/faults.txt"; exit 1; }

# Bad input: exit 2; no board: exit 1.
set +e
"$slamo" match > "$dir/none.txt" 2>&1; test $? -eq 2 || { echo "no board: not 2"; exit 1; }
grep -q -- "--port DEV" "$dir/none.txt" || { echo "no board: message"; exit 1; }
"$slamo" match --fake-board --camera sim --alliance green --out "$dir/bad" > /dev/null 2>&1
test $? -eq 2 || { echo "bad alliance: not 2"; exit 1; }
"$slamo" match --port /dev/null --camera sim --out "$dir/bad" > /dev/null 2>&1
test $? -eq 2 || { echo "sim camera without fake board: not 2"; exit 1; }
"$slamo" match --fake-board --recording "$dir/nothing" --out "$dir/bad" > /dev/null 2>&1
test $? -eq 2 || { echo "missing recording: not 2"; exit 1; }
"$slamo" match --port "$dir/no-such-device" --recording "$dir/rec" --out "$dir/bad" > "$dir/nodev.txt" 2>&1
test $? -eq 1 || { echo "missing device: not 1"; cat "$dir/nodev.txt"; exit 1; }
grep -q "did not answer" "$dir/nodev.txt" || { echo "missing device: message"; exit 1; }
set -e
echo "match CLI checks passed"
