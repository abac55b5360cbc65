#!/bin/sh
# SPDX-License-Identifier: MIT
# test.sh: the whole test suite, from a fresh Debian machine (installs what is missing).
#   host       Debug build: unit, build/symbol checks, tables, tools, integration tests
#   host-asan  ASan + UBSan build of the same tests, plus the bounded fuzz run
#   aarch64    unit tests cross-built, run under qemu-aarch64
#   s390x      unit tests cross-built (big-endian), run under qemu-s390x
#   cortex-m0/m4f  bare-metal firmware-configuration builds (core + example image), size budget
#   firmware   the Cortex-M figures proved by the host ctest (thumb, stack, size): printed
# Exit status: non-zero when any step fails. Set SL_TEST_ONLY="host aarch64" to run a subset.
set -eu
cd "$(dirname "$0")/.."
T0=$(date +%s)
sh scripts/deps.sh build test
echo "=== [deps] $(($(date +%s) - T0)) s"
STEPS=${SL_TEST_ONLY:-"host host-asan aarch64 s390x cortex-m0 cortex-m4f firmware"}
JOBS=${SL_JOBS:-2}
failed=""
CTLOG=$(mktemp)
trap 'rm -f "$CTLOG"' EXIT
run() { # name, command...: each step's wall time, so a slow step shows in the CI log
    name=$1; shift
    echo "=== [$name] $*"
    t=$(date +%s)
    if ! "$@"; then failed="$failed $name"; echo "=== [$name] FAILED"; fi
    now=$(date +%s)
    echo "=== [$name] $((now - t)) s (suite $((now - T0)) s)"
}
run_ctest() { # ctest args...: keeps ctest's summary lines for the closing total
    set +e
    ctest "$@" > "$CTLOG.out" 2>&1
    rc=$?
    set -e
    cat "$CTLOG.out"
    grep -E "tests passed, [0-9]+ tests? failed out of [0-9]+" "$CTLOG.out" >> "$CTLOG" || true
    rm -f "$CTLOG.out"
    return $rc
}
firmware_figures() { # re-runs the few firmware tests verbosely (seconds) for their figures
    ctest --preset host -R "thumb_run|thumb_oxford_m|check_stack_cortex|check_size_budget_cortex_m" -V > "$CTLOG.fw" 2>&1
    rc=$?
    sed -n 's/^[0-9]*: \(thumb: .*\|stack: .*\|.*TOTAL (core.*\|image .*\|check_size_budget: .*\)$/  \1/p' "$CTLOG.fw"
    grep -E "tests passed, [0-9]+ tests? failed out of [0-9]+" "$CTLOG.fw" >> "$CTLOG" || true
    rm -f "$CTLOG.fw"
    return $rc
}
configure_build() { # preset
    cmake --preset "$1" >/dev/null && cmake --build --preset "$1" -j "$JOBS"
}
for s in $STEPS; do
    case "$s" in
    host) run host-build configure_build host
          run host-ctest run_ctest --preset host --output-on-failure ;;
    host-asan) run asan-build configure_build host-asan
          # static analysis, the Cortex-M tests and the fuzz run (clang's own ASan + UBSan
          # build of the decoder) do not depend on the host's sanitizers: the host step
          # runs them once.
          run asan-ctest run_ctest --preset host-asan --output-on-failure -LE "vm|slow|static|thumb|install|fuzz" ;;
    aarch64) run aarch64-build configure_build cross-aarch64
          run aarch64-ctest run_ctest --preset cross-aarch64 --output-on-failure ;;
    s390x) run s390x-build configure_build cross-s390x
          run s390x-ctest run_ctest --preset cross-s390x --output-on-failure ;;
    cortex-m0|cortex-m4f) run "$s" configure_build "cross-$s" ;;
    firmware) run firmware firmware_figures ;;
    *) echo "unknown step $s"; exit 2 ;;
    esac
done
if [ -n "$failed" ]; then
    echo "test.sh: FAILED:$failed"
else
    echo "test.sh: all steps passed ($STEPS)"
fi
# One closing line over every ctest run: "<failed> tests failed out of <total>" summed.
awk '{ for (i = 1; i <= NF; i++) if ($i == "out" && $(i+1) == "of") total += $(i+2);
       for (i = 1; i <= NF; i++) if ($i == "failed" && $(i-2) ~ /^[0-9]+$/) bad += $(i-2) }
     END { printf "total: %d passed, %d failed\n", total - bad, bad }' "$CTLOG"
[ -z "$failed" ]
