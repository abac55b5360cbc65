#!/bin/sh
# SPDX-License-Identifier: MIT
# check_core_symbols.sh NM ARCHIVE [--no-softfloat|--sanitized]
#
# Fails (exit 1) when the portable core references anything outside the freestanding set:
# every symbol the archive leaves undefined must either be defined inside the archive or be
# on the allowlist below (mem* and the compiler's integer helpers). That catches malloc &
# co., stdio, any OS call, and with --no-softfloat (Cortex-M0) every soft-float helper.
# It names each offending symbol and the object that references it. --sanitized (the
# ASan/UBSan build) also allows the sanitizer runtime's hooks (__asan_*, __ubsan_*, ...),
# which the instrumentation itself adds; everything else stays forbidden.
set -eu
NM=$1
LIB=$2
NOSOFT=${3:-}
sanitizer='^$'
if [ "$NOSOFT" = "--sanitized" ]; then
    sanitizer='^(__(asan|ubsan|lsan|sanitizer)_[A-Za-z0-9_]+|__sancov_[A-Za-z0-9_]+)$'
fi
[ -f "$LIB" ] || { echo "check_core_symbols: no such archive: $LIB" >&2; exit 2; }

# Symbols defined anywhere in the archive.
defined=$($NM -g --defined-only "$LIB" 2>/dev/null | awk 'NF>=3 {print $3}' | sort -u)
# "object:symbol" for every undefined reference (nm -A prefixes archive:object:).
undef=$($NM -A -u "$LIB" 2>/dev/null | awk '{o=$1; sub(/:$/,"",o); n=split(o,p,":"); print p[n] ":" $NF}' | sort -u)

allow='^(memcpy|memset|memmove|memcmp|__aeabi_(u?idiv(mod)?|u?ldivmod|lmul|llsl|llsr|lasr|u?lcmp|memcpy[48]?|memmove[48]?|memset[48]?|memclr[48]?|uread[48]|uwrite[48])|__gnu_thumb1_case_[a-z0-9]+|__(u?div|u?mod|mul|ashl|ashr|lshr|popcount|clz|ctz|ffs|bswap|cmp|ucmp)[sdt]i[23]|__stack_chk_fail|__stack_chk_guard|_GLOBAL_OFFSET_TABLE_)$'
# Soft-float helpers (ARM EABI and libgcc names).
soft='^(__aeabi_(f|d|[iul]+2[fd]|[fd]2)|__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord)[sdt]f[23]|__(fix|fixuns|float|floatun|extend|trunc)[a-z]*[sdt]f[a-z0-9]*)'
forbidden_named='^(malloc|calloc|realloc|free|printf|fprintf|sprintf|snprintf|puts|putchar|fopen|fwrite|fread|fputs|fputc|stdout|stderr|stdin|abort|exit|time|clock_gettime|gettimeofday|socket|read|write|open|close|send|recv|sleep|usleep|assert|__assert_fail)$'

bad=0
for ref in $undef; do
    obj=${ref%%:*}
    sym=${ref#*:}
    if printf '%s\n' "$defined" | grep -qx "$sym"; then
        continue
    fi
    if printf '%s\n' "$sym" | grep -Eq "$sanitizer"; then
        continue
    fi
    if printf '%s\n' "$sym" | grep -Eq "$soft"; then
        if [ "$NOSOFT" = "--no-softfloat" ]; then
            echo "FORBIDDEN soft-float helper: $sym (referenced by $obj)"
            bad=1
        fi
        continue
    fi
    if printf '%s\n' "$sym" | grep -Eq "$forbidden_named"; then
        echo "FORBIDDEN libc/OS symbol: $sym (referenced by $obj)"
        bad=1
        continue
    fi
    if ! printf '%s\n' "$sym" | grep -Eq "$allow"; then
        echo "FORBIDDEN unlisted external symbol: $sym (referenced by $obj)"
        bad=1
    fi
done
if [ $bad -ne 0 ]; then
    echo "check_core_symbols: $LIB references symbols outside the freestanding set" >&2
    exit 1
fi
echo "check_core_symbols: $LIB OK ($(printf '%s\n' "$undef" | grep -c . || true) external references, all allowed)"
