#!/bin/sh
# `slamo detect` as a user runs it: on an ordinary photo with a colours file, on a rendered
# frame with depth and without it, and on bad input (exit status 2, a message, no crash).
# Usage: detect_test.sh SLAMO_BINARY SOURCE_DIR
set -u
slamo=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The photo: eleven sweets are red, green or blue and wholly in view; K-Means finds them.
out=$("$slamo" detect --color "$src/tests/data/photos/smarties.png" \
  --colours "$src/tests/data/photos/smarties_colours.yaml" --method kmeans --json) || fail "photo: exit $?"
n=$(echo "$out" | grep -c '"colour"')
[ "$n" -ge 10 ] || fail "photo: $n detections, expected at least 10"

# A rendered frame with depth: every detection has a range.
"$slamo" sim render --seed 5 --pose -1.2,-0.5,30 --out "$work/frame" > /dev/null || fail "render"
out=$("$slamo" detect --color "$work/frame/colour.png" --depth "$work/frame/depth.png" \
  --out "$work/seen.png") || fail "frame: exit $?"
echo "$out"
echo "$out" | grep -q "range" || fail "frame: no range in the output"
[ -s "$work/seen.png" ] || fail "frame: no annotated picture"

# The same frame without depth: the objects on the floor are typed and ranged on the ground
# plane. This view also holds three large balls lying on the barrier and the blue stash: none
# rests on the floor, so they stay untyped; with them, a 94-pixel piece of the blue one's rim
# by its highlight (five at most).
out=$("$slamo" detect --color "$work/frame/colour.png") || fail "no depth: exit $?"
echo "$out"
n=$(echo "$out" | grep -c "centre")
typed=$(echo "$out" | grep "centre" | grep -c "(ground plane)")
untyped=$(echo "$out" | grep "centre" | grep -c "  -  ")
[ "$typed" -ge 6 ] || fail "no depth: $typed of $n detections typed on the ground plane, expected 6"
[ "$untyped" -le 5 ] || fail "no depth: $untyped untyped detections, expected at most 5"
[ $((typed + untyped)) -eq "$n" ] || fail "no depth: a typed detection without a ground-plane range"

# Bad input.
expect_2() {  # expect_2 NAME PATTERN ARGS...
  name=$1; pattern=$2; shift 2
  msg=$("$slamo" "$@" 2>&1); code=$?
  [ "$code" -eq 2 ] || fail "$name: exit $code, expected 2 ($msg)"
  echo "$msg" | grep -q "$pattern" || fail "$name: message '$msg' lacks '$pattern'"
}
echo "not an image" > "$work/not_an_image.png"
expect_2 non_image "not a readable image" detect --color "$work/not_an_image.png"
"$slamo" sim render --seed 1 --out "$work/other" > /dev/null
expect_2 depth_8bit "16-bit" detect --color "$work/frame/colour.png" --depth "$work/other/colour.png"
printf 'colours:\n  red: {rgb: "#ee0000", hue_tolerence_deg: 6}\n' > "$work/typo.yaml"
expect_2 colours_typo "unknown key" detect --color "$work/frame/colour.png" --colours "$work/typo.yaml"
expect_2 bad_method "threshold or kmeans" detect --color "$work/frame/colour.png" --method hough
[ "$failures" -eq 0 ]
