#!/usr/bin/env python3
"""The layers of src/ include only the layers below them (docs/architecture.md, "Layers"); the
libraries of CMakeLists.txt link the same way. Exit 1 and name every include that breaks the rule.

    engine  core, contact, geometry   may include: engine
    files   io/input_file             may include: core/errors.hpp (the error types every layer throws)
    lab     lab                       may include: engine, files
    io      io (the rest)             may include: engine, files, lab, io
    app     cli                       may include: everything
"""
import os
import re
import sys

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
ENGINE = {"core", "contact", "geometry"}
BASE = {"core/errors.hpp"}  # header-only error types, below every layer


def layer(path):
    """The layer of a file or include path relative to src/ ("core/x.hpp", "io/input_file.cpp")."""
    top = path.split("/", 1)[0]
    if top in ENGINE:
        return "engine"
    if path.startswith("io/input_file."):
        return "files"
    return {"lab": "lab", "io": "io", "cli": "app"}.get(top)


ALLOWED = {
    "engine": {"engine"},
    "files": {"files"},
    "lab": {"engine", "files", "lab"},
    "io": {"engine", "files", "lab", "io"},
    "app": {"engine", "files", "lab", "io", "app"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def violations():
    out = []
    for root, _, files in os.walk(SRC):
        for name in files:
            if not name.endswith((".cpp", ".hpp", ".in")):
                continue
            rel = os.path.relpath(os.path.join(root, name), SRC).replace(os.sep, "/")
            mine = layer(rel)
            if mine is None:
                out.append(f"src/{rel}: in no layer")
                continue
            with open(os.path.join(root, name), encoding="utf-8") as f:
                for inc in INCLUDE.findall(f.read()):
                    theirs = None if inc in BASE else layer(inc)
                    if theirs is not None and theirs not in ALLOWED[mine]:
                        out.append(f"src/{rel} ({mine}) includes {inc} ({theirs})")
    return out


if __name__ == "__main__":
    bad = violations()
    for line in bad:
        print(line)
    print(f"check_layers: {len(bad)} include(s) against the layering" if bad else "check_layers: layers hold")
    sys.exit(1 if bad else 0)
