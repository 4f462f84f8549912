#!/usr/bin/env python3
"""Includes go downwards only (docs/design.md, "Layers and who includes whom").

The layers and what each may use come from src/CMakeLists.txt (its sphdisk_layer(NAME ... DEPENDS
sphdisk_X ...) lines, taken transitively), so the build and this check cannot disagree. Every
`#include "folder/..."` in src/FOLDER/ must name FOLDER or a layer below it; <mpi.h> and <omp.h> only
in src/parallel/ (threads and MPI stay out of the physics); every source folder must be a layer.
Prints each violation as file:line and exits 1 if there is one.
Usage: check_includes.py SRC_DIR
"""
import pathlib
import re
import sys

src = pathlib.Path(sys.argv[1])
cmake = (src / "CMakeLists.txt").read_text()
direct = {}
for m in re.finditer(r"sphdisk_layer\((\w+)(.*?)\)\n", cmake, re.S):
    deps = re.search(r"DEPENDS(.*)", m.group(2), re.S)
    direct[m.group(1)] = set(re.findall(r"sphdisk_(\w+)", deps.group(1))) if deps else set()


def below(layer, seen=None):
    seen = set() if seen is None else seen
    for d in direct[layer]:
        if d not in seen:
            seen.add(d)
            below(d, seen)
    return seen


problems = []
folders = sorted(p.name for p in src.iterdir() if p.is_dir())
for folder in folders:
    if folder not in direct:
        problems.append(f"src/{folder}/: not a layer of src/CMakeLists.txt (sphdisk_layer)")
        continue
    allowed = below(folder) | {folder}
    for path in sorted((src / folder).iterdir()):
        if path.suffix not in (".hpp", ".cpp", ".inc"):
            continue
        for n, line in enumerate(path.read_text().splitlines(), 1):
            m = re.match(r'\s*#\s*include\s+"(\w+)/', line)
            if m and m.group(1) not in allowed:
                problems.append(f"src/{folder}/{path.name}:{n}: includes {m.group(1)}/, which is above {folder}/ "
                                f"(it may include {', '.join(sorted(allowed))})")
            if re.match(r"\s*#\s*include\s+<(mpi|omp)\.h>", line) and folder != "parallel":
                problems.append(f"src/{folder}/{path.name}:{n}: threads and MPI belong in src/parallel/")
for p in problems:
    print(p)
print(f"include layers: {len(direct)} layers, {len(problems)} violations")
sys.exit(1 if problems else 0)
