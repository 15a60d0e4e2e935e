"""Run folders: one run per folder, never mixed.

* A new run gets a folder that cannot collide: ``runs/SCENE-YYYYmmdd-HHMMSS``
  (:func:`new_run_dir`, suffixed ``-2``, ``-3`` ... when that exists), and the
  link ``runs/SCENE-latest`` points to the newest one (:func:`update_latest`).
* An explicit folder must be empty or absent (:func:`claim`), unless the user
  asks to ``overwrite`` it (its contents are removed first, and only when it is a
  lagice run folder) or to ``resume`` the run in it.
* :func:`prepare` creates the folder, proves it is writable (writes the marker
  file ``lagice_run.json``, with the fingerprint of the run's physics settings)
  before any mesh work, and removes the temporary files a killed write left behind
  (checkpoints, snapshots, VTU, index files).
* :func:`restart_unstarted`: ``lagice run SCENE --out DIR --resume`` on a folder whose
  run (same scene, same physics settings: its marker says so) was stopped before its
  first checkpoint starts that run afresh there; any other content is refused.
* :class:`RunLock`: the process that writes a run into a folder holds an exclusive
  advisory lock (``flock``) on ``DIR/.lock`` for the whole run; a second process on the
  same folder (``lagice run --out``, ``--resume``, ``lagice resume``, ``lagice branch
  --out``, an ensemble member) fails at once (:class:`~lagice.errors.RunFolderLocked`,
  naming the holder's pid, host and start time) before it reads or writes anything
  there. The kernel drops the lock when its process ends, also on a crash or SIGKILL, so
  a ``.lock`` file left behind never blocks a later run: the lock decides, not the file.
"""
from __future__ import annotations

import errno
import hashlib
import json
import logging
import os
import shlex
import shutil
import socket
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

from .errors import ConfigError, OutputError, RunFolderLocked

MARKER = "lagice_run.json"
#: the run-folder lock file (:class:`RunLock`): ``flock``-ed by the process writing the run
LOCK = ".lock"
#: what marks a folder as a lagice run folder (besides the marker)
RUN_ENTRIES = ("snapshots", "checkpoints", "summary.json", "timeseries.nc")
#: what a run writes into its folder besides RUN_ENTRIES and the marker (``{scene}``: the scene name)
RUN_OUTPUTS = ("drifters.nc", "{scene}.png")
#: temporary files of the atomic writers (``*.tmp`` then ``os.replace``)
TEMP_GLOBS = ("*.tmp", ".*.tmp.png", "snapshots/*.tmp", "snapshots/*.tmp.vtu", "diagnostics/*.tmp",
              "diagnostics/.*.tmp.png", "checkpoints/*.tmp-*")

log = logging.getLogger("lagice")


def new_run_dir(scene: str, root="runs", now: datetime | None = None) -> Path:
    """``root/SCENE-YYYYmmdd-HHMMSS`` (local time), suffixed ``-2``, ``-3``... if taken."""
    stamp = (now or datetime.now()).strftime("%Y%m%d-%H%M%S")
    base = Path(root) / f"{scene}-{stamp}"
    p, k = base, 1
    while p.exists() or p.is_symlink():
        k += 1
        p = base.with_name(f"{base.name}-{k}")
    return p


def latest_link(scene: str, root="runs") -> Path:
    return Path(root) / f"{scene}-latest"


def update_latest(run_dir: Path, scene: str) -> Path | None:
    """Point ``runs/SCENE-latest`` (a relative symlink next to ``run_dir``) at ``run_dir``;
    None when the file system has no symlinks (the run is unaffected)."""
    run_dir = Path(run_dir)
    link = latest_link(scene, run_dir.parent)
    tmp = link.with_name(f".{link.name}.tmp-{os.getpid()}")
    try:
        tmp.unlink(missing_ok=True)
        os.symlink(run_dir.name, tmp, target_is_directory=True)
        os.replace(tmp, link)
    except OSError as exc:
        log.warning(f"could not update the link {link} -> {run_dir.name} ({exc.strerror})")
        return None
    return link


def is_run_dir(path) -> bool:
    p = Path(path)
    return (p / MARKER).exists() or any((p / e).exists() for e in RUN_ENTRIES)


def settings_fingerprint(config: dict) -> str:
    """Hash of the settings that determine a run's trajectory (the physics view of its
    configuration, :func:`lagice.scenes.config.physics_view`), as the checkpoints' scene
    fingerprint (:meth:`lagice.model.Model.fingerprint`) hashes them."""
    from .scenes.config import physics_view

    view = {k: v for k, v in physics_view(config).items() if not k.startswith("_")}
    return hashlib.sha256(json.dumps(view, sort_keys=True, default=str).encode()).hexdigest()[:16]


def is_empty(path) -> bool:
    """Absent, or a folder that holds nothing but the lock file :data:`LOCK`."""
    p = Path(path)
    return not p.exists() or (p.is_dir() and not any(c.name != LOCK for c in p.iterdir()))


def claim(out, overwrite: bool = False) -> Path:
    """Make sure a new run may write into ``out``: absent or empty, or (``overwrite``)
    a lagice run folder whose contents are removed now. ConfigError otherwise."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"output folder {out} exists and is not a folder")
    if is_empty(out):
        return out
    if not overwrite:
        hint = "continue it with --resume, " if (out / "checkpoints").is_dir() else ""
        raise ConfigError(f"output folder {out} is not empty (a previous run?); {hint}replace it with --overwrite, "
                          f"or choose another --out (runs are never mixed in one folder)")
    if not is_run_dir(out):
        raise ConfigError(f"output folder {out} is not empty and is not a lagice run folder (no {MARKER}, "
                          f"snapshots/ or checkpoints/); refusing to delete it with --overwrite")
    clear_folder(out, keep=(LOCK,))
    log.info(f"cleared {out}/ (--overwrite)")
    return out


def restart_unstarted(out, config: dict) -> Path:
    """``lagice run SCENE --out DIR --resume`` when DIR holds no checkpoint: start the run
    afresh in DIR. Allowed when DIR is empty or absent, or when it holds the run of the same
    scene with the same physics settings (its marker ``lagice_run.json`` names the scene
    and the settings fingerprint, :func:`settings_fingerprint`), stopped before its first
    checkpoint; that run's partial outputs are removed (one line says so). A folder holding
    another run (other scene or settings, a branch, an ensemble member, a marker without a
    fingerprint) or files a run does not write is refused (ConfigError naming it)."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"output folder {out} exists and is not a folder")
    if is_empty(out):
        return out
    scene = config["scene"]["name"]
    how = "replace it with --overwrite, or choose another --out (runs are never mixed in one folder)"
    marker = out / MARKER
    if not marker.is_file():
        raise ConfigError(f"--resume: output folder {out} holds no checkpoint and no {MARKER}: it is not the folder "
                          f"of a run of scene {scene!r}; {how}")
    try:
        info = json.loads(marker.read_text())
    except (OSError, ValueError) as exc:
        raise ConfigError(f"--resume: cannot read {marker} ({exc}); {how}") from None
    if not isinstance(info, dict):
        raise ConfigError(f"--resume: {marker} is not a lagice run marker; {how}")
    if info.get("parent") or info.get("ensemble"):
        what = "a branch of a checkpoint" if info.get("parent") else "an ensemble member"
        raise ConfigError(f"--resume: output folder {out} holds {what} stopped before its first checkpoint, not a "
                          f"run of scene {scene!r}; {how}")
    if info.get("scene") != scene:
        raise ConfigError(f"--resume: output folder {out} holds a run of scene {info.get('scene')!r} (no "
                          f"checkpoint), not of {scene!r}; {how}")
    if info.get("fingerprint") is None:
        raise ConfigError(f"--resume: output folder {out} holds a run of {scene!r} without a checkpoint, and its "
                          f"{MARKER} has no settings fingerprint (an older lagice) to tell whether it is this run; "
                          f"{how}")
    fp = settings_fingerprint(config)
    if info["fingerprint"] != fp:
        raise ConfigError(f"--resume: output folder {out} holds a run of {scene!r} with other physics settings "
                          f"(fingerprint {info['fingerprint']}, these settings {fp}) and no checkpoint; {how}")
    known = {MARKER, LOCK, *RUN_ENTRIES, *(o.format(scene=scene) for o in RUN_OUTPUTS)}
    for child in sorted(out.iterdir()):
        if child.name not in known and not child.name.endswith(".tmp"):
            raise ConfigError(f"--resume: output folder {out} holds {child.name}, which a run does not write; "
                              f"refusing to replace the run in it (move {child.name} away, or choose another --out)")
    ck = out / "checkpoints"
    if ck.is_dir() and any(ck.glob("checkpoint_*.npz")):  # the caller resumes these
        raise ConfigError(f"--resume: output folder {out} holds checkpoints: resume them")
    clear_folder(out, keep=(LOCK,), why="--resume")
    log.info(f"{out}/ holds this run of {scene!r} stopped before its first checkpoint: starting it afresh there "
             f"(its partial outputs are replaced)")
    return out


def prepare(out, config: dict | None = None) -> list[Path]:
    """Create ``out``, prove it writable (by writing the marker ``lagice_run.json``:
    scene, lagice version and git commit, command, parent checkpoint of a branch, ensemble member; or, when it
    exists, a probe file), and remove stale temporary files of killed writes.
    Raises OutputError naming the folder."""
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the output folder {out}: {exc.strerror}") from None
    removed = clean_stale(out)
    marker = out / MARKER
    if not marker.exists():  # a resumed run keeps the marker of its start
        from . import __version__
        from .io.cf import git_commit, git_modified_files

        cfg = config or {}
        info = {"scene": cfg.get("scene", {}).get("name"), "source": cfg.get("scene", {}).get("source"),
                "lagice_version": __version__, "written": datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
                "command": shlex.join(sys.argv) if sys.argv and sys.argv[0] else None}   # shell-quoted
        if git_commit():   # the code that made the run, when lagice runs from a git checkout
            info["git_commit"] = git_commit()
            if git_modified_files():   # "-dirty": which tracked files differed from that commit
                info["git_modified_files"] = git_modified_files()
        if cfg.get("scene"):
            info["fingerprint"] = settings_fingerprint(cfg)
        if cfg.get("_parent"):
            info["parent"] = cfg["_parent"]
        if cfg.get("_ensemble"):
            info["ensemble"] = cfg["_ensemble"]
        tmp = marker.with_name(f"{MARKER}.tmp")
        try:
            tmp.write_text(json.dumps(info, indent=1, default=str))
            os.replace(tmp, marker)
        except OSError as exc:
            try:
                tmp.unlink(missing_ok=True)
            except OSError:
                pass
            raise OutputError(f"cannot write in the output folder {out}: {exc.strerror}") from None
    else:
        probe = out / f".lagice-write-probe-{os.getpid()}"
        try:
            probe.write_bytes(b"")
            probe.unlink()
        except OSError as exc:
            raise OutputError(f"cannot write in the output folder {out}: {exc.strerror}") from None
    return removed


def discard(out, remove_folder: bool) -> None:
    """Undo :func:`prepare` for a new run that failed before it started (a check that
    needed the mesh): remove what was written in ``out`` (it was empty), and ``out``
    itself when ``remove_folder`` (it did not exist), so that the corrected command can
    use the same folder. The lock file :data:`LOCK` stays for the process that holds it
    (:meth:`RunLock.release` removes it with the folder it made). Failures to remove are
    reported, not raised (the first error matters)."""
    out = Path(out)
    try:
        clear_folder(out, keep=(LOCK,), why="removing the folder of the failed run")
        if remove_folder and not any(out.iterdir()):
            out.rmdir()
    except (OSError, OutputError) as exc:
        log.warning(f"could not remove {out} after the failed start: {exc}")


def clean_stale(out) -> list[Path]:
    """Remove the temporary files killed writes left in the run folder ``out``."""
    from .io.checkpoint import clean_stale_temporaries

    out = Path(out)
    removed = clean_stale_temporaries(out / "checkpoints")
    for pattern in TEMP_GLOBS[:-1]:
        for p in out.glob(pattern):
            if p.is_file():
                try:
                    p.unlink()
                    removed.append(p)
                except OSError:
                    pass
    for p in removed:
        log.info(f"removed a temporary file left by an interrupted write: {p}")
    return removed


def clear_folder(folder: Path, keep: tuple[str, ...] = (), why: str = "--overwrite") -> None:
    """Remove everything in ``folder`` but the names in ``keep`` (``--overwrite``);
    a file that cannot be removed is an :class:`OutputError` naming it."""
    for child in Path(folder).iterdir():
        if child.name in keep:
            continue
        try:
            if child.is_dir() and not child.is_symlink():
                shutil.rmtree(child)
            else:
                child.unlink()
        except OSError as exc:
            raise OutputError(f"{why}: cannot remove {child}: {exc.strerror}") from None


def make_run_dir(scene: str, root="runs") -> Path:
    """A new, empty default run folder ``root/SCENE-YYYYmmdd-HHMMSS`` (:func:`new_run_dir`),
    created here: two processes started in the same second get two folders."""
    for _ in range(100):
        p = new_run_dir(scene, root)
        try:
            p.mkdir(parents=True)
        except FileExistsError:
            continue  # taken between the look and the mkdir: the next suffix
        except OSError as exc:
            raise OutputError(f"cannot create the output folder {p}: {exc.strerror}") from None
        return p
    raise OutputError(f"cannot create a new run folder for {scene!r} in {root}/ (every name was taken)")


class RunLock:
    """The exclusive advisory lock of the run folder ``folder``: ``flock`` on
    ``folder/.lock`` (:data:`LOCK`), which holds the holder's pid, host, start time and
    command as one line of JSON while it runs (empty once it is done).

    :meth:`acquire` (or ``with RunLock(folder):``) creates the folder when it is absent
    and fails at once, with :class:`~lagice.errors.RunFolderLocked` naming the folder and
    the holder, when another process holds the lock; or when the file system cannot lock
    (lagice does not run unlocked). The kernel drops the lock when its process ends, so a
    ``.lock`` file left by a killed run never blocks a later one. The lock file stays in
    a run folder, emptied, when the lock is released; when no run was started in the
    folder (a command refused after taking the lock, a new run that failed its checks on
    the mesh), :meth:`release` removes the lock file it made, and the folder when it made
    that too (``created``) and it is empty, so no trace is left and the corrected command
    can use the folder. A ``.lock`` in a folder that is not a run folder and holds other
    files is not lagice's: it is refused (ConfigError), not overwritten.

    One lock per run folder and process: a second ``RunLock`` on the same folder in the
    same process is refused like another process's (``flock`` locks open files)."""

    def __init__(self, folder, created: bool = False):
        self.folder = Path(folder)
        self.path = self.folder / LOCK
        self.created = created
        self._made_file = False
        self._fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()
        return False

    @property
    def held(self) -> bool:
        return self._fd is not None

    def acquire(self) -> RunLock:
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not a POSIX system
            raise RunFolderLocked(f"cannot lock the run folder {self.folder}: this system has no flock (fcntl); "
                                  f"lagice does not write a run folder unlocked") from None
        folder = self.folder
        if folder.exists() and not folder.is_dir():
            raise ConfigError(f"output folder {folder} exists and is not a folder")
        if not folder.exists():
            try:
                folder.mkdir(parents=True)
                self.created = True
            except FileExistsError:
                pass  # made by another process just now: the lock decides
            except OSError as exc:
                raise OutputError(f"cannot create the output folder {folder}: {exc.strerror}") from None
        for _ in range(10):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o644)
                self._made_file = True
            except FileExistsError:
                fd = None
                if not is_run_dir(folder) and not is_empty(folder):  # not a lock of lagice's: leave it alone
                    raise ConfigError(f"output folder {folder} holds a {LOCK} file and other files but is not a "
                                      f"lagice run folder (no {MARKER}, snapshots/ or checkpoints/); refusing to "
                                      f"take {self.path} as its run lock: choose another --out") from None
            except OSError as exc:
                fd = -1
                err = exc
            if fd is None:  # an earlier run's lock file (held or not: the lock decides)
                try:
                    fd = os.open(self.path, os.O_RDWR | os.O_CLOEXEC)
                except FileNotFoundError:
                    continue  # removed just now by its holder's release: make it again
                except OSError as exc:
                    fd = -1
                    err = exc
            if fd == -1:
                if self.created:
                    try:
                        folder.rmdir()
                    except OSError:
                        pass
                raise OutputError(f"cannot write in the output folder {folder}: {err.strerror}") from None
            try:
                _flock_exclusive(fd)
            except BlockingIOError:
                holder = _lock_holder(fd)
                os.close(fd)
                raise RunFolderLocked(
                    f"run folder {folder} is in use by another lagice process ({holder}); wait for it to finish, "
                    f"or stop it (SIGTERM: it writes a checkpoint), then run this command again") from None
            except OSError as exc:
                os.close(fd)
                self._tidy()
                raise RunFolderLocked(
                    f"cannot lock the run folder {folder}: flock on {self.path} failed ({exc.strerror}; errno "
                    f"{errno.errorcode.get(exc.errno, exc.errno)}), so the file system does not support file locks; "
                    f"lagice does not write a run folder unlocked (another process could write the same folder): "
                    f"use a folder on a file system with locks (a local disk, NFS with locking)") from None
            try:  # the file this lock holds is still the folder's lock file (not removed by a release meanwhile)
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        else:  # pragma: no cover - the lock file was replaced ten times in a row
            raise RunFolderLocked(f"cannot lock the run folder {folder}: its lock file {self.path} keeps changing")
        info = {"pid": os.getpid(), "host": socket.gethostname(),
                "started": datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
                "command": shlex.join(sys.argv) if sys.argv and sys.argv[0] else None}   # shell-quoted
        try:
            os.ftruncate(fd, 0)
            os.pwrite(fd, (json.dumps(info) + "\n").encode(), 0)
        except OSError as exc:
            fcntl.flock(fd, fcntl.LOCK_UN)
            os.close(fd)
            raise OutputError(f"cannot write in the output folder {folder}: {exc.strerror}") from None
        self._fd = fd
        return self

    def release(self) -> None:
        """Give the lock up: the lock file is emptied (or removed, with the folder this lock
        made when nothing else is in it), then unlocked. Never raises."""
        if self._fd is None:
            return
        import fcntl

        fd, self._fd = self._fd, None
        try:
            if not self._tidy():
                os.ftruncate(fd, 0)
        except OSError:
            pass
        finally:
            try:
                fcntl.flock(fd, fcntl.LOCK_UN)
            finally:
                os.close(fd)

    def _tidy(self) -> bool:
        """When no run was started in the folder (it is not a run folder: a start that was
        refused, or that failed its checks on the mesh) and this lock made the lock file,
        remove that file, and the folder when this lock made it and nothing else is in it;
        True when it did."""
        if not self._made_file:
            return False
        try:
            if is_run_dir(self.folder):
                return False
            self.path.unlink(missing_ok=True)
            if self.created and not any(self.folder.iterdir()):
                self.folder.rmdir()
        except OSError:
            return False
        return True


#: a lock found held is tried again this many times, this far apart [s], before the run is
#: refused: ``running_holder``'s probe (``lagice plot`` / ``diagnose`` beside the folder) holds a
#: shared lock for microseconds, and a run or resume that starts in that moment waits it out
#: instead of being refused; a run that holds the lock is still refused, after 0.2 s
LOCK_RETRIES = 20
LOCK_RETRY_S = 0.01


def _flock_exclusive(fd) -> None:
    """Take the exclusive flock of ``fd`` without blocking, tried :data:`LOCK_RETRIES` times
    :data:`LOCK_RETRY_S` apart; BlockingIOError when it is still held."""
    import fcntl

    for k in range(LOCK_RETRIES):
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            if k == LOCK_RETRIES - 1:
                raise
            time.sleep(LOCK_RETRY_S)


def running_holder(folder) -> str | None:
    """'pid P on host H, since T' of the process that holds the run lock of ``folder`` now
    (a run still going, or a resume), else None (no lock file, or a lock left by a run that
    ended or was killed: the kernel dropped it). For the commands that only read a run
    folder (``lagice plot``, ``lagice diagnose``), which may run beside the run: they say
    that their figure covers the run so far. The probe is a non-blocking *shared* flock
    that is released at once: it never waits, and a run that starts in the same
    microseconds waits it out (:func:`_flock_exclusive` tries again for 0.2 s)."""
    import fcntl

    path = Path(folder) / LOCK
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return _lock_holder(fd)
        except OSError:
            return None  # a file system without locks: no run can hold one there either
        fcntl.flock(fd, fcntl.LOCK_UN)
        return None
    finally:
        os.close(fd)


def _lock_holder(fd) -> str:
    """'pid P on host H, since T' of the lock file ``fd`` (its holder writes it
    just after it takes the lock: read again for a moment when it is still empty)."""
    for _ in range(20):
        try:
            raw = os.pread(fd, 4096, 0)
            info = json.loads(raw.decode()) if raw.strip() else None
        except (OSError, ValueError, UnicodeDecodeError):
            info = None
        if isinstance(info, dict):  # its command is in the file too (often long: not in the one-line error)
            return f"pid {info.get('pid')} on host {info.get('host')}, since {info.get('started')}"
        time.sleep(0.025)
    return "its pid, host and start time are not in the lock file yet"
