#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Write the field tables of docs/JSON_OUTPUTS.md from the JSON Schemas in docs/schema (the
one source of every field's meaning and unit).

    sl_schema_doc.py [--check] [DOCS_DIR]     (default: docs/ beside this script's parent)

Replaces the text between "<!-- BEGIN GENERATED: <file>.schema.json -->" and
"<!-- END GENERATED -->" with one row per field (path, JSON type, description).
--check: write nothing; exit 1 when the page is not what the schemas give."""
import json
import os
import re
import sys


def resolve(root, s):
    while isinstance(s, dict) and "$ref" in s:
        ref = s["$ref"]
        extra = {k: v for k, v in s.items() if k != "$ref"}
        target = root
        for part in ref.lstrip("#/").split("/"):
            target = target[part]
        s = dict(target, **extra)
    if isinstance(s, dict) and "allOf" in s:
        merged = {k: v for k, v in s.items() if k != "allOf"}
        for sub in s["allOf"]:
            sub = resolve(root, sub)
            for k, v in sub.items():
                merged.setdefault(k, v)
        s = merged
    return s


def type_of(root, s):
    s = resolve(root, s)
    if "const" in s:
        return f"`{json.dumps(s['const'])}`"
    if s.get("type") == "string" and re.fullmatch(r"\^[\w./-]+\$", s.get("pattern", "")):
        return f"`{json.dumps(s['pattern'][1:-1])}`"
    if "enum" in s:
        return " \\| ".join(f"`{json.dumps(e)}`" for e in s["enum"])
    t = s.get("type", "")
    t = " or ".join(t) if isinstance(t, list) else t
    if t == "array" and "items" in s:
        inner = resolve(root, s["items"])
        it = inner.get("type", "object")
        it = " or ".join(it) if isinstance(it, list) else it
        n = ""
        if s.get("minItems") is not None and s.get("minItems") == s.get("maxItems"):
            n = f"{s['minItems']} x "
        return f"array of {n}{it}"
    rng = ""
    if "minimum" in s and "maximum" in s:
        rng = f" {s['minimum']}..{s['maximum']}"
    elif "minimum" in s:
        rng = f" >= {s['minimum']}"
    return (t or "any") + rng


def rows(root, s, path, required, out):
    s = resolve(root, s)
    desc = s.get("description", "")
    if path:
        req = "" if required else " (optional)"
        out.append(f"| `{path}` | {type_of(root, s)} | {desc}{req} |")
    props = s.get("properties")
    if props:
        req = set(s.get("required", []))
        for k, v in props.items():
            rows(root, v, f"{path}.{k}" if path else k, k in req, out)
    items = s.get("items")
    if isinstance(items, dict):  # arrays of objects: their fields as path[].field
        it = resolve(root, items)
        req = set(it.get("required", []))
        for k, v in it.get("properties", {}).items():
            rows(root, v, f"{path}[].{k}", k in req, out)


def tables(schema):
    out = []
    variants = schema.get("oneOf")
    for v in (variants if variants else [schema]):
        r = resolve(schema, v)
        title = r.get("description") if variants else None
        if variants:
            kind = r["properties"].get("type", r["properties"].get("experiment", {})).get("const", "")
            out.append(f"\n**{kind}**: {title}\n")
        out.append("| field | type | meaning |")
        out.append("|---|---|---|")
        rows(schema, r, "", True, out)
    return "\n".join(out).strip("\n")


def render(docs_dir, text):
    def sub(m):
        name = m.group(1)
        with open(os.path.join(docs_dir, "schema", name)) as fh:
            schema = json.load(fh)
        return f"<!-- BEGIN GENERATED: {name} -->\n{tables(schema)}\n<!-- END GENERATED -->"
    return re.sub(r"<!-- BEGIN GENERATED: (\S+) -->.*?<!-- END GENERATED -->", sub, text, flags=re.S)


def main(argv):
    check = "--check" in argv
    rest = [a for a in argv[1:] if a != "--check"]
    docs = rest[0] if rest else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs")
    page = os.path.join(docs, "JSON_OUTPUTS.md")
    with open(page) as fh:
        old = fh.read()
    new = render(docs, old)
    if check:
        if new != old:
            print(f"sl_schema_doc: {page} is not what docs/schema gives: run scripts/sl_schema_doc.py")
            return 1
        print(f"sl_schema_doc: {page} matches the schemas")
        return 0
    if new != old:
        with open(page, "w") as fh:
            fh.write(new)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
