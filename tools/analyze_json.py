"""`sphdisk analyze --json` of one snapshot, read back as a dict (docs/formats.md, "analyze output"),
so that the reports quote the analysis's own figures instead of a second implementation of them."""
import json
import os
import subprocess
import tempfile


def analysis(sphdisk, snapshot, bins=None):
    """The analysis of one snapshot; bins: the radial bins (shells) asked for, or analyze's default."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "analysis.json")
        command = [sphdisk, "analyze", snapshot, "--json", path] + (["--bins", str(bins)] if bins else [])
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        with open(path) as f:
            return json.load(f)
