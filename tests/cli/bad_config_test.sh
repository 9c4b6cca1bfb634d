#!/bin/sh
# `slamo field check` on broken season files: exit status 2 and a message naming
# file:line:column, the key path and what was expected. Files are made from the shipped
# toss_up.yaml, one mistake each. Usage: bad_config_test.sh SLAMO_BINARY SOURCE_DIR
set -u
slamo=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

expect() {  # expect NAME SED_EXPRESSION PATTERN
  sed "$2" "$src/field_configs/toss_up.yaml" > "$work/$1.yaml"
  out=$("$slamo" field check "$work/$1.yaml" 2>&1)
  code=$?
  echo "$out"
  if [ "$code" -ne 2 ]; then echo "FAIL $1: exit status $code, expected 2"; failures=$((failures + 1)); fi
  if ! echo "$out" | grep -Eq "$3"; then echo "FAIL $1: message does not match: $3"; failures=$((failures + 1)); fi
}

expect misspelt_key 's/^  tile_m:/  tiel_m:/' \
  "misspelt_key.yaml:[0-9]+:3: field.tiel_m: unknown key: expected a known key \(did you mean 'tile_m'\?\)" 
expect negative_size 's/size_m: 0.127/size_m: -0.127/' \
  "negative_size.yaml:[0-9]+:[0-9]+: object_types\[0\].size_m: expected a positive number, got '-0.127'"
[ "$failures" -eq 0 ]
