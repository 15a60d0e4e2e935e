"""``lagice ensemble SPEC --out DIR``: the command-line entry (parser kept light:
dask and the model are imported only when the command runs)."""
from __future__ import annotations

import signal
from pathlib import Path


def add_subcommand(sub) -> None:
    e = sub.add_parser("ensemble", help="run an ensemble or parameter sweep (TOML spec) on dask",
                       description="Run the members of an ensemble spec (docs/ensembles.md) on dask.distributed. "
                                   "Re-running the same command resumes: finished members are skipped, "
                                   "interrupted ones resume from their newest checkpoint.")
    e.add_argument("spec", help="ensemble spec (TOML)")
    e.add_argument("--out", help="output folder (default runs/ENSEMBLE_NAME)")
    e.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a scene key for every member (after the spec's [set])")
    e.add_argument("--workers", type=int, help="worker processes of the local cluster (default: one per core, "
                                                "at most one per member); or workers to start on SLURM/PBS")
    e.add_argument("--scheduler", metavar="ADDRESS", help="use an existing dask scheduler (tcp://host:8786)")
    e.add_argument("--serial", action="store_true", help="run the members one by one in this process (no dask)")
    e.add_argument("--skip-failed", action="store_true", help="do not run failed members again")
    e.add_argument("--dry-run", action="store_true", help="validate the spec, print the members and stop")
    e.add_argument("--no-plot", action="store_true", help="no spread PNG")
    e.set_defaults(func=run_command)


def run_command(args) -> int:
    from ..errors import ConfigError
    from .core import Ensemble

    if args.workers is not None and args.workers < 1:
        raise ConfigError(f"--workers = {args.workers}: expected an integer >= 1")
    ens = Ensemble.from_file(Path(args.spec), args.out, overrides=args.set)
    if args.dry_run:
        ens.check_folder()
        plan = ens.plan(not args.skip_failed)
        print(f"lagice ensemble {ens.spec.name!r}: {len(ens.members)} members ({ens.spec.kind}), "
              f"base {ens.spec.base or ens.spec.branch_from} -> {ens.out_dir}/")
        for m, line in zip(ens.members, ens.spec.table().splitlines()):
            print(f"{line}   [{plan[m.id]}]")
        kind = ens.spec.cluster.get("kind", "local")
        if kind in ("slurm", "pbs") and not args.scheduler:  # show the job script, submit nothing
            from .cluster import make_cluster
            cluster, desc = make_cluster(ens.spec.cluster, len(ens.members), args.workers)
            try:
                print(f"{desc}; job script (not submitted):\n{cluster.job_script()}")
            finally:
                cluster.close()
        return 0

    def _terminate(signum, frame):  # a batch system's SIGTERM: stop like Ctrl-C (close the cluster, summarise)
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        summary = ens.run(workers=args.workers, scheduler=args.scheduler, serial=args.serial,
                          retry_failed=not args.skip_failed, plot=not args.no_plot)
    except KeyboardInterrupt:
        print(f"lagice ensemble: interrupted; the summary holds the members finished so far. Run the same "
              f"command again to resume (finished members are skipped): lagice ensemble {args.spec} "
              f"--out {ens.out_dir}", flush=True)
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    return 0 if all(s == "done" for s in summary["status"].values) else 1
