#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every source file of the project says its licence in its first lines (SPDX).

    spdx_check.py SOURCE_DIR [--fix]

Source files: C, C++, headers, assembly, linker scripts, Python, shell, awk, Lua, CMake
(CMakeLists.txt, *.cmake, *.in templates), YAML; found with `git ls-files` (or a walk of the
tree when it is not a git checkout), build/ and out/ excluded. Data, scenes, pictures,
generated logs, Markdown and the licence itself are not source. --fix inserts the line (after
a #! line), in the comment syntax of the file.
"""
import os
import subprocess
import sys

TAG = "SPDX-License-Identifier: MIT"
SLASH = (".c", ".h", ".cpp", ".hpp", ".c.in", ".h.in", ".supp")
BLOCK = (".S", ".S.in", ".ld")
HASH = (".py", ".sh", ".awk", ".cmake", ".cmake.in", ".yml", ".pc.in")
DASH = (".lua",)


def style(path):
    name = os.path.basename(path)
    if name == "CMakeLists.txt" or path == ".ci/run":
        return "#"
    for ends, st in ((SLASH, "//"), (BLOCK, "/*"), (HASH, "#"), (DASH, "--")):
        if name.endswith(ends):
            return st
    return None


def files(src):
    try:
        out = subprocess.run(["git", "-C", src, "ls-files"], capture_output=True, text=True, check=True)
        return [f for f in out.stdout.splitlines() if f]
    except (OSError, subprocess.CalledProcessError):
        res = []
        for root, dirs, names in os.walk(src):
            dirs[:] = [d for d in dirs if d not in (".git", "build", "out")]
            res += [os.path.relpath(os.path.join(root, n), src) for n in names]
        return res


def main(argv):
    src, fix = argv[0], "--fix" in argv[1:]
    missing = []
    checked = 0
    for rel in files(src):
        st = style(rel)
        if st is None:
            continue
        path = os.path.join(src, rel)
        try:
            with open(path, encoding="utf-8") as fh:
                lines = fh.readlines()
        except (OSError, UnicodeDecodeError):
            continue
        checked += 1
        if any(TAG in l for l in lines[:3]):
            continue
        if not fix:
            missing.append(rel)
            continue
        line = {"//": f"// {TAG}\n", "/*": f"/* {TAG} */\n", "#": f"# {TAG}\n", "--": f"-- {TAG}\n"}[st]
        at = 1 if lines and lines[0].startswith("#!") else 0
        lines.insert(at, line)
        with open(path, "w", encoding="utf-8") as fh:
            fh.writelines(lines)
    for m in missing:
        print(f"no SPDX line: {m}")
    print(f"spdx_check: {checked} source files, {len(missing)} without '{TAG}'")
    return 1 if missing or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
