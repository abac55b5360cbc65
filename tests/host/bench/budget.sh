#!/bin/sh
# SPDX-License-Identifier: MIT
# budget.sh SL_SIM BUILD_DIR SRC_DIR WORKDIR: the pipeline's instruction budget, counted by
# valgrind's callgrind (host_tools/bench/callgrind.sh over sl-bench, the firmware
# configuration compiled -O2 whatever the build type; no timing):
#   <= 2,500 instructions per azimuth and <= 1.0 M per rotation (paper-sim: 400 azimuths) on
#   - scenes/bench_eight_poles.ini: 8 tracked targets, static (docs/PERFORMANCE.md);
#   - scenes/driveby_two_poles.ini with its [clutter] band enabled at 1 m/s: the clutter
#     test's capture (tests/system/daemon/clutter_driveby.sh), the heaviest detection load
#     the project has (docs/DESIGN.md, "Clutter").
# Prints each capture's figures; fails on the first one over the budget.
set -eu
sim=$1 build=$2 src=$3 dir=$4
MAX_AZ=${MAX_AZ:-2500}
MAX_ROT=${MAX_ROT:-1000000}
rm -rf "$dir"; mkdir -p "$dir"
"$sim" "$src/scenes/bench_eight_poles.ini" -o "$dir/eight.colossus" --threads 1 --quiet
sed 's/^enabled = false/enabled = true/' "$src/scenes/driveby_two_poles.ini" > "$dir/clutter1.ini"
grep -q '^enabled = true' "$dir/clutter1.ini" || { echo "budget: scene edit failed" >&2; exit 1; }
"$sim" "$dir/clutter1.ini" -o "$dir/clutter1.colossus" --threads 1 --quiet
fail=0
check() { # name, capture, sl-bench args...
    name=$1 cap=$2
    shift 2
    out=$(sh "$src/host_tools/bench/callgrind.sh" "$build" "$cap" --board paper-sim "$@")
    echo "$out" | sed "s/^/$name: /"
    az=$(echo "$out" | awk '$1 == "instructions_per_azimuth:" {print $2; exit}')
    rot=$(echo "$out" | awk '$1 == "instructions_per_rotation:" {print $2; exit}')
    [ -n "$az" ] && [ -n "$rot" ] || { echo "budget: $name: no figures" >&2; exit 1; }
    if [ "$az" -gt "$MAX_AZ" ] || [ "$rot" -gt "$MAX_ROT" ]; then
        echo "budget: $name: $az instructions per azimuth, $rot per rotation: over the" \
             "$MAX_AZ / $MAX_ROT budget" >&2
        fail=1
    else
        echo "budget: $name: $az per azimuth, $rot per rotation (budget $MAX_AZ / $MAX_ROT)"
    fi
}
check eight "$dir/eight.colossus"
check clutter "$dir/clutter1.colossus" --speed-mm-s 1000
[ "$fail" = 0 ] && echo "budget: OK"
exit "$fail"
