#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Validate a tool's real JSON output against its schema in docs/schema (Debian's
python3-jsonschema, Draft 2020-12).

    validate_json.py SCHEMA.json FILE [--lines] [--expect-schema NAME/MAJOR] [--require PATH]...

--lines: JSON Lines (targets.jsonl): every line validated; the first must carry "schema".
Checks, each a failure:
  - the output validates against the schema as published (extra keys allowed: consumers
    ignore keys they do not know);
  - strict: every key the tool writes is described in the schema (the schema, and the page
    generated from it, documents every field);
  - the "schema" key equals --expect-schema;
  - the schema rejects the output with its "schema" key removed, and with the major
    version bumped (the validation can fail);
  - --require a.b.c: that path exists and is non-empty somewhere in the output
    (e.g. rotation.targets: some rotation line has targets).
"""
import copy
import json
import sys

import jsonschema


def strict(schema):
    """The schema with additionalProperties false on every object that lists properties."""
    s = copy.deepcopy(schema)

    def walk(x):
        if isinstance(x, dict):
            if "properties" in x and "additionalProperties" not in x:
                x["additionalProperties"] = False
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)
    walk(s)
    return s


def errors_of(validator, doc):
    return sorted(validator.iter_errors(doc), key=lambda e: list(e.absolute_path))


def found(doc, path):
    """True when path (keys; a key "type=value" selects lines) leads to a non-empty value."""
    head, *rest = path
    if isinstance(doc, list):
        return any(found(d, path) for d in doc)
    if not isinstance(doc, dict):
        return False
    if "=" in head:
        k, v = head.split("=", 1)
        return doc.get(k) == v and (not rest or found(doc, rest))
    if head not in doc:
        return False
    v = doc[head]
    if not rest:
        return v not in (None, [], {}, "")
    return found(v, rest)


def main(argv):
    args = argv[1:]
    if len(args) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    schema_path, path = args[0], args[1]
    lines = "--lines" in args
    expect = args[args.index("--expect-schema") + 1] if "--expect-schema" in args else None
    requires = [args[i + 1] for i, a in enumerate(args) if a == "--require"]
    with open(schema_path) as fh:
        schema = json.load(fh)
    jsonschema.Draft202012Validator.check_schema(schema)
    loose = jsonschema.Draft202012Validator(schema)
    tight = jsonschema.Draft202012Validator(strict(schema))
    with open(path) as fh:
        text = fh.read()
    docs = [json.loads(x) for x in text.splitlines() if x.strip()] if lines else [json.loads(text)]
    if not docs:
        print(f"FAIL: {path}: no JSON")
        return 1
    bad = 0
    for n, d in enumerate(docs, 1):
        for v, what in ((loose, "schema"), (tight, "undocumented key")):
            errs = errors_of(v, d)
            if errs:
                bad += 1
                e = errs[0]
                where = "/".join(str(p) for p in e.absolute_path)
                print(f"FAIL: {path}:{n}: {what}: at '{where}': {e.message[:300]}")
                break
    first = docs[0]
    if expect is not None and first.get("schema") != expect:
        print(f"FAIL: {path}: schema key {first.get('schema')!r}, expected {expect!r}")
        bad += 1
    # The schema must be able to fail on this very output.
    if "schema" in first:
        no_key = {k: v for k, v in first.items() if k != "schema"}
        name, _, major = str(first["schema"]).partition("/")
        bumped = dict(first, schema=f"{name}/{int(major or 0) + 1}")
        for mutant, what in ((no_key, "without its schema key"), (bumped, "with the next major version")):
            if loose.is_valid(mutant):
                print(f"FAIL: {schema_path} accepts the output {what}")
                bad += 1
    for r in requires:
        if not found(docs, r.split(".")):
            print(f"FAIL: {path}: nothing at {r}")
            bad += 1
    print(f"validate_json: {path}: {len(docs)} object(s) against {schema_path}: "
          f"{'ok' if not bad else f'{bad} failure(s)'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
