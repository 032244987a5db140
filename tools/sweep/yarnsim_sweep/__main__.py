"""yarnsim-sweep SWEEP.toml [-o OUT] [--scheduler tcp://HOST:8786] [--workers N] [--resume]"""
import argparse
import sys

from .spec import Sweep, SweepError


def main(argv=None):
    ap = argparse.ArgumentParser(prog="yarnsim-sweep", description="Run a parameter sweep of an FMU on Dask (see the README, 'Parameter sweeps on Dask').")
    ap.add_argument("sweep", help="the sweep file (TOML)")
    ap.add_argument("-o", "--out", help="output folder (default: out/<sweep file name>)")
    ap.add_argument("--fmu", help="use this FMU instead of the sweep file's `fmu`")
    ap.add_argument("--scheduler", help="address of an existing Dask scheduler, e.g. tcp://HOST:8786 (default: an embedded LocalCluster)")
    ap.add_argument("--workers", type=int, help="workers of the embedded LocalCluster (default: one per core)")
    ap.add_argument("--connect-timeout", type=float, default=10.0, help="seconds to wait for --scheduler (default 10)")
    ap.add_argument("--resume", action="store_true", help="skip the points already in OUT/results.parquet")
    ap.add_argument("--no-plot", action="store_true", help="do not draw the [plot]")
    ap.add_argument("--dry-run", action="store_true", help="check the sweep file and list the points, run nothing")
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)
    import os

    try:
        sweep = Sweep(args.sweep, fmu_override=args.fmu)
        sweep.preflight()
        if args.workers is not None and args.workers < 1:
            raise SweepError(f"--workers: expected an integer >= 1, got {args.workers}")
        out = args.out or os.path.join("out", os.path.splitext(os.path.basename(args.sweep))[0])
        if args.dry_run:
            print(f"{sweep.fmu}: {len(sweep.points)} points ({sweep.design}) over {', '.join(sweep.varied)}")
            for key, values in sweep.points:
                print(key, values)
            return 0
        from .runner import run_sweep

        s = run_sweep(sweep, out, scheduler=args.scheduler, workers=args.workers, resume=args.resume,
                      connect_timeout=args.connect_timeout, quiet=args.quiet, plot=not args.no_plot)
    except SweepError as exc:
        print(f"yarnsim-sweep: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("yarnsim-sweep: interrupted; the points done so far are saved, run again with --resume", file=sys.stderr)
        return 130
    msg = f"{s['rows']} rows ({s['ran']} run, {s['skipped']} skipped as done, {s['failed']} failed) in {out}/results.parquet and .csv"
    if s.get("throughput"):
        msg += f"; {s['throughput']:.2f} points/s on {s['workers']} workers"
    if s.get("plot"):
        msg += f"; plot {s['plot']}"
    print(msg)
    return 0


if __name__ == "__main__":
    sys.exit(main())
