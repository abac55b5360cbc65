#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Write the generated parts of the documentation from their sources of truth.

    sl_docs_gen.py [--check] [PART...]     PART: can config footprint results debian (default: all)

Each part replaces the text between "<!-- BEGIN GENERATED: sl_docs_gen PART -->" and
"<!-- END GENERATED: sl_docs_gen PART -->" in the pages that carry those markers:

  can        docs/CAN_REFERENCE.md  <- boards/*/shadowlean.dbc (written by sl-tables from the
             core's layout table): every message, signal, bit layout, range, value table, E2E
  config     docs/DAEMON.md         <- apps/shadowleand/daemon_opts.c: the option table
             (k_cli) and the usage text's meaning of every option and config key
  footprint  docs/INTEGRATION.md    <- firmware/size_budget.txt and the budgets of the thumb
             and stack tests (tests/core/thumb/CMakeLists.txt)
  results    docs/RESULTS.md, README.md  <- docs/results/*.json (sl-eval --json outputs;
             the command that produced each is in RESULTS.md)
  debian     packaging/debian/changelog <- CHANGELOG.md (the whole file)

--check: write nothing; exit 1 and name the page when a part is not what its source gives.
Run without --check after changing a source: regeneration is this one command."""
import glob
import json
import os
import re
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def rd(rel):
    with open(os.path.join(ROOT, rel), encoding="utf-8") as fh:
        return fh.read()


# ---------------------------------------------------------------------------------- DBC
def parse_dbc(text):
    """The subset of DBC that sl-tables writes: BO_/SG_/CM_/BA_/VAL_."""
    msgs, order = {}, []
    cur = None
    net_comment = ""
    for line in text.splitlines():
        m = re.match(r"BO_ (\d+) (\w+): (\d+) (\w+)", line)
        if m:
            cur = {"id": int(m.group(1)), "name": m.group(2), "dlc": int(m.group(3)),
                   "sender": m.group(4), "signals": [], "attrs": {}, "comment": ""}
            msgs[cur["id"]] = cur
            order.append(cur["id"])
            continue
        m = re.match(r' SG_ (\w+) : (\d+)\|(\d+)@([01])([+-]) \(([^,]+),([^)]+)\) '
                     r'\[([^|]+)\|([^\]]+)\] "([^"]*)" (.*)', line)
        if m and cur is not None:
            cur["signals"].append({
                "name": m.group(1), "start": int(m.group(2)), "len": int(m.group(3)),
                "intel": m.group(4) == "1", "signed": m.group(5) == "-",
                "factor": m.group(6), "offset": m.group(7), "min": m.group(8), "max": m.group(9),
                "unit": m.group(10), "receivers": m.group(11).strip(), "comment": "", "values": []})
            continue
    for m in re.finditer(r'^CM_ "((?:[^"\\]|\\.)*)";', text, re.M):
        net_comment = m.group(1)
    for m in re.finditer(r'^CM_ BO_ (\d+) "((?:[^"\\]|\\.)*)";', text, re.M):
        msgs[int(m.group(1))]["comment"] = m.group(2)
    for m in re.finditer(r'^CM_ SG_ (\d+) (\w+) "((?:[^"\\]|\\.)*)";', text, re.M):
        for s in msgs[int(m.group(1))]["signals"]:
            if s["name"] == m.group(2):
                s["comment"] = m.group(3)
    for m in re.finditer(r'^BA_ "(\w+)" BO_ (\d+) (.+);', text, re.M):
        msgs[int(m.group(2))]["attrs"][m.group(1)] = m.group(3).strip().strip('"')
    enum = {}
    m = re.search(r'^BA_DEF_ BO_\s+"GenMsgSendType" ENUM\s+(.+);', text, re.M)
    if m:
        enum = {i: v.strip().strip('"') for i, v in enumerate(m.group(1).split(","))}
    for m in re.finditer(r'^VAL_ (\d+) (\w+) (.*);', text, re.M):
        pairs = re.findall(r'(\d+) "([^"]*)"', m.group(3))
        for s in msgs[int(m.group(1))]["signals"]:
            if s["name"] == m.group(2):
                s["values"] = sorted((int(v), n) for v, n in pairs)
    baud = re.search(r'^BA_ "Baudrate" (\d+);', text, re.M)
    return [msgs[i] for i in order], net_comment, enum, int(baud.group(1)) if baud else None


def bit_span(s):
    """Intel (little-endian) layout: the bytes and bits the signal occupies."""
    first, last = s["start"], s["start"] + s["len"] - 1
    if first // 8 == last // 8:
        return f"byte {first // 8}, bits {first % 8}..{last % 8}"
    return f"byte {first // 8} bit {first % 8} .. byte {last // 8} bit {last % 8}"


def can_id(raw):
    """A DBC message id as a reader writes it: 29-bit ids (the DBC sets bit 31) with 'ext'."""
    if raw & 0x80000000:
        return f"0x{raw & 0x1FFFFFFF:08X} ext"
    return f"0x{raw:03X}"


def md(text):
    return text.replace("|", "\\|").replace("\n", " ")


def gen_can():
    boards = sorted(os.path.basename(os.path.dirname(p))
                    for p in glob.glob(os.path.join(ROOT, "boards", "*", "shadowlean.dbc")))
    ref = "paper-sim" if "paper-sim" in boards else boards[0]
    msgs, net, enum, baud = parse_dbc(rd(f"boards/{ref}/shadowlean.dbc"))
    out = [f"Source: `boards/{ref}/shadowlean.dbc` (every board's DBC has the same layouts; "
           "ids and bit rate per board below). Classic CAN, DLC 8, "
           f"{baud // 1000 if baud else '?'} kbit/s by default.", "",
           "**E2E (every message).** " + md(net), "",
           "Ids and bit rate per board (`[can]` in `boards/<board>/board.ini`):", ""]
    head = "| board | bit rate | " + " | ".join(m["name"] for m in msgs) + " |"
    out += [head, "|---" * (2 + len(msgs)) + "|"]
    for b in boards:
        bm, _, _, bb = parse_dbc(rd(f"boards/{b}/shadowlean.dbc"))
        ids = {m["name"]: m["id"] for m in bm}
        out.append(f"| `{b}` | {bb} | " + " | ".join(
            can_id(ids[m["name"]]) if m["name"] in ids else "-" for m in msgs) + " |")
    for m in msgs:
        a = m["attrs"]
        send = enum.get(int(a["GenMsgSendType"]), a["GenMsgSendType"]) if "GenMsgSendType" in a else "-"
        cyc = a.get("GenMsgCycleTime", "-")
        idle = a.get("SlIdleCycleTime")
        did = int(a["SlE2EDataId"]) if "SlE2EDataId" in a else None
        out += ["", f"### {m['name']} ({can_id(m['id'])})", "",
                f"Sender {m['sender']}, DLC {m['dlc']}, {send}, cycle {cyc} ms"
                + (f", idle cycle {idle} ms" if idle else "")
                + (f", E2E Data ID 0x{did:02X}" if did is not None else "") + ".", "",
                md(m["comment"]), "",
                "| signal | start\\|length | bytes / bits | type | factor, offset | range | unit | values | meaning |",
                "|---|---|---|---|---|---|---|---|---|"]
        for s in m["signals"]:
            vals = ", ".join(f"{v} {n}" for v, n in s["values"]) or ""
            typ = ("signed" if s["signed"] else "unsigned") + (" LE" if s["intel"] else " BE")
            out.append(f"| `{s['name']}` | {s['start']}\\|{s['len']} | {bit_span(s)} | {typ} | "
                       f"{s['factor']}, {s['offset']} | {s['min']} .. {s['max']} | {s['unit']} | "
                       f"{md(vals)} | {md(s['comment'])} |")
    return "\n".join(out)


# ------------------------------------------------------------------------- daemon config
def c_strings(block):
    """Concatenate the C string literals of a block, with the usual escapes."""
    parts = re.findall(r'"((?:[^"\\]|\\.)*)"', block)
    s = "".join(parts)
    return s.replace("\\n", "\n").replace('\\"', '"').replace("\\\\", "\\")


def gen_config():
    src = rd("apps/shadowleand/daemon_opts.c")
    table = re.search(r"static const cli_opt_t k_cli\[\] = \{(.*?)\n\};", src, re.S).group(1)
    opts = re.findall(r'\{"([^"]+)", (NULL|"[a-z]+"), "([a-z_0-9]+)", (\d), (NULL|"[^"]*")\}', table)
    keys_in_parser = set(re.findall(r'IS\("([a-z]+)", "([a-z_0-9]+)"\)', src))
    usage_fn = re.search(r"void sld_opts_usage\(void \*fpv\)\n\{(.*?)\n\}", src, re.S).group(1)
    text = "".join(c_strings(b) for b in re.findall(r"fputs\((.*?),\s*fp\);", usage_fn, re.S))
    # meaning per "[section] key": the usage line's third column plus its continuation lines
    meaning, last = {}, None
    for line in text.splitlines():
        m = re.match(r"  (\S.*?)\s+\[(\w+)\] (\w+)\s+(.*)$", line)
        if m:
            last = (m.group(2), m.group(3))
            meaning[last] = [m.group(1).strip(), m.group(4).strip()]
            continue
        if last and re.match(r"\s{40,}\S", line):
            meaning[last][1] += " " + line.strip()
            continue
        last = None
    rows, seen = [], set()
    for opt, sec, key, _argc, _fixed in opts:
        if sec == "NULL":
            continue
        sec = sec.strip('"')
        if (sec, key) in seen:
            continue
        seen.add((sec, key))
        flags = [o for o, s2, k2, _, _ in opts if s2.strip('"') == sec and k2 == key]
        usage_opt, desc = meaning.get((sec, key), ["", ""])
        rows.append((sec, key, usage_opt or " / ".join(flags), desc))
    missing = sorted(set(keys_in_parser) - seen)
    if missing:
        raise SystemExit(f"sl_docs_gen: config keys without an option in k_cli: {missing}")
    undocumented = [f"[{s}] {k}" for s, k, _, d in rows if not d]
    if undocumented:
        raise SystemExit(f"sl_docs_gen: options without a meaning in the usage text: {undocumented}")
    out = ["Source: `apps/shadowleand/daemon_opts.c` (the option table `k_cli` and the usage "
           "text `shadowleand --help` prints). Every key is also a command-line option; the "
           "command line wins over the file.", ""]
    for sec in ("daemon", "input", "can", "output"):
        out += ["", f"**[{sec}]**", "", "| key | option | meaning |", "|---|---|---|"]
        for s, k, o, d in rows:
            if s == sec:
                out.append(f"| `{k}` | `{md(o)}` | {md(d)} |")
    return "\n".join(out).replace("\n\n\n", "\n\n")


# ----------------------------------------------------------------------------- footprint
def gen_footprint():
    rows = {}
    for line in rd("firmware/size_budget.txt").splitlines():
        f = line.split()
        if len(f) == 6 and not line.startswith("#"):
            rows[(f[0], f[1])] = [int(x) for x in f[2:]]
    cm = rd("tests/core/thumb/CMakeLists.txt")
    specs = re.findall(r'foreach\(spec ((?:"[^"]+"\s*)+)\)', cm)
    if len(specs) != 2:
        raise SystemExit("sl_docs_gen: expected the two foreach(spec ...) of the thumb tests")
    def budgets(s):
        return {p.split(";")[1]: int(p.split(";")[3]) for p in re.findall(r'"([^"]+)"', s)}
    sim, oxford = budgets(specs[0]), budgets(specs[1])
    stack = re.search(r"check_stack_cortex_\$\{tag\} COMMAND .*?--budget (\d+)\)", cm).group(1)
    cpus = [("cortex-m0", "m0", "Cortex-M0 (ARMv6-M)"), ("cortex-m4f", "m4f", "Cortex-M4F (FPU unused)")]
    kb = lambda b: f"{b / 1000:.1f} KB"
    out = ["Budgets, each held by a ctest: the measured value must stay at or below it. "
           "Sources: `firmware/size_budget.txt` (flash and RAM per object, `TOTAL` and `image` "
           "rows) and `tests/core/thumb/CMakeLists.txt` (instructions per azimuth, stack). "
           "Firmware configuration: `SL_CFG_MASK_BINS=160 SL_CFG_MASK_FRAMES_MAX=16`, "
           "`arm-none-eabi-gcc -Os -mgeneral-regs-only`.", "",
           "| budget | " + " | ".join(c[2] for c in cpus) + " | ctest |", "|---|---|---|---|"]
    def row(label, vals, test):
        out.append(f"| {label} | " + " | ".join(vals) + f" | `{test}` |")
    row("core code (`libsl_core.a` text, without board tables)",
        [kb(rows[(c, "TOTAL")][0]) for c, _, _ in cpus], "check_size_budget_cortex_*")
    row("core constants (rodata, without board tables)",
        [kb(rows[(c, "TOTAL")][1]) for c, _, _ in cpus], "check_size_budget_cortex_*")
    row("one board's tables (rodata)",
        [kb(rows[(c, "sl_board_*.c")][1]) for c, _, _ in cpus], "check_size_budget_cortex_*")
    row("example firmware image: flash (two boards, without the capture)",
        [kb(rows[(c, "image")][0]) for c, _, _ in cpus], "check_size_budget_cortex_*")
    row("example firmware image: RAM (.data + .bss)",
        [kb(rows[(c, "image")][3]) for c, _, _ in cpus], "check_size_budget_cortex_*")
    row("stack, worst case from `sl_pipeline_feed` (call graph)",
        [f"{int(stack):,} B" for _ in cpus], "check_stack_cortex_*")
    row("instructions per azimuth, simulated scene (three tracked poles, 1,460-byte segments)",
        [f"{sim[t]:,}" for _, t, _ in cpus], "thumb_run_*")
    row("instructions per azimuth, Oxford scans (no target, 64 KiB chunks)",
        [f"{oxford[t]:,}" for _, t, _ in cpus], "thumb_oxford_*")
    out += ["", "Per object (text / rodata budget, bytes):", "",
            "| object | " + " | ".join(c[2] for c in cpus) + " |", "|---|---|---|"]
    objs = [o for (c, o) in rows if c == "cortex-m0" and o not in ("TOTAL", "image")]
    for o in objs:
        out.append(f"| `{o}` | " + " | ".join(
            f"{rows[(c, o)][0]:,} / {rows[(c, o)][1]:,}" if (c, o) in rows else "-" for c, _, _ in cpus) + " |")
    return "\n".join(out)


# ------------------------------------------------------------------------------- results
def load_results():
    res = {}
    for p in sorted(glob.glob(os.path.join(ROOT, "docs", "results", "*.json"))):
        with open(p, encoding="utf-8") as fh:
            res[os.path.splitext(os.path.basename(p))[0]] = json.load(fh)
    return res


def f1(x, nd=2):
    return "-" if x is None else f"{x:.{nd}f}"


def gen_results_parts():
    """(headline for README and RESULTS, per-condition tables for RESULTS)"""
    import sl_results  # the result pages' table layout, beside this script
    return sl_results.render(load_results())


# ------------------------------------------------------------------------ debian changelog
def gen_debian():
    """packaging/debian/changelog from CHANGELOG.md: one entry per release, one bullet per line."""
    import datetime
    import textwrap
    text = rd("CHANGELOG.md")
    out = []
    for m in re.finditer(r"^## (\S+) \((\d{4}-\d{2}-\d{2})\)\n(.*?)(?=^## |\Z)", text, re.M | re.S):
        ver, date, body = m.group(1), m.group(2), m.group(3)
        items = [l[2:].strip() for l in body.splitlines() if l.startswith("- ")]
        when = datetime.datetime.strptime(date, "%Y-%m-%d").strftime("%a, %d %b %Y 00:00:00 +0000")
        out.append(f"shadowlean ({ver}) unstable; urgency=medium\n")
        for it in items:
            out.append(textwrap.fill(it, width=76, initial_indent="  * ", subsequent_indent="    "))
        out.append(f"\n -- The shadowlean authors <shadowlean@example.org>  {when}\n")
    return "\n".join(out)


def write_whole(page_rel, body, check, errors):
    path = os.path.join(ROOT, page_rel)
    try:
        with open(path, encoding="utf-8") as fh:
            old = fh.read()
    except OSError:
        old = None
    if old == body:
        return
    if check:
        errors.append(f"{page_rel} is not what CHANGELOG.md gives: run scripts/sl_docs_gen.py debian")
    else:
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(body)


# ----------------------------------------------------------------------------- plumbing
def replace(page_rel, part, body, check, errors):
    path = os.path.join(ROOT, page_rel)
    with open(path, encoding="utf-8") as fh:
        old = fh.read()
    pat = re.compile(r"(<!-- BEGIN GENERATED: sl_docs_gen %s -->\n)(?:.*?\n)?(<!-- END GENERATED: sl_docs_gen %s -->)"
                     % (re.escape(part), re.escape(part)), re.S)
    if not pat.search(old):
        errors.append(f"{page_rel}: no markers for part '{part}'")
        return
    new = pat.sub(lambda m: m.group(1) + body + "\n" + m.group(2), old)
    if new == old:
        return
    if check:
        errors.append(f"{page_rel}: part '{part}' is not what its source gives: run scripts/sl_docs_gen.py {part.split('-')[0]}")
    else:
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(new)


def main(argv):
    check = "--check" in argv
    parts = [a for a in argv[1:] if a != "--check"] or ["can", "config", "footprint", "results", "debian"]
    errors = []
    for part in parts:
        if part == "can":
            replace("docs/CAN_REFERENCE.md", "can", gen_can(), check, errors)
        elif part == "config":
            replace("docs/DAEMON.md", "config", gen_config(), check, errors)
        elif part == "footprint":
            replace("docs/INTEGRATION.md", "footprint", gen_footprint(), check, errors)
        elif part == "debian":
            write_whole("packaging/debian/changelog", gen_debian(), check, errors)
        elif part == "results":
            sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
            for page, name, body in gen_results_parts():
                replace(page, name, body, check, errors)
        else:
            print(f"sl_docs_gen: unknown part '{part}'", file=sys.stderr)
            return 2
    for e in errors:
        print("sl_docs_gen: " + e)
    if not errors:
        print("sl_docs_gen: " + ", ".join(parts) + (": up to date" if check else ": written"))
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
