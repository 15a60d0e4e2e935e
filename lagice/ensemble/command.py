"""``lagice ensemble SPEC --out DIR``: the command-line entry (parser kept light:
dask and the model are imported only when the command runs)."""
from __future__ import annotations

from pathlib import Path


def add_subcommand(sub, parents=()) -> None:
    e = sub.add_parser("ensemble", parents=list(parents),
                       help="run an ensemble or parameter sweep (TOML spec) on dask",
                       description="Run the members of an ensemble spec (docs/ensembles.md) on dask.distributed. "
                                   "Every member's configuration is checked before any member starts. Re-running "
                                   "the same command resumes: finished members are skipped, interrupted ones "
                                   "resume from their newest checkpoint. SIGTERM/SIGINT (or the file DIR/STOP) "
                                   "stop the running members cleanly with a checkpoint.")
    e.add_argument("spec", help="ensemble spec (TOML)")
    e.add_argument("--out", help="output folder (default runs/ENSEMBLE_NAME); re-running into it resumes")
    e.add_argument("--overwrite", action="store_true", help="remove an earlier ensemble in --out first")
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
        plan = {m.id: "new" for m in ens.members} if args.overwrite else None
        if plan is None:
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
    if args.overwrite:
        ens.clear_folder()
    try:
        summary = ens.run(workers=args.workers, scheduler=args.scheduler, serial=args.serial,
                          retry_failed=not args.skip_failed, plot=not args.no_plot)
    except KeyboardInterrupt:  # a second SIGINT/SIGTERM: stopped at once
        print(f"lagice ensemble: interrupted at once; members in flight resume from their last periodic "
              f"checkpoint. Run the same command again to resume: lagice ensemble {args.spec} --out {ens.out_dir}",
              flush=True)
        return 130
    if ens.stopped:  # a clean stop (as `lagice run`: exit 0, with how to resume)
        print(f"  resume with: lagice ensemble {args.spec} --out {ens.out_dir}", flush=True)
        return 0
    return 0 if all(s == "done" for s in summary["status"].values) else 1
