#!/bin/sh
# SPDX-License-Identifier: MIT
# check_core_no_vfp.sh OBJDUMP ARCHIVE
#
# Fails (exit 1) when any object of a Cortex-M core archive contains a VFP or NEON
# instruction (v*: vpush/vpop/vldr/vstr/vmov/vmrs/vadd.f32 ..., or the pre-UAL f* memory
# forms). The symbol check cannot see these: on a hard-float build GCC keeps uint64_t
# values in d registers without calling any helper, and the first such instruction faults
# while the FPU is still off (CPACR CP10/CP11 = 0 at reset) and, under an RTOS, turns every
# calling task into an FP task. The core is built with -mgeneral-regs-only; this proves it.
# Names each offending object, function and instruction.
set -eu
OBJDUMP=$1
LIB=$2
[ -f "$LIB" ] || { echo "check_core_no_vfp: no such archive: $LIB" >&2; exit 2; }
out=$($OBJDUMP -d --no-show-raw-insn "$LIB" 2>/dev/null | awk '
    /^In archive/ { next }
    /file format/ { obj = $1; sub(/:$/, "", obj); n = split(obj, p, "/"); obj = p[n]; next }
    /^[0-9a-f]+ <.*>:$/ { fn = $2; gsub(/[<>:]/, "", fn); next }
    /^[ \t]+[0-9a-f]+:\t/ {
        ins = $0; sub(/^[ \t]+[0-9a-f]+:[ \t]+/, "", ins); sub(/[ \t].*/, "", ins)
        if (ins ~ /^v[a-z]/ || ins ~ /^f(ld|st)m/ || ins ~ /^f(mrx|mxr|mrs|msr)$/) {
            total++
            printf "FORBIDDEN VFP/NEON instruction: %s in %s (%s)\n", ins, fn, obj
        }
        insns++
    }
    END { printf "INSNS %d\n", insns }')
insns=$(printf '%s\n' "$out" | sed -n 's/^INSNS //p')
bad=$(printf '%s\n' "$out" | grep -c '^FORBIDDEN' || true)
[ "${insns:-0}" -gt 0 ] || { echo "check_core_no_vfp: no instructions disassembled from $LIB" >&2; exit 2; }
if [ "$bad" -ne 0 ]; then
    printf '%s\n' "$out" | grep '^FORBIDDEN'
    echo "check_core_no_vfp: $LIB has $bad VFP/NEON instruction(s)" >&2
    exit 1
fi
echo "check_core_no_vfp: $LIB OK ($insns instructions, no VFP/NEON)"
