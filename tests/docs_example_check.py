#!/usr/bin/env python3
"""Keeps docs/adding-an-estimator.md true as the code changes.

1. Every code block of the page that follows a `<!-- file: PATH -->` line equals that file of
   docs/examples/ byte for byte (the page shows what is shipped).
2. docs/examples/register.patch (the one entry in slam/pipeline/algorithms.cc and the test's line
   in slam/pipeline/CMakeLists.txt) still applies to the tree (`patch --dry-run`).
3. With a build folder: the example estimator and its test still compile against today's
   headers (`-fsyntax-only` with the flags compile_commands.json gives the pipeline's files, or
   its unity batches), and
   the estimator still fits the algorithm table (AlgorithmOptionsFor is instantiated).

Usage: tests/docs_example_check.py REPOSITORY [BUILD_DIR]
Prints one line per problem and exits 1 when there is one. Nothing in the tree is modified.
"""
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

PAGE = "docs/adding-an-estimator.md"
EXAMPLES = "docs/examples"


def check_blocks(root):
    problems, checked = [], 0
    lines = open(os.path.join(root, PAGE), encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        marker = re.match(r"^<!-- file: (\S+) -->$", lines[i])
        if not marker:
            i += 1
            continue
        path = marker.group(1)
        if i + 1 >= len(lines) or not lines[i + 1].startswith("```"):
            problems.append(f"{PAGE}:{i + 1}: {path}: no code block after the marker")
            i += 1
            continue
        end = i + 2
        while end < len(lines) and not lines[end].startswith("```"):
            end += 1
        block = "\n".join(lines[i + 2 : end]) + "\n"
        full = os.path.join(root, path)
        if not os.path.isfile(full):
            problems.append(f"{PAGE}:{i + 1}: {path}: no such file")
        elif open(full, encoding="utf-8").read() != block:
            problems.append(f"{PAGE}:{i + 3}: the block differs from {path}")
        checked += 1
        i = end + 1
    if checked == 0:
        problems.append(f"{PAGE}: no `<!-- file: ... -->` code block found")
    return problems


def check_patch(root):
    patch = os.path.join(root, EXAMPLES, "register.patch")
    if shutil.which("patch"):
        command = ["patch", "--dry-run", "--batch", "-p1", "-d", root, "-i", patch]
    elif shutil.which("git"):
        command = ["git", "-C", root, "apply", "--check", patch]
    else:
        return ["neither patch nor git is installed: cannot check register.patch"]
    run = subprocess.run(command, capture_output=True, text=True)
    if run.returncode != 0:
        return [f"{EXAMPLES}/register.patch no longer applies to the tree: "
                + " ".join((run.stdout + run.stderr).split())[:300]]
    return []


def command_for(commands, patterns):
    """The compile command of the first entry whose file ends with a match of one of `patterns`
    (regular expressions), tried in order."""
    for pattern in patterns:
        for entry in commands:
            if re.search("(^|/)" + pattern + "$", entry["file"]):
                if "arguments" in entry:
                    return entry["arguments"], entry["directory"]
                return shlex.split(entry["command"]), entry["directory"]
    return None, None


def syntax_check(arguments, directory, source, include_first):
    """The compile command of another file of the same target, on `source`, syntax only."""
    out = []
    skip = False
    for a in arguments:
        if skip:
            skip = False
            continue
        if a in ("-o", "-c", "-MF", "-MT", "-MQ"):
            skip = a != "-c"
            continue
        if a.endswith((".cc", ".cpp", ".cxx")) or a in ("-MD", "-MMD"):
            continue
        out.append(a)
    out = [out[0], f"-I{include_first}"] + out[1:] + ["-fsyntax-only", source]
    return subprocess.run(out, cwd=directory, capture_output=True, text=True)


def check_compiles(root, build):
    database = os.path.join(build, "compile_commands.json")
    if not os.path.isfile(database):
        return [f"{database}: missing (configure with CMAKE_EXPORT_COMPILE_COMMANDS)"]
    commands = json.load(open(database))
    problems = []
    with tempfile.TemporaryDirectory() as scratch:
        # The example as it would sit in the tree, found before anything else.
        target = os.path.join(scratch, "slam", "pipeline")
        os.makedirs(target)
        shutil.copy(os.path.join(root, EXAMPLES, "scan_to_scan_estimator.h"), target)
        unit = os.path.join(scratch, "registration.cc")
        with open(unit, "w") as f:
            f.write('#include "slam/pipeline/scan_to_scan_estimator.h"\n'
                    "template class slamrig::slam::AlgorithmOptionsFor<"
                    "slamrig::slam::ScanToScanOptions, slamrig::slam::ScanToScanEstimator>;\n")
        # The library's flags: algorithms.cc's, or in a unity build (SLAMRIG_UNITY_BUILD) a
        # batch's, which compiles it among others with the same flags.
        library = ("slam/pipeline/algorithms.cc",
                   [re.escape("slam/pipeline/algorithms.cc"),
                    r"slam/pipeline/CMakeFiles/slamrig_pipeline\.dir/Unity/unity_\d+_cxx\.cxx"])
        test = ("slam/pipeline/rbpf_estimator_test.cc",
                [re.escape("slam/pipeline/rbpf_estimator_test.cc")])
        for source, (model, patterns) in (
                (unit, library),
                (os.path.join(root, EXAMPLES, "scan_to_scan_estimator_test.cc"), test)):
            arguments, directory = command_for(commands, patterns)
            if arguments is None:
                problems.append(f"{database}: no entry for {model}")
                continue
            run = syntax_check(arguments, directory, source, scratch)
            if run.returncode != 0:
                first = [l for l in run.stderr.splitlines() if "error" in l][:3]
                problems.append(f"{os.path.basename(source)} does not compile: " + " | ".join(first))
    return problems


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    root = os.path.abspath(argv[1])
    problems = check_blocks(root) + check_patch(root)
    if len(argv) > 2:
        problems += check_compiles(root, os.path.abspath(argv[2]))
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
