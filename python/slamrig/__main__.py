"""`python3 -m slamrig run SCENARIO ...`: runs a scenario as `slamrig run` does (same flags, same
report folder, same exit codes: 0 pass, 3 an expectation failed, 2 a bad command line or
scenario, 1 other errors), with Python estimators imported into this interpreter. Other
commands are handed to the `slamrig` binary of this build."""

import argparse
import os
import shutil
import sys
import time

EXIT_DATA_ERROR = 1
EXIT_USAGE = 2
EXIT_EXPECTATIONS_FAILED = 3


def _run(argv):
    import slamrig

    parser = argparse.ArgumentParser(
        prog="python3 -m slamrig run",
        description="Simulates the scenario's world and robot (or reads its log), runs each of "
                    "its SLAM configurations, scores them, writes a report folder and prints "
                    "the table of expectations. Exit code 3 when an expectation fails.")
    parser.add_argument("scenario", nargs="?", default="office_loop",
                        help="scenario file or shipped name [default: office_loop]")
    parser.add_argument("--out", help="report folder [default: out/<scenario name>]")
    parser.add_argument("--seed", type=int, help="replace the scenario's seed")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a scenario, world. or robot. key")
    parser.add_argument("--view", action="store_true", help="show the run live in a window")
    parser.add_argument("--quiet", action="store_true", help="print only the verdict line")
    args = parser.parse_args(argv)
    if args.seed is not None and args.seed < 0:
        parser.error("--seed: expected a non-negative integer")

    spec = slamrig.load_scenario(args.scenario, args.set, args.seed)
    out_dir = args.out or "out/" + spec.name
    tty = sys.stderr.isatty()

    def progress(t, duration):
        if tty:
            sys.stderr.write("\r  simulated %.0f s (at most %.0f)" % (t, duration))

    if not args.quiet:
        print("%s: %s" % (spec.name, spec.description), flush=True)
    start = time.perf_counter()
    result = slamrig.run_scenario(spec, view=args.view,
                                  progress=None if args.quiet else progress)
    wall_s = time.perf_counter() - start
    if not args.quiet and tty:
        sys.stderr.write("\n")
    result.write_report(out_dir)
    if not args.quiet:
        line = "  %.1f s simulated in %.1f s (%.0fx real time), %d scans" % (
            result.sim_time_s, wall_s, result.sim_time_s / max(wall_s, 1e-9), result.scans)
        if result.scans_blacked_out:
            line += " (%d blacked out)" % result.scans_blacked_out
        print(line)
        nan = float("nan")
        for name, c in result.configs.items():
            m = c.metrics
            print("  %-16s ATE RMSE %.3f m, max %.3f m, final %.3f m, map F1 %.3f" % (
                name, m.get("ate_rmse_m", nan), m.get("ate_max_m", nan),
                m.get("final_error_m", nan), m.get("map_f1", nan)))
        sys.stdout.write(result.expectation_table())
    print("%s: %s -> %s/report.html" % (spec.name, "PASS" if result.passed else "FAIL", out_dir))
    return 0 if result.passed else EXIT_EXPECTATIONS_FAILED


def _cli():
    try:
        from . import _paths
        if os.access(_paths.CLI, os.X_OK):
            return _paths.CLI
    except ImportError:
        pass
    return shutil.which("slamrig")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "run":
        try:
            return _run(argv[1:])
        except Exception as e:  # one line, as the command line prints it
            import slamrig
            sys.stdout.flush()
            message = str(e).replace("\n", " ")
            if isinstance(e, slamrig.ConfigError):
                print("slamrig: error: %s" % message, file=sys.stderr)
                return EXIT_USAGE
            if not isinstance(e, (RuntimeError, ValueError, OSError, slamrig.ParseError)):
                message = "%s: %s" % (type(e).__name__, message)
            print("slamrig: error: %s" % message, file=sys.stderr)
            return EXIT_DATA_ERROR
    cli = _cli()
    if cli is None:
        print("slamrig: error: only `run` is built into the module, and no slamrig binary was "
              "found for %s" % (argv[0] if argv else "--help"), file=sys.stderr)
        return EXIT_USAGE
    os.execv(cli, [cli] + argv)


if __name__ == "__main__":
    sys.exit(main())
