"""Where ensemble members run: dask.distributed clusters from a ``[cluster]`` table.

``kind``:

- ``"local"`` (default): an embedded :class:`distributed.LocalCluster` of worker
  *processes*, one member at a time per worker. ``workers`` (default: one per
  core, at most one per member) and ``threads_per_member`` (numba threads per
  member; default ``cores // workers``) size it so the workers together use
  the machine's cores once: ``NUMBA_NUM_THREADS`` is set in each worker's
  environment before numba is imported. Other keys go to ``LocalCluster``
  (e.g. ``memory_limit = "4GiB"``).
- ``"slurm"`` / ``"pbs"``: :class:`dask_jobqueue.SLURMCluster` /
  :class:`~dask_jobqueue.PBSCluster`. ``cores`` and ``memory`` are per job;
  ``threads_per_member`` (default 1) gives ``processes = cores //
  threads_per_member`` workers per job; up to ``jobs`` (default 1) jobs are
  submitted while members wait and released as they finish (``adapt``).
  Every other key is a dask-jobqueue keyword (``queue``, ``account``,
  ``walltime``, ``job_extra_directives``, ``python``, ...). Each worker gets
  ``NUMBA_NUM_THREADS = cores // processes`` and a ``member`` resource of 1,
  so it runs one member at a time.
- ``"address"``: an existing scheduler (``address = "tcp://host:8786"``, or
  ``lagice ensemble --scheduler``). Workers started with ``--resources
  member=1`` run one member each; otherwise each worker thread takes one.
"""
from __future__ import annotations

import os

from ..errors import ConfigError

RESOURCE = "member"


def machine_cores() -> int:
    """Cores this process may use (CPU affinity / cgroup cpuset), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def local_cluster_kwargs(cores: int, n_members: int, workers: int | None = None,
                         threads_per_member: int | None = None, **extra) -> dict:
    """Keyword arguments of a LocalCluster with one member per worker and
    ``workers × numba threads <= cores`` (never fewer than 1 of each)."""
    if workers is None:
        workers = max(1, cores // (threads_per_member or 1))
        workers = max(1, min(workers, n_members))
    threads = threads_per_member or max(1, cores // workers)
    if workers * threads > cores:
        print(f"lagice ensemble: warning: {workers} workers x {threads} numba threads = {workers * threads} "
              f"threads on {cores} cores (oversubscribed)", flush=True)
    kw = {"n_workers": int(workers), "threads_per_worker": 1, "processes": True,
          "resources": {RESOURCE: 1}, "dashboard_address": ":0",
          "env": {"NUMBA_NUM_THREADS": str(threads), "OMP_NUM_THREADS": "1",
                  "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}}
    kw.update(extra)
    return kw


def jobqueue_kwargs(kind: str, cfg: dict) -> dict:
    """Keyword arguments of a SLURMCluster/PBSCluster from a ``[cluster]`` table."""
    kw = {k: v for k, v in cfg.items() if k not in ("kind", "jobs", "workers", "threads_per_member")}
    for k in ("cores", "memory"):
        if k not in kw:
            raise ConfigError(f"cluster.kind = {kind!r} needs cluster.{k} (per job, e.g. cores = 32, "
                              "memory = \"64GiB\")")
    cores = kw["cores"]
    if not isinstance(cores, int) or isinstance(cores, bool) or cores < 1:
        raise ConfigError(f"cluster.cores = {cores!r}: expected an integer >= 1 (cores per job)")
    tpm = cfg.get("threads_per_member") or 1
    processes = kw.setdefault("processes", max(1, cores // tpm))
    if not isinstance(processes, int) or not 1 <= processes <= cores:
        raise ConfigError(f"cluster.processes = {processes!r}: expected an integer in [1, cores = {cores}]")
    threads = max(1, cores // processes)
    prologue = list(kw.pop("job_script_prologue", []))
    prologue += [f"export NUMBA_NUM_THREADS={threads}", "export OMP_NUM_THREADS=1"]
    kw["job_script_prologue"] = prologue
    extra_args = list(kw.pop("worker_extra_args", []))
    kw["worker_extra_args"] = extra_args + ["--resources", f"{RESOURCE}=1"]
    return kw


def make_cluster(cfg: dict, n_members: int, workers: int | None = None):
    """An unstarted-for-work cluster object (no job submitted) from a ``[cluster]`` table.

    Returns ``(cluster, description)``; for ``kind = "address"`` returns (None, address)."""
    kind = cfg.get("kind", "local")
    if kind == "local":
        extra = {k: v for k, v in cfg.items() if k not in ("kind", "workers", "threads_per_member")}
        kw = local_cluster_kwargs(machine_cores(), n_members, workers or cfg.get("workers"),
                                  cfg.get("threads_per_member"), **extra)
        from distributed import LocalCluster
        cluster = LocalCluster(**kw)
        return cluster, (f"LocalCluster: {kw['n_workers']} worker processes x "
                         f"{kw['env']['NUMBA_NUM_THREADS']} numba thread(s) on {machine_cores()} cores")
    if kind in ("slurm", "pbs"):
        try:
            from dask_jobqueue import PBSCluster, SLURMCluster
        except ImportError as exc:  # pragma: no cover - dask-jobqueue is a dependency
            raise ConfigError(f"cluster.kind = {kind!r} needs dask-jobqueue: {exc}") from exc
        cls = SLURMCluster if kind == "slurm" else PBSCluster
        kw = jobqueue_kwargs(kind, cfg)
        try:
            cluster = cls(**kw)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"[cluster] kind = {kind!r}: {cls.__name__} refused the keywords: {exc}") from exc
        return cluster, (f"{cls.__name__}: {kw['processes']} workers per job x "
                         f"{max(1, kw['cores'] // kw['processes'])} numba thread(s)")
    if kind == "address":
        return None, cfg["address"]
    raise ConfigError(f"cluster.kind = {kind!r}: expected one of ['local', 'slurm', 'pbs', 'address']")


def scale(cluster, cfg: dict, workers: int | None = None) -> None:
    """Let a jobqueue cluster submit up to ``jobs`` jobs (or ``workers`` workers) while
    members wait, and release them as the members finish (``cluster.adapt``)."""
    if cfg.get("kind") in ("slurm", "pbs"):
        n = workers or cfg.get("workers")
        if n:
            cluster.adapt(minimum=0, maximum=n)
        else:
            cluster.adapt(minimum_jobs=0, maximum_jobs=cfg.get("jobs", 1))


def uses_member_resource(client) -> tuple[bool, int]:
    """(all workers declare the ``member`` resource, member slots across workers)."""
    info = client.scheduler_info(n_workers=-1) if _accepts_n_workers(client) else client.scheduler_info()
    ws = list(info.get("workers", {}).values())
    if ws and all(w.get("resources", {}).get(RESOURCE) for w in ws):
        return True, int(sum(w["resources"][RESOURCE] for w in ws))
    return False, int(sum(w.get("nthreads", 1) for w in ws))


def _accepts_n_workers(client) -> bool:
    import inspect
    try:
        return "n_workers" in inspect.signature(client.scheduler_info).parameters
    except (TypeError, ValueError):
        return False
