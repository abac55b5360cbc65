#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The documentation rules of CONTRIBUTING.md, checked over every tracked file.

    sl_docs_lint.py [SOURCE_DIR]          (default: this script's repository)

Files: `git ls-files` in SOURCE_DIR (without git: every file under it but .git and build/).
Rules, one message per hit as FILE:LINE: RULE: text:
  chronology   development history in shipped text: a numbered session or round (the
               word, a space, a number; a TCP or pcap session is not one), or "this",
               "last", "previous", "earlier", "next" or "development" before either word
  shared-path  a path into a folder beside the checkout (dot-dot, then "shared", then a slash):
               a clone does not have it
  left-out     the experiment-log phrase "tried" + "and left out"
  dead-link    a relative markdown link (or image) to a file or folder that does not exist
  doc-map      a docs/ file that README.md does not link (directly or through a linked
               folder; pictures count as linked when a page shows them)
Exit status: 0 clean, 1 hits, 2 usage."""
import os
import re
import subprocess
import sys

# Built from pieces so that this file does not match its own rules.
CHRONO = re.compile(r"(?i)(?<!tcp )(?<!pcap )(?<!new tcp )\bsessions? [0-9]+\b|\brounds? [0-9]+\b"
                    r"|\b(?:this|last|previous|earlier|next|development) (?:session|round)\b")
SHARED = re.compile(re.escape(".." + "/" + "shared" + "/"))
LEFT_OUT = re.compile(r"(?i)tried " + "and left out")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def tracked(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], check=True,
                             capture_output=True).stdout.decode()
        files = [f for f in out.split("\0") if f]
        if files:
            return files
    except (OSError, subprocess.CalledProcessError):
        pass
    files = []
    for d, dirs, names in os.walk(root):
        dirs[:] = [x for x in dirs if x not in (".git", "build")]
        files += [os.path.relpath(os.path.join(d, n), root) for n in names]
    return sorted(files)


def text_of(path):
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError:
        return None
    if b"\0" in data:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def links(text):
    """Relative link targets of a markdown page, outside code spans and blocks."""
    out = []
    fence = False
    for n, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fence = not fence
            continue
        if fence:
            continue
        line = re.sub(r"`[^`]*`", "", line)
        for m in LINK.finditer(line):
            t = m.group(1)
            if re.match(r"[a-z][a-z0-9+.-]*:", t) or t.startswith("#"):
                continue
            out.append((n, t.split("#")[0]))
    return out


def main(argv):
    if len(argv) > 2:
        print(__doc__, file=sys.stderr)
        return 2
    root = os.path.abspath(argv[1] if len(argv) == 2 else
                           os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    files = tracked(root)
    present = set(files)
    dirs = set()
    for f in files:
        p = os.path.dirname(f)
        while p:
            dirs.add(p)
            p = os.path.dirname(p)
    hits = []
    shown = set()      # files some page links or shows
    readme_links = set()
    for f in files:
        text = text_of(os.path.join(root, f))
        if text is None:
            continue
        for n, line in enumerate(text.splitlines(), 1):
            for rule, rx in (("chronology", CHRONO), ("shared-path", SHARED), ("left-out", LEFT_OUT)):
                m = rx.search(line)
                if m:
                    hits.append(f"{f}:{n}: {rule}: {line.strip()[:160]}")
        if f.endswith(".md"):
            for n, t in links(text):
                if not t:
                    continue
                target = os.path.normpath(os.path.join(os.path.dirname(f), t))
                if target not in present and target not in dirs and not os.path.exists(os.path.join(root, target)):
                    hits.append(f"{f}:{n}: dead-link: {t}")
                shown.add(target)
                if f == "README.md":
                    readme_links.add(target)
    for f in files:
        if not f.startswith("docs/"):
            continue
        covered = f in readme_links or any(f.startswith(d.rstrip("/") + "/") for d in readme_links)
        if not covered and f.startswith("docs/img/") and f in shown:
            covered = True
        if not covered:
            hits.append(f"README.md: doc-map: {f} is not linked from the documentation map")
    for h in hits:
        print(h)
    print(f"sl_docs_lint: {len(files)} files, {len(hits)} hit(s)")
    return 1 if hits else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
