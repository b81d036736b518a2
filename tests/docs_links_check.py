#!/usr/bin/env python3
"""Checks that every relative link in README.md and docs/**/*.md resolves: the file exists, and a
#fragment names a heading of that markdown file (GitHub's anchors). Also that nothing there
refers to ../shared except the data folder's default.

Usage: tests/docs_links_check.py [REPOSITORY]   (default: the folder above this script's)
Prints one line per broken link (file:line: link: why) and exits 1 when there is one.
"""
import os
import re
import sys

LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^\s*(```|~~~)")


def markdown_files(root):
    files = [os.path.join(root, "README.md")]
    for folder, _, names in os.walk(os.path.join(root, "docs")):
        files += [os.path.join(folder, n) for n in sorted(names) if n.endswith(".md")]
    return files


def prose_lines(path):
    """(line number, text) of the lines outside fenced code blocks."""
    inside = False
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            if FENCE.match(line):
                inside = not inside
                continue
            if not inside:
                yield number, line


_ANCHORS = {}


def anchors(path):
    """GitHub's anchors of a markdown file's headings (duplicates get -1, -2, ...)."""
    if path in _ANCHORS:
        return _ANCHORS[path]
    seen, result = {}, set()
    for _, line in prose_lines(path):
        match = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not match:
            continue
        slug = re.sub(r"[^\w\- ]", "", match.group(1).lower()).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        result.add(slug if count == 0 else f"{slug}-{count}")
    _ANCHORS[path] = result
    return result


def main(argv):
    root = os.path.abspath(argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    problems = []
    for path in markdown_files(root):
        shown = os.path.relpath(path, root)
        with open(path, encoding="utf-8") as f:
            for number, line in enumerate(f, 1):
                if "../shared" in line and "../shared/datasets" not in line:
                    problems.append(f"{shown}:{number}: refers to ../shared (only the data folder may)")
        for number, line in prose_lines(path):
            for match in LINK.finditer(line):
                target = match.group(1) or match.group(2)
                if re.match(r"^[a-z]+:", target):  # http:, https:, mailto:
                    continue
                file_part, _, fragment = target.partition("#")
                resolved = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
                if not os.path.exists(resolved):
                    problems.append(f"{shown}:{number}: {target}: no such file")
                elif fragment and resolved.endswith(".md") and fragment not in anchors(resolved):
                    problems.append(f"{shown}:{number}: {target}: no heading with that anchor")
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
