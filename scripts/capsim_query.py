"""The one way the Python scripts read a campaign database: `capsim query ... --format json`.

The SQL lives in capsim (campaign/store/); a script asks capsim and reads its JSON. The capsim binary is the one
given (the scripts' --capsim), else $CAPSIM_BUILD_DIR/bin/capsim, else build/bin/capsim of this source tree
(the build folder scripts/test and scripts/run use).
"""

import json
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class QueryError(Exception):
    """capsim is missing or refused the query: the message is one line (capsim's own where it gave one)."""


def default_capsim():
    """$CAPSIM_BUILD_DIR/bin/capsim, else build/bin/capsim of this source tree."""
    return os.path.join(os.environ.get("CAPSIM_BUILD_DIR") or os.path.join(ROOT, "build"), "bin", "capsim")


def query(capsim, *args):
    """The rows of `capsim query ARGS --format json` (a list of dicts)."""
    exe = capsim or default_capsim()
    if not os.access(exe, os.X_OK):
        raise QueryError(f"{exe}: no capsim executable (build first, or give --capsim EXE)")
    cmd = [exe, "query", *map(str, args), "--format", "json"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        lines = r.stderr.strip().splitlines()
        raise QueryError(lines[-1] if lines else f"capsim query {args[0]} failed (exit {r.returncode})")
    try:
        rows = json.loads(r.stdout)
    except ValueError as e:
        raise QueryError(f"capsim query {args[0]}: output is not JSON ({e})")
    if not isinstance(rows, list):
        raise QueryError(f"capsim query {args[0]}: expected a JSON list")
    return rows
