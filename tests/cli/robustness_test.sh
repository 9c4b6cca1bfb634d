#!/bin/sh
# slamo experiment robustness on MRPT's simul-landmarks logs (one run a row): the table has a
# slamo and an MRPT line for each of the nine noise rows, and where the noise is what both
# filters are told, slamo's map and trajectory are within a centimetre of the truth. In every
# row, at up to 10x the told motion or sensor noise, slamo's landmark RMSE and ATE are within
# 1.5x MRPT's on the same logs, and its mean pose NEES under twice the band's top (18.7).
# On our simulator the V5 robot's rows (told the thesis robot's noise, then its own) are there
# with the same checks, and slamo's map and trajectory are within 3 cm of the truth in both.
set -eu
slamo="$1"
dir="$2"
rm -rf "$dir"
"$slamo" experiment robustness --runs 1 --out "$dir/logs" > "$dir.txt" 2> /dev/null
rows=$(grep -cE '^[0-9.]+x +[0-9.]+x +(slamo|mrpt) ' "$dir.txt")
test "$rows" -eq 18 || { echo "expected 18 table rows, got $rows"; cat "$dir.txt"; exit 1; }
sim=$(grep -cE '^v5_drivetrain +(thesis_robot|v5_drivetrain) +(slamo|mrpt) ' "$dir.txt")
test "$sim" -eq 4 || { echo "expected 4 simulator rows, got $sim"; cat "$dir.txt"; exit 1; }
awk '$1 == "v5_drivetrain" && $3 == "slamo" {
       if (!($4 < 0.03 && $5 < 0.03)) { print $1 " told " $2 ": landmark RMSE " $4 ", ATE " $5; bad = 1 }
     }
     END { exit bad }' "$dir.txt"
awk '$1 == "1.00x" && $2 == "1.00x" && $3 == "slamo" {
       found = 1
       if (!($4 < 0.01 && $5 < 0.01)) { print "1x/1x: landmark RMSE " $4 ", ATE " $5; bad = 1 }
     }
     END { if (!found) { print "no 1x/1x slamo row"; exit 1 } exit bad }' "$dir.txt"
awk '$3 == "slamo" { lm[$1 " " $2] = $4; ate[$1 " " $2] = $5; nees[$1 " " $2] = $6 }
     $3 == "mrpt" { mlm[$1 " " $2] = $4; mate[$1 " " $2] = $5 }
     END {
       for (row in lm) {
         if (lm[row] > 1.5 * mlm[row] || ate[row] > 1.5 * mate[row] || nees[row] > 18.7) {
           print row ": slamo landmarks " lm[row] " ATE " ate[row] " NEES " nees[row] \
                 " against MRPT " mlm[row] " and " mate[row]
           bad = 1
         }
       }
       exit bad
     }' "$dir.txt"
