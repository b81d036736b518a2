import os
import shutil
import subprocess
import sys

import pytest

import slamrig

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
EXAMPLES = os.path.join(SOURCE, "python", "examples")
sys.path.insert(0, EXAMPLES)


def _cli():
    cli = os.environ.get("SLAMRIG_CLI")
    if not cli:
        from slamrig import _paths
        cli = _paths.CLI
    return os.path.abspath(cli)


@pytest.fixture(scope="session")
def cli():
    path = _cli()
    if not os.access(path, os.X_OK):
        pytest.fail("no slamrig binary at %s (build the slamrig target)" % path)
    return path


@pytest.fixture(scope="session")
def intel():
    path = "carmen_corrected/intel-corrected.log.gz"
    if not os.path.exists(os.path.join(slamrig.data_dir(), path)):
        message = "intel-corrected log not in %s" % slamrig.data_dir()
        if os.environ.get("CI") == "true":
            pytest.fail(message)  # as the C++ tests: a missing dataset is a failure in CI
        pytest.skip(message)
    return path


def run(args, **kwargs):
    env = dict(os.environ)
    return subprocess.run(args, capture_output=True, text=True, env=env, **kwargs)
