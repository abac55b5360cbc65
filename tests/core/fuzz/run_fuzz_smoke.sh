#!/bin/sh
# SPDX-License-Identifier: MIT
# run_fuzz_smoke.sh FUZZER CORPUS_DIR SECONDS ARTIFACT_DIR [MAX_LEN]
# Bounded libFuzzer run on a temporary copy of a seed corpus (the committed corpus of
# fuzz_proto, the drive-bys fuzz_tilt_replay writes for fuzz_tilt; never modified), inputs
# up to MAX_LEN bytes (default 40000). Exit status: the fuzzer's (non-zero on a crash or
# invariant failure; the reproducer is written to ARTIFACT_DIR).
set -eu
fuzzer=$1
corpus=$2
seconds=$3
artifacts=$4
max_len=${5:-40000}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_fuzz.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
cp "$corpus"/* "$tmp"/
mkdir -p "$artifacts"
"$fuzzer" -max_total_time="$seconds" -max_len="$max_len" -timeout=20 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts"/ "$tmp"
