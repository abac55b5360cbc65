#!/bin/sh
# SPDX-License-Identifier: MIT
# run_fuzz_tilt.sh FUZZER REPLAY SECONDS ARTIFACT_DIR
# Bounded libFuzzer run of fuzz_tilt, seeded with 40 pseudo-random drive-bys that the replay
# build writes to a temporary directory (fuzz_tilt_replay --random 40 --write DIR). Exit
# status: the fuzzer's (non-zero on a crash, a sanitizer report or a failed invariant; the
# reproducer is written to ARTIFACT_DIR; replay it with `fuzz_tilt_replay FILE`).
set -eu
fuzzer=$1
replay=$2
seconds=$3
artifacts=$4
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_fuzz_tilt.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
"$replay" --random 40 --write "$tmp"
mkdir -p "$artifacts"
"$fuzzer" -max_total_time="$seconds" -max_len=4096 -timeout=20 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts"/ "$tmp"
