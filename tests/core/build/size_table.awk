# SPDX-License-Identifier: MIT
# size -A FILE -> "object text rodata data bss" per object: for an archive every member
# ("x.c.obj (ex lib.a):"), for a linked image one row "image" (flash = code + constants
# without the .capture test data; RAM = .data + .bss, the stack reserve not included).
BEGIN { obj = "image"; objs[obj] = 0 }
/\(ex / { obj = $1; sub(/\.obj$/, "", obj); sub(/\.o$/, "", obj); objs[obj] = 1; next }
NF == 3 && $2 ~ /^[0-9]+$/ {
    s = $1; n = $2; objs[obj] = 1
    if (s ~ /^\.(text|isr_vector|ARM\.exidx)/) t[obj] += n
    else if (s ~ /^\.rodata/) r[obj] += n
    else if (s ~ /^\.data/) d[obj] += n
    else if (s ~ /^\.bss/ || s ~ /^COMMON/) b[obj] += n
}
END { for (o in objs) if (objs[o]) printf "%s %d %d %d %d\n", o, t[o], r[o], d[o], b[o] }
