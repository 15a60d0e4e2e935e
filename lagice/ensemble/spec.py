"""Ensemble specs (TOML): a base scene, common overrides and members.

::

    [ensemble]
    name = "cohesion_seeds"          # default: the spec file name
    base = "winter_basin"            # bundled scene name or a .toml path (relative to this file)
    # branch_from = "spinup/checkpoints/checkpoint_0000000720.npz"   # instead of base

    [set]                            # overrides common to every member (dotted keys)
    "domain.resolution_m" = 20e3
    "run.duration" = "2d"

    # members: exactly one of [[member]], [grid] or [seeds]
    [[member]]
    id = "weak"                      # default m000, m001, ...
    set = { "rheology.cohesion_max_pa" = 10e3 }

    [grid]                           # Cartesian product, first key slowest
    "rheology.alpha" = [3.0, 4.0, 5.0]
    "forcing.wind.n" = [4, 6]

    [seeds]
    n = 8
    seed = 2026                      # master seed
    keys = ["run.seed", "forcing.wind.seed"]            # a random integer seed per member and key
    perturb = { "rheology.cohesion_max_pa" = { relative = 0.1, distribution = "normal" } }

    [cluster]                        # where members run (lagice.ensemble.cluster)
    kind = "local"

    [analysis]                       # deformation statistics of each member's last window(s)
    window = "1d"
    windows = 1
    coast_buffer_km = 0

Every member's configuration is built and validated (``load_scene`` and the
engine's pre-mesh checks) when the spec is read, so a bad spec fails before
any member starts, with a message naming the member and the key.
"""
from __future__ import annotations

import copy
import hashlib
import itertools
import json
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, LagiceError
from ..schedule import parse_duration

TABLES = ("ensemble", "set", "member", "grid", "seeds", "cluster", "analysis")
ENSEMBLE_KEYS = ("name", "base", "description", "branch_from")
MEMBER_KEYS = ("id", "set")
SEED_KEYS = ("n", "seed", "keys", "perturb")
PERTURB_KEYS = ("relative", "absolute", "distribution")
DISTRIBUTIONS = ("normal", "uniform")
ANALYSIS_DEFAULTS = {"window": None, "windows": 1, "coast_buffer_km": 0.0}
CLUSTER_KINDS = ("local", "slurm", "pbs", "address")
_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._=+,-]{0,119}$")


@dataclass
class Member:
    """One ensemble member: its id, its own overrides and its full, validated scene config."""
    id: str
    overrides: dict                 # the member's own overrides (dotted key -> value)
    config: dict = field(repr=False)  # validated scene config (common + member overrides applied)

    @property
    def config_hash(self) -> str:
        """SHA-256 (16 hex) of the member's config, the keys starting with ``_`` left out."""
        return config_hash(self.config)


@dataclass
class EnsembleSpec:
    name: str
    members: list
    common: dict                    # overrides common to every member
    base: str | None                # scene name or path (None when branching)
    branch_from: Path | None
    branch_sha256: str | None
    kind: str                       # "member", "grid" or "seeds"
    cluster: dict
    analysis: dict
    description: str = ""
    source: str = "<dict>"
    raw: dict = field(default_factory=dict, repr=False)

    def member(self, member_id: str) -> Member:
        for m in self.members:
            if m.id == member_id:
                return m
        raise KeyError(member_id)

    def table(self) -> str:
        """A one-line-per-member description (``lagice ensemble --dry-run``)."""
        lines = []
        width = max(len(m.id) for m in self.members)
        for m in self.members:
            sets = ", ".join(f"{k}={_fmt(v)}" for k, v in m.overrides.items()) or "(base)"
            lines.append(f"  {m.id:<{width}}  {sets}")
        return "\n".join(lines)


def config_hash(cfg: dict) -> str:
    clean = {k: v for k, v in cfg.items() if not k.startswith("_")}
    return hashlib.sha256(json.dumps(clean, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    return str(v) if not isinstance(v, str) else v


# -- reading ---------------------------------------------------------------------------
def load_spec(spec, overrides=None) -> EnsembleSpec:
    """An :class:`EnsembleSpec` from a TOML file path, TOML text or a dict.

    ``overrides`` (``{"table.key": value}`` or ``["table.key=value"]``) are added
    to the spec's ``[set]`` table (they win), e.g. ``lagice ensemble --set``.
    Raises :class:`~lagice.errors.ConfigError` naming the problem.
    """
    source, root = "<dict>", Path.cwd()
    if isinstance(spec, (str, Path)) and not (isinstance(spec, str) and "\n" in spec):
        path = Path(spec)
        if not path.is_file():
            raise ConfigError(f"ensemble spec {path} does not exist")
        source, root = str(path), path.resolve().parent
        try:
            raw = tomllib.loads(path.read_text())
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"{path}: not valid TOML: {exc}") from exc
    elif isinstance(spec, str):
        try:
            raw = tomllib.loads(spec)
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"ensemble spec: not valid TOML: {exc}") from exc
        source = "<toml>"
    elif isinstance(spec, dict):
        raw = copy.deepcopy(spec)
    else:
        raise ConfigError(f"ensemble spec: expected a TOML file path, TOML text or a dict, got {type(spec).__name__}")
    return parse_spec(raw, source, root, overrides)


def parse_spec(raw: dict, source: str = "<dict>", root: Path | None = None, overrides=None) -> EnsembleSpec:
    root = Path.cwd() if root is None else Path(root)
    for t in raw:
        if t not in TABLES:
            raise ConfigError(f"{source}: unknown table [{t}]; known tables: {list(TABLES)}")
    ens = _table(raw, "ensemble", source)
    for k in ens:
        if k not in ENSEMBLE_KEYS:
            raise ConfigError(f"{source}: unknown key ensemble.{k}; known keys: {list(ENSEMBLE_KEYS)}")
    name = ens.get("name") or (Path(source).stem if source not in ("<dict>", "<toml>") else "ensemble")
    if not isinstance(name, str) or not _ID.match(name):
        raise ConfigError(f"{source}: ensemble.name = {name!r}: expected letters, digits and ._=+,- "
                          "(it names folders)")
    common = flatten(_table(raw, "set", source), "set", source)
    common.update(_cli_overrides(overrides))

    # base configuration: a scene, or the config stored in a checkpoint
    base, branch, branch_sha, parent = ens.get("base"), ens.get("branch_from"), None, None
    if (base is None) == (branch is None):
        raise ConfigError(f"{source}: give exactly one of ensemble.base (a scene name or .toml path) or "
                          "ensemble.branch_from (a checkpoint file every member starts from)")
    if base is not None:
        if not isinstance(base, str):
            raise ConfigError(f"{source}: ensemble.base = {base!r}: expected a scene name or a .toml path")
        base = _resolve_base(base, root, source)
    else:
        if not isinstance(branch, str):
            raise ConfigError(f"{source}: ensemble.branch_from = {branch!r}: expected a checkpoint file path")
        branch = (Path(branch) if Path(branch).is_absolute() else (root / branch)).resolve()
        from ..io.checkpoint import file_sha256, read_checkpoint
        if not branch.is_file():
            raise ConfigError(f"{source}: ensemble.branch_from = {str(branch)!r}: checkpoint file not found")
        try:
            _, meta = read_checkpoint(branch)
        except LagiceError as exc:
            raise ConfigError(f"{source}: ensemble.branch_from = {str(branch)!r}: {exc}") from None
        branch_sha = file_sha256(branch)
        parent = (branch, meta, branch_sha)

    members_raw = _expand_members(raw, source, common, base, parent)
    members, seen = [], {}
    for mid, own in members_raw:
        if mid in seen:
            raise ConfigError(f"{source}: duplicate member id {mid!r} (members {seen[mid] + 1} and {len(seen) + 1}); "
                              "member ids must be unique (they name the member folders)")
        seen[mid] = len(seen)
        if not isinstance(mid, str) or not _ID.match(mid):
            raise ConfigError(f"{source}: member id {mid!r}: expected 1-120 letters, digits and ._=+,- "
                              "starting with a letter or digit (it names a folder)")
        try:
            cfg = member_config(base, {**common, **own}, parent)
        except LagiceError as exc:
            raise ConfigError(f"{source}: member {mid!r} ({_overrides_text(own)}): {exc}") from None
        members.append(Member(mid, own, cfg))
    if not members:
        raise ConfigError(f"{source}: the ensemble has no members")
    kind = next(k for k in ("member", "grid", "seeds") if k in raw)
    return EnsembleSpec(name=name, members=members, common=common, base=base, branch_from=branch,
                        branch_sha256=branch_sha, kind=kind, cluster=parse_cluster(raw.get("cluster", {}), source),
                        analysis=parse_analysis(raw.get("analysis", {}), source),
                        description=str(ens.get("description", "")), source=source, raw=raw)


def _overrides_text(d: dict) -> str:
    return ", ".join(f"{k}={_fmt(v)}" for k, v in d.items()) or "no own overrides"


def _table(raw, name, source):
    t = raw.get(name, {})
    if not isinstance(t, dict):
        raise ConfigError(f"{source}: [{name}] must be a table")
    return t


def _cli_overrides(overrides) -> dict:
    if not overrides:
        return {}
    if isinstance(overrides, dict):
        return dict(overrides)
    from ..scenes.config import split_overrides
    return dict(split_overrides(overrides))


def _resolve_base(base: str, root: Path, source: str) -> str:
    from ..scenes.config import scene_path
    looks_like_path = base.endswith(".toml") or "/" in base
    if looks_like_path:
        p = Path(base) if Path(base).is_absolute() else root / base
        if not p.is_file():
            raise ConfigError(f"{source}: ensemble.base = {base!r}: scene file {p} does not exist")
        return str(p)
    try:
        return str(scene_path(base))
    except ConfigError as exc:
        raise ConfigError(f"{source}: ensemble.base = {base!r}: {exc}") from None


def flatten(d: dict, where: str, source: str, stop=None) -> dict:
    """``{"run": {"duration": "2d"}}`` and ``{"run.duration": "2d"}`` -> ``{"run.duration": "2d"}``.

    A nested table merges key by key into the scene (like ``--set`` of each leaf);
    ``stop(value)`` marks a table that is itself a value (e.g. a perturbation rule)."""
    out = {}

    def walk(prefix, node):
        for k, v in node.items():
            key = f"{prefix}.{k}" if prefix else k
            if isinstance(v, dict) and v and not (stop and stop(v)):
                walk(key, v)
            else:
                if key in out:
                    raise ConfigError(f"{source}: [{where}] gives {key} twice")
                out[key] = v
    walk("", d)
    return out


# -- members ---------------------------------------------------------------------------
def _expand_members(raw, source, common, base, parent):
    kinds = [k for k in ("member", "grid", "seeds") if k in raw]
    if len(kinds) != 1:
        raise ConfigError(f"{source}: give the members as exactly one of [[member]] (a list of overrides), "
                          f"[grid] (value lists, Cartesian product) or [seeds] (n members with seed rules); "
                          f"found {['[[member]]' if k == 'member' else f'[{k}]' for k in kinds] or 'none'}")
    kind = kinds[0]
    if kind == "member":
        return _list_members(raw["member"], source)
    if kind == "grid":
        return grid_members(flatten(_table(raw, "grid", source), "grid", source), source)
    return seed_members(_table(raw, "seeds", source), source, common, base, parent)


def _list_members(items, source):
    if not isinstance(items, list) or not all(isinstance(m, dict) for m in items):
        raise ConfigError(f"{source}: members must be an array of tables: [[member]] id = ..., set = {{...}}")
    if not items:
        raise ConfigError(f"{source}: [[member]] is empty: give at least one member")
    width = max(3, len(str(len(items) - 1)))
    out = []
    for i, m in enumerate(items):
        for k in m:
            if k not in MEMBER_KEYS:
                raise ConfigError(f"{source}: member {i + 1}: unknown key {k!r}; known keys: {list(MEMBER_KEYS)}")
        own = m.get("set", {})
        if not isinstance(own, dict):
            raise ConfigError(f"{source}: member {i + 1}: set must be a table of overrides")
        out.append((m.get("id", f"m{i:0{width}d}"), flatten(own, f"member {i + 1} set", source)))
    return out


def grid_members(grid: dict, source: str = "<grid>"):
    """[(id, overrides)] of the Cartesian product of ``{key: [values]}`` (first key slowest).

    Ids join ``leaf=value`` with ``__`` (``alpha=3__n=4``); the full dotted key is
    used when two keys share a leaf name."""
    if not grid:
        raise ConfigError(f"{source}: [grid] is empty: give at least one key with a list of values")
    for k, vals in grid.items():
        if not isinstance(vals, list):
            raise ConfigError(f"{source}: grid.{k} = {vals!r}: expected a list of values")
        if not vals:
            raise ConfigError(f"{source}: grid.{k} is an empty list: the grid would have no members")
    leaves = [k.rsplit(".", 1)[-1] for k in grid]
    labels = [leaf if leaves.count(leaf) == 1 else key for leaf, key in zip(leaves, grid)]
    out = []
    for combo in itertools.product(*grid.values()):
        own = dict(zip(grid, combo))
        mid = "__".join(f"{lab}={_id_value(v)}" for lab, v in zip(labels, combo))
        out.append((mid, own))
    return out


def _id_value(v) -> str:
    if isinstance(v, bool):
        s = str(v).lower()
    elif isinstance(v, float):
        s = f"{v:g}"
    else:
        s = json.dumps(v) if not isinstance(v, (str, int)) else str(v)
    return re.sub(r"[^A-Za-z0-9.+-]", "-", s)


def seed_members(t: dict, source: str, common: dict, base, parent):
    """[(id, overrides)] of ``n`` members: member k draws from ``default_rng([seed, k])``,
    first one integer in [0, 2**31 - 1) per entry of ``keys`` (in order), then one
    perturbation per entry of ``perturb`` (in order). Member k does not depend on n."""
    for k in t:
        if k not in SEED_KEYS:
            raise ConfigError(f"{source}: unknown key seeds.{k}; known keys: {list(SEED_KEYS)}")
    n = t.get("n")
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ConfigError(f"{source}: seeds.n = {n!r}: expected an integer >= 1 (number of members)")
    master = t.get("seed", 0)
    if not isinstance(master, int) or isinstance(master, bool) or master < 0:
        raise ConfigError(f"{source}: seeds.seed = {master!r}: expected an integer >= 0 (master seed)")
    perturb = t.get("perturb", {})
    if not isinstance(perturb, dict):
        raise ConfigError(f"{source}: seeds.perturb = {perturb!r}: expected a table of "
                          "{key = {relative = ...} or {absolute = ...}}")
    perturb = flatten(perturb, "seeds.perturb", source, stop=lambda v: any(k in v for k in PERTURB_KEYS))
    keys = t.get("keys", ["run.seed"] if not perturb else [])
    if not isinstance(keys, list) or not all(isinstance(k, str) for k in keys):
        raise ConfigError(f"{source}: seeds.keys = {keys!r}: expected a list of dotted keys "
                          "(e.g. [\"run.seed\", \"forcing.wind.seed\"])")
    if not keys and not perturb:
        raise ConfigError(f"{source}: [seeds] needs keys (seeded keys) or perturb (perturbed keys)")
    base_cfg = member_config(base, common, parent) if perturb else None
    rules = {}
    for key, rule in perturb.items():
        if not isinstance(rule, dict):
            raise ConfigError(f"{source}: seeds.perturb.{key} = {rule!r}: expected a table "
                              "{relative = 0.1} or {absolute = 500.0} (and distribution = 'normal'|'uniform')")
        bad = set(rule) - set(PERTURB_KEYS)
        if bad:
            raise ConfigError(f"{source}: seeds.perturb.{key}: unknown keys {sorted(bad)}; known: {list(PERTURB_KEYS)}")
        if ("relative" in rule) == ("absolute" in rule):
            raise ConfigError(f"{source}: seeds.perturb.{key}: give exactly one of relative or absolute")
        amp = rule.get("relative", rule.get("absolute"))
        if isinstance(amp, bool) or not isinstance(amp, (int, float)) or not amp > 0:
            raise ConfigError(f"{source}: seeds.perturb.{key}: amplitude {amp!r} must be a number > 0")
        dist = rule.get("distribution", "normal")
        if dist not in DISTRIBUTIONS:
            raise ConfigError(f"{source}: seeds.perturb.{key}.distribution = {dist!r}: "
                              f"expected one of {list(DISTRIBUTIONS)}")
        value = _get(base_cfg, key)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{source}: seeds.perturb.{key}: the base value {value!r} is not a number "
                              "(only numeric keys can be perturbed)")
        rules[key] = (float(value), "relative" in rule, float(amp), dist)
    width = max(3, len(str(n - 1)))
    out = []
    for k in range(n):
        rng = np.random.default_rng([master, k])
        own = {key: int(rng.integers(0, 2**31 - 1)) for key in keys}
        for key, (value, relative, amp, dist) in rules.items():
            z = rng.standard_normal() if dist == "normal" else rng.uniform(-1.0, 1.0)
            own[key] = value * (1.0 + amp * z) if relative else value + amp * z
        out.append((f"s{k:0{width}d}", own))
    return out


def _get(cfg: dict, dotted: str):
    node = cfg
    for p in dotted.split("."):
        if not isinstance(node, dict) or p not in node:
            raise ConfigError(f"{dotted}: no such key in the base scene")
        node = node[p]
    return node


# -- configs ---------------------------------------------------------------------------
def member_config(base, overrides: dict, parent=None) -> dict:
    """The validated scene config of a member, with the checks ``lagice run`` and
    ``lagice branch`` make before any work: ``load_scene(base, overrides)`` and
    :func:`~lagice.scenes.builder.validate_config` (every table, forcing keywords and
    gridded forcing files included); for a member branched from a checkpoint
    (``parent`` = (path, metadata, SHA-256)),
    :func:`~lagice.scenes.builder.branch_config` (the checkpoint's config with the
    overrides; domain, initial state, time step and start date cannot change)."""
    from ..scenes.builder import branch_config, validate_config
    from ..scenes.config import load_scene

    if parent is None:
        cfg = load_scene(base, overrides)
        validate_config(cfg)
        return cfg
    path, meta, sha = parent
    return branch_config(path, meta, overrides, sha256=sha)


def parse_analysis(t: dict, source: str) -> dict:
    if not isinstance(t, dict):
        raise ConfigError(f"{source}: [analysis] must be a table")
    out = dict(ANALYSIS_DEFAULTS)
    for k, v in t.items():
        if k not in ANALYSIS_DEFAULTS:
            raise ConfigError(f"{source}: unknown key analysis.{k}; known keys: {list(ANALYSIS_DEFAULTS)}")
        out[k] = v
    if out["window"] is not None:
        out["window_s"] = parse_duration(out["window"], "analysis.window")
    else:
        out["window_s"] = None
    w = out["windows"]
    if not isinstance(w, int) or isinstance(w, bool) or w < 1:
        raise ConfigError(f"{source}: analysis.windows = {w!r}: expected an integer >= 1")
    b = out["coast_buffer_km"]
    if isinstance(b, bool) or not isinstance(b, (int, float)) or not b >= 0:
        raise ConfigError(f"{source}: analysis.coast_buffer_km = {b!r}: expected a distance >= 0 km")
    return out


def parse_cluster(t: dict, source: str) -> dict:
    if not isinstance(t, dict):
        raise ConfigError(f"{source}: [cluster] must be a table")
    out = dict(t)
    kind = out.setdefault("kind", "local")
    if kind not in CLUSTER_KINDS:
        raise ConfigError(f"{source}: cluster.kind = {kind!r}: expected one of {list(CLUSTER_KINDS)}")
    if kind == "address" and not isinstance(out.get("address"), str):
        raise ConfigError(f"{source}: cluster.kind = 'address' needs cluster.address = 'tcp://HOST:PORT'")
    for k in ("workers", "jobs", "threads_per_member"):
        v = out.get(k)
        if v is not None and (not isinstance(v, int) or isinstance(v, bool) or v < 1):
            raise ConfigError(f"{source}: cluster.{k} = {v!r}: expected an integer >= 1")
    return out
