#!/bin/sh
# SPDX-License-Identifier: MIT
# run_fuzz_smoke.sh FUZZER CORPUS_DIR SECONDS ARTIFACT_DIR
# Bounded libFuzzer run on a temporary copy of the committed corpus (the committed corpus
# is never modified). Exit status: the fuzzer's (non-zero on a crash or invariant failure;
# the reproducer is written to ARTIFACT_DIR).
set -eu
fuzzer=$1
corpus=$2
seconds=$3
artifacts=$4
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_fuzz_proto.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
cp "$corpus"/* "$tmp"/
mkdir -p "$artifacts"
"$fuzzer" -max_total_time="$seconds" -max_len=40000 -timeout=20 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts"/ "$tmp"
