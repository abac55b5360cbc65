# SPDX-License-Identifier: MIT
"""The package version: the project's CMake version. `cmake --install` writes this file
with the version baked in; from a source checkout it is read from the top CMakeLists.txt."""
import os
import re


def _from_source():
    top = os.path.join(os.path.dirname(__file__), "..", "..", "CMakeLists.txt")
    try:
        with open(top, encoding="utf-8") as fh:
            m = re.search(r"project\(\s*shadowlean\s+VERSION\s+([0-9.]+)", fh.read())
    except OSError:
        return "0+unknown"
    return m.group(1) if m else "0+unknown"


__version__ = _from_source()
