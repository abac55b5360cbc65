#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""stack_budget.py: worst-case stack depth of the core from its call graph.

usage: stack_budget.py --ci-dir DIR --elf IMAGE.elf --objdump OBJDUMP --archive LIB.a
                       --root FN [--root FN ...] --budget BYTES [--cpu NAME]

Frames and direct calls of the core come from GCC's -fcallgraph-info=su files (*.ci, one per
object: every function's static frame size and call edges). Functions without a .ci node
(libgcc's __aeabi_* helpers, libc's memcpy/memset/memcmp, whatever the linked image uses)
are analysed from the image's disassembly: push/stmdb registers x 4 + sub sp + vpush, plus
their own bl/b.w callees. Indirect calls (GCC's __indirect_call, with the call's source
location) are resolved by the member called there (`s->cfg.on_row(...)` -> `on_row`) to the
address-taken core functions (R_ARM_ABS32 relocations against a function in the archive)
that the core's sources assign to that member (`.on_row = on_row`); a call whose member
no core function is assigned to is a port callback; a call the script cannot read is
resolved to every address-taken function (conservative). A function never appears twice
on one chain (the core is not reentrant). Indirect calls to the port (can_tx, on_rotation) leave the core:
the script reports the depth at the deepest such call site, which is what the port's
callbacks must add. Exit 1 when the worst chain from any root exceeds the budget, 2 on an
unusable input (no .ci files, a dynamic frame in the core, unknown callee).
Nothing is listed by hand, so functions added later are covered.
"""
import argparse
import glob
import os
import re
import subprocess
import sys

NODE = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
EDGE = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"(?: label: "([^"]+)")?')
ASSIGN = re.compile(r'\.\s*([A-Za-z_]\w*)\s*=\s*&?\s*([A-Za-z_]\w*)\s*[;,}]')


def short(title):
    return title.rsplit(':', 1)[-1] if ':' in title else title


def load_ci(ci_dir):
    frames, dynamic, edges, static_of = {}, set(), {}, {}
    files = glob.glob(os.path.join(ci_dir, '**', '*.ci'), recursive=True)
    for f in files:
        obj = os.path.basename(f)[:-3]  # scan.c.ci -> scan.c
        for line in open(f, encoding='utf-8', errors='replace'):
            m = NODE.search(line)
            if m:
                title, label = m.group(1), m.group(2)
                fm = re.search(r'(\d+) bytes \(([a-z, ]+)\)', label)
                if fm:
                    frames[title] = int(fm.group(1))
                    if 'dynamic' in fm.group(2):
                        dynamic.add(title)
                    if ':' in title:
                        static_of.setdefault((obj, short(title)), title)
                edges.setdefault(title, [])
                continue
            m = EDGE.search(line)
            if m:
                tgt = m.group(2)
                if tgt == '__indirect_call':
                    tgt = '__indirect_call@' + (m.group(3) or '?')
                edges.setdefault(m.group(1), []).append(tgt)
    return files, frames, dynamic, edges, static_of


def address_taken(objdump, archive, frames, static_of):
    """Core functions whose address is stored (callbacks): R_ARM_ABS32 against a function."""
    out = subprocess.run([objdump, '-r', archive], capture_output=True, text=True, check=True).stdout
    taken, obj = set(), None
    for line in out.splitlines():
        m = re.match(r'RELOCATION RECORDS FOR \[([^\]]+)\]', line)
        if m:
            continue
        m = re.match(r'^(\S+\.obj):\s+file format', line)
        if m:
            obj = m.group(1)[:-4]  # scan.c.obj -> scan.c
            continue
        parts = line.split()
        if len(parts) == 3 and parts[1] == 'R_ARM_ABS32':
            sym = parts[2]
            sym = sym[len('.text.'):] if sym.startswith('.text.') else sym
            if obj and (obj, sym) in static_of:
                taken.add(static_of[(obj, sym)])
            elif sym in frames:
                taken.add(sym)
    return taken


_src_cache = {}


def member_at(loc):
    """Member name called at 'path:line:col' (the identifier before the first '(')."""
    try:
        path, line, col = loc.rsplit(':', 2)
        if path not in _src_cache:
            _src_cache[path] = open(path, encoding='utf-8', errors='replace').read().splitlines()
        text = _src_cache[path][int(line) - 1][int(col) - 1:]
    except (ValueError, OSError, IndexError):
        return None
    m = re.match(r'[^(]*?([A-Za-z_]\w*)\s*\(', text)
    return m.group(1) if m else None


def assignments(src_dirs):
    """member -> functions assigned to it anywhere in the core's sources."""
    out = {}
    for d in src_dirs:
        for f in glob.glob(os.path.join(d, '*.c')):
            for m in ASSIGN.finditer(open(f, encoding='utf-8', errors='replace').read()):
                out.setdefault(m.group(1), set()).add(m.group(2))
    return out


def elf_frames(objdump, elf):
    """Own frame and callees of every function in the image, from its disassembly."""
    out = subprocess.run([objdump, '-d', '--no-show-raw-insn', elf], capture_output=True,
                         text=True, check=True).stdout
    alias = {}  # address -> the name objdump prints; other names at that address map to it
    nm = subprocess.run([objdump.replace('objdump', 'nm'), elf], capture_output=True, text=True).stdout
    by_addr = {}
    for line in nm.splitlines():
        p = line.split()
        if len(p) == 3 and p[1] in 'tTwW':
            by_addr.setdefault(p[0], []).append(p[2])
    frames, calls, fn = {}, {}, None
    for line in out.splitlines():
        m = re.match(r'^[0-9a-f]+ <([^>]+)>:$', line)
        if m:
            fn = m.group(1)
            frames.setdefault(fn, 0)
            calls.setdefault(fn, set())
            continue
        if fn is None:
            continue
        m = re.match(r'^\s+[0-9a-f]+:\s+(\S+)\s*(.*)$', line)
        if not m:
            continue
        op, args = m.group(1), m.group(2)
        if op in ('push', 'push.w') or (op.startswith('stmdb') and args.startswith('sp!')):
            regs = re.search(r'\{([^}]*)\}', args)
            if regs:
                n = 0
                for r in regs.group(1).split(','):
                    r = r.strip()
                    if '-' in r:
                        a, b = r.split('-')
                        n += int(b.strip()[1:]) - int(a.strip()[1:]) + 1
                    elif r:
                        n += 1
                frames[fn] += 4 * n
        elif op.startswith('str') and re.search(r'\[sp,\s*#-(\d+)\]!', args):
            frames[fn] += int(re.search(r'\[sp,\s*#-(\d+)\]!', args).group(1))
        elif op == 'vpush':
            regs = re.search(r'\{([^}]*)\}', args)
            if regs:
                frames[fn] += 8 * len(regs.group(1).split(','))
        elif op.startswith('sub') and re.match(r'sp,\s*(sp,\s*)?#\d+', args):
            frames[fn] += int(re.search(r'#(\d+)', args).group(1))
        elif op in ('bl', 'b.w', 'blx') or (op.startswith('b') and '<' in args and '+' not in args):
            t = re.search(r'<([^>+]+)>', args)
            if t and t.group(1) != fn:
                calls[fn].add(t.group(1))
    for names in by_addr.values():
        known = [n for n in names if n in frames]
        if known:
            for n in names:
                if n not in frames:
                    frames[n] = frames[known[0]]
                    calls[n] = calls[known[0]]
    return frames, calls


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--ci-dir', required=True)
    ap.add_argument('--elf', required=True)
    ap.add_argument('--objdump', required=True)
    ap.add_argument('--archive', required=True)
    ap.add_argument('--root', action='append', required=True)
    ap.add_argument('--budget', type=int, required=True)
    ap.add_argument('--cpu', default='')
    a = ap.parse_args()

    files, frames, dynamic, edges, static_of = load_ci(a.ci_dir)
    if not files:
        print(f'stack_budget: no .ci files under {a.ci_dir} (build with -fcallgraph-info=su)')
        return 2
    if dynamic:
        print('stack_budget: dynamic (unbounded) frames in the core: ' + ', '.join(sorted(dynamic)))
        return 2
    taken = address_taken(a.objdump, a.archive, frames, static_of)
    src_dirs = sorted({os.path.dirname(t.rsplit(':', 1)[0]) for t in frames if ':' in t})
    assigned = assignments(src_dirs)
    efr, ecalls = elf_frames(a.objdump, a.elf)

    sys.setrecursionlimit(10000)
    port_sites = []  # (depth at the indirect call incl. the caller's frame, chain)

    def frame_of(n):
        if n in frames:
            return frames[n]
        s = short(n)
        if s in efr:
            return efr[s]
        raise KeyError(n)

    def callees(n):
        if n in frames:
            return list(edges.get(n, []))
        return sorted(ecalls.get(short(n), ()))

    def resolve(site):
        """Core functions an indirect call may reach; [] = a port callback."""
        member = member_at(site.split('@', 1)[1])
        if member is None:
            return sorted(taken)  # unreadable: every callback (conservative)
        names = assigned.get(member, set())
        return sorted(t for t in taken if short(t) in names)

    unknown = set()

    def worst(n, path):
        """Deepest stack below and including n, as (bytes, chain)."""
        try:
            own = frame_of(n)
        except KeyError:
            unknown.add(n)
            return 0, [n + ' (?)']
        best, chain = 0, []
        for t in callees(n):
            if t.startswith('__indirect_call'):
                targets = resolve(t)
                if not targets:
                    port_sites.append((sum(frame_of(p) for p in path) + own, path + [n]))
                for cb in targets:
                    if cb in path or cb == n:
                        continue
                    d, c = worst(cb, path + [n])
                    if d > best:
                        best, chain = d, c
                continue
            if t in path or t == n:
                continue  # recursion is not allowed in the core; a cycle here is a helper loop
            d, c = worst(t, path + [n])
            if d > best:
                best, chain = d, c
        return own + best, [n] + chain

    bad = False
    for root in a.root:
        titles = [t for t in frames if short(t) == root]
        if not titles:
            print(f'stack_budget: root {root} not found in the call graph')
            return 2
        d, chain = worst(titles[0], [])
        print(f'stack: {a.cpu} worst case from {root}: {d} bytes (budget {a.budget}), '
              'port callbacks not included')
        acc = 0
        for n in chain:
            try:
                f = frame_of(n)
            except KeyError:
                f = 0
            acc += f
            print(f'  {acc:5d}  +{f:4d}  {short(n)}')
        if d > a.budget:
            print(f'FAIL: {root} needs {d} bytes > budget {a.budget}')
            bad = True
    if port_sites:
        depth, chain = max(port_sites, key=lambda x: x[0])
        print(f'stack: deepest indirect call site (a port callback runs on top of this): '
              f'{depth} bytes in {short(chain[-1])}')
    if unknown:
        print('stack_budget: callees without a frame (not in the .ci files nor the image): '
              + ', '.join(sorted(unknown)))
        return 2
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
