"""`python3 -m slamrig run` runs a scenario like `slamrig run`: same report bits, same exit codes."""

import json
import os
import sys

from conftest import HERE, SOURCE, run

SHORT = ["--set", "duration_s=12", "--set", "world.drive.laps=1", "--set", "slam.pf.particles=10"]


def metrics_without_wall_clock(path):
    metrics = json.load(open(path))

    def strip(node):
        if isinstance(node, dict):
            return {k: strip(v) for k, v in node.items()
                    if "realtime_factor" not in k and "wall" not in k}
        if isinstance(node, list):
            return [strip(v) for v in node]
        return node
    return strip(metrics)


def test_module_run_equals_cli_run_bit_for_bit(cli, tmp_path):
    a, b = tmp_path / "cli", tmp_path / "module"
    out_cli = run([cli, "run", "office_loop", "--out", str(a), "--quiet"] + SHORT, cwd=SOURCE)
    out_py = run([sys.executable, "-m", "slamrig", "run", "office_loop", "--out", str(b),
                  "--quiet"] + SHORT, cwd=SOURCE)
    assert out_cli.returncode == out_py.returncode, (out_cli.stderr, out_py.stderr)
    for name in ("pf.tum", "dead_reckoning.tum", "truth.tum", "config.yaml", "pf_map.pgm"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    assert metrics_without_wall_clock(a / "metrics.json") == metrics_without_wall_clock(
        b / "metrics.json")
    assert out_py.stdout.strip().endswith("%s/report.html" % b)


def test_module_run_exit_codes(tmp_path):
    broken = os.path.join(HERE, "data", "broken_key.yaml")
    out = run([sys.executable, "-m", "slamrig", "run", broken, "--out", str(tmp_path / "x")])
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1 and "broken_key.yaml:6:" in out.stderr
    assert not (tmp_path / "x").exists()
    out = run([sys.executable, "-m", "slamrig", "run", "--no-such-flag"])
    assert out.returncode == 2
    # A failed expectation is exit code 3, as on the command line.
    out = run([sys.executable, "-m", "slamrig", "run", "office_loop", "--quiet", "--out",
               str(tmp_path / "y"), "--set", "expect.pf.ate_rmse_m_max=0.000001"] + SHORT,
              cwd=SOURCE)
    assert out.returncode == 3, out.stderr
    assert "FAIL" in out.stdout


def test_python_estimator_same_bits_from_the_cli_and_the_module(cli, tmp_path):
    # The CLI's embedded interpreter and this one run the example filter to the same bits.
    scenario = os.path.join(SOURCE, "python", "examples", "office_pf_python.yaml")
    short = ["--set", "duration_s=6", "--set", "slam.numpy_pf.particles=10", "--quiet"]
    a, b = tmp_path / "cli", tmp_path / "module"
    out_cli = run([cli, "run", scenario, "--out", str(a)] + short, cwd=str(tmp_path))
    out_py = run([sys.executable, "-m", "slamrig", "run", scenario, "--out", str(b)] + short,
                 cwd=str(tmp_path))
    assert out_cli.returncode == 0 and out_py.returncode == 0, (out_cli.stderr, out_py.stderr)
    for name in ("numpy_pf.tum", "numpy_pf_map.pgm", "pf.tum", "config.yaml"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    # config.yaml repeats the run, the estimator's options included.
    again = tmp_path / "again"
    out = run([cli, "run", str(a / "config.yaml"), "--out", str(again), "--quiet"],
              cwd=str(tmp_path))
    assert out.returncode == 0, out.stderr
    assert (again / "numpy_pf.tum").read_bytes() == (a / "numpy_pf.tum").read_bytes()


def test_a_failing_python_estimator_is_one_error_line_on_the_cli(cli, tmp_path):
    (tmp_path / "fails.py").write_text(
        "class Fails:\n"
        "    def add_scan(self, scan):\n"
        "        return 1 / 0\n")
    (tmp_path / "fails.yaml").write_text(
        "name: fails\n"
        "world: office\n"
        "robot: ece276a\n"
        "duration_s: 1\n"
        "slam:\n"
        "  bad: {algorithm: python, module: fails, class: Fails}\n")
    # Run from elsewhere: the module is found beside the scenario file.
    out = run([cli, "run", str(tmp_path / "fails.yaml"), "--out", str(tmp_path / "out")],
              cwd="/")
    assert out.returncode == 1
    errors = [line for line in out.stderr.splitlines() if "error" in line]
    assert errors == ["slamrig: error: fails.Fails.add_scan(): ZeroDivisionError: division by zero"]
    assert not (tmp_path / "out" / "report.html").exists()
