#!/usr/bin/python3
"""The README's contract and the project's text, checked (plain script, no pytest).

    /usr/bin/python3 tests/docs/check_project_text.py [REPO_ROOT]

- README.md starts with one fenced block of exactly two commands: the first installs, builds and
  runs the main job (scripts/main-job.sh), the second installs, builds and runs every test; CI
  (.ci/run) runs the second one verbatim.
- README.md stays at most 120 lines.
- No project text counts its own history in numbered work periods (a work period's name followed by
  its number, in prose or inside a label, or "stop" or "wave" with a number): README, docs (data
  file names and contents too), src, tests, bench, tools, scripts and configs. Git history holds how the code was written; the text states facts, with a
  date or a commit where provenance matters.
Prints each check; exits 1 if any failed.
"""
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from checklist import Checks  # noqa: E402

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
MAX_README_LINES = 120
FOLDERS = ["docs", "src", "tests", "bench", "tools", "scripts", "configs", ".ci"]
# A numbered work period, in prose or inside a data label, or "stop"/"wave" and a number (not a
# name such as a test's directory "stop2"). The word is spelt in two pieces so that this file does
# not match itself.
PERIOD_WORD = "sess" + "ion"
WORK_PERIOD = re.compile(r"(?<![a-z])" + PERIOD_WORD + r"s?[ _#-]*\d|\b(stops?|waves?) +#?\d", re.IGNORECASE)
TEXT_SUFFIXES = (".md", ".txt", ".csv", ".json", ".toml", ".py", ".sh", ".cpp", ".hpp", ".inc", ".h", ".cu",
                 ".cmake", "CMakeLists.txt", "run")

check = Checks()


def fenced_blocks(lines):
    """(first line index, body lines) of each ``` block."""
    blocks, body, start = [], None, 0
    for k, line in enumerate(lines):
        if line.startswith("```"):
            if body is None:
                body, start = [], k
            else:
                blocks.append((start, body))
                body = None
        elif body is not None:
            body.append(line)
    return blocks


def check_readme():
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        lines = f.read().splitlines()
    check(len(lines) <= MAX_README_LINES, f"README.md has {len(lines)} lines (at most {MAX_README_LINES})")
    blocks = fenced_blocks(lines)
    first = [line.strip() for line in blocks[0][1] if line.strip()] if blocks else []
    check(len(first) == 2, f"README's first fenced block holds exactly two commands ({len(first)})")
    if len(first) != 2:
        return
    main_job, tests = first
    check(main_job.startswith("./scripts/install-deps.sh") and "scripts/main-job.sh" in main_job,
          "the first command installs and runs the main job (scripts/main-job.sh)")
    check(tests.startswith("./scripts/install-deps.sh") and "ctest" in tests,
          "the second command installs and runs every test (ctest)")
    with open(os.path.join(ROOT, ".ci", "run"), encoding="utf-8") as f:
        ci = f.read()
    check(tests in ci, "CI (.ci/run) runs the README's test command verbatim")


def project_files():
    yield os.path.join(ROOT, "README.md")
    for folder in FOLDERS:
        for base, dirs, files in os.walk(os.path.join(ROOT, folder)):
            dirs[:] = [d for d in dirs if d not in ("figures", "__pycache__")]
            for name in files:
                yield os.path.join(base, name)


def check_no_work_periods():
    me = os.path.abspath(__file__)
    hits = []
    for path in project_files():
        rel = os.path.relpath(path, ROOT)
        if WORK_PERIOD.search(os.path.basename(path)):
            hits.append(f"{rel} (file name)")
        if os.path.abspath(path) == me or not path.endswith(TEXT_SUFFIXES):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            for number, line in enumerate(f, 1):
                m = WORK_PERIOD.search(line)
                if m:
                    hits.append(f"{rel}:{number}: {m.group(0)!r}")
    for hit in hits[:20]:
        print("  numbered work period:", hit)
    check(not hits, f"no project text cites numbered work periods ({len(hits)} places)")


check_readme()
check_no_work_periods()
sys.exit(check.exit_code("project text"))
