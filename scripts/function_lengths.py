#!/usr/bin/env python3
"""Lists the C++ functions longer than a limit, from universal-ctags' `end:` field.

    scripts/function_lengths.py [--max-lines N] [--root DIR] [--fail] [DIR ...]

A function longer than the limit for a good reason (a SIMD kernel, a generated table) carries
the marker `// function-length: exception (the reason)` on one of the comment lines directly
above its first line; it is listed as an exception and never fails the check. With --fail the
exit status is 1 when any function without the marker is over the limit. Tests (`*_test.cc`)
are scanned like any other file.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys

DEFAULT_DIRS = ["apps", "bench", "fuzz", "python", "scenarios", "sim", "slam", "tests"]
# The reason may run on over the following comment lines; its first line is enough here.
MARKER = re.compile(r"//\s*function-length:\s*exception\s*\((.+?)\)?\s*$")


def Functions(root, dirs):
    """(path, start line, end line, qualified name) of every function definition under dirs."""
    ctags = shutil.which("ctags")
    if ctags is None:
        print("function_lengths: universal-ctags not found (scripts/install_deps.sh installs it)",
              file=sys.stderr)
        sys.exit(77)  # CTest's skip code
    present = [d for d in dirs if os.path.isdir(os.path.join(root, d))]
    out = subprocess.run(
        [ctags, "--output-format=json", "--fields=+ne", "--languages=C++", "--kinds-C++=f",
         "-R", "-f", "-"] + present,
        cwd=root, check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        tag = json.loads(line)
        if tag.get("_type") != "tag" or "end" not in tag:
            continue
        scope = tag.get("scope", "")
        name = f"{scope}::{tag['name']}" if scope else tag["name"]
        yield tag["path"], tag["line"], tag["end"], name


def ExceptionReason(lines, start):
    """The reason of a marker in the comment block directly above line `start` (1-based)."""
    i = start - 2
    while i >= 0 and lines[i].strip().startswith("//"):
        m = MARKER.search(lines[i])
        if m:
            return m.group(1)
        i -= 1
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dirs", nargs="*", default=DEFAULT_DIRS)
    parser.add_argument("--max-lines", type=int, default=120)
    parser.add_argument("--root", default=os.path.join(os.path.dirname(__file__), ".."))
    parser.add_argument("--fail", action="store_true",
                        help="exit 1 when a function without the marker is over the limit")
    args = parser.parse_args()

    cache = {}
    offenders, exceptions = [], []
    for path, start, end, name in Functions(args.root, args.dirs):
        length = end - start + 1
        if length <= args.max_lines:
            continue
        if path not in cache:
            with open(os.path.join(args.root, path), encoding="utf-8", errors="replace") as f:
                cache[path] = f.read().splitlines()
        reason = ExceptionReason(cache[path], start)
        row = f"{length:5d}  {path}:{start}  {name}"
        (exceptions if reason else offenders).append((length, row, reason))

    for _, row, _ in sorted(offenders, reverse=True):
        print(row)
    for _, row, reason in sorted(exceptions, reverse=True):
        print(f"{row}  (exception: {reason})")
    print(f"function_lengths: {len(offenders)} function(s) over {args.max_lines} lines, "
          f"{len(exceptions)} documented exception(s)")
    return 1 if args.fail and offenders else 0


if __name__ == "__main__":
    sys.exit(main())
