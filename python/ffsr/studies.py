"""Studies in shards: a map (Scenario.map) or a Monte Carlo run (Scenario.robust) cut into parts that run
anywhere -- processes, Dask workers, cluster jobs -- and the parts merged as ffsr-optimize merges them,
to the bit. The shard functions take and return plain values (a scenario path and keywords in; numpy
arrays, dicts, the command's JSON text out), which a scheduler pickles to another process or machine.
docs/python.md, "Studies on a cluster", shows them on Dask.
"""

from __future__ import annotations

import dataclasses
import json
import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Union

import numpy as np

__all__ = ["MapPart", "map_shard", "merge_map", "robust_shard", "merge_robust"]

# the keys of a map's --json that every part of one map shares (the rest: its shard and its extremes)
_MAP_GRID_KEYS = ("urdf", "joints_deg", "contact_joints", "axes", "points", "version")


@dataclasses.dataclass
class MapPart:
    """Rows [first, end) of a map of `points` points, in the grid's numbering (Scenario.map's arrays).

    summary: the command's --json of these rows (``MapResult.to_dict()``): the grid, the shard and the
    extremes of M_ie among the rows. A merged map (merge_map) is one part holding every row.
    """

    first: int
    end: int
    points: int
    angles_deg: np.ndarray
    M_ie: np.ndarray
    f_max: np.ndarray
    summary: Dict[str, Any]


def _scenario(path: Union[str, os.PathLike], overrides: Optional[Mapping[str, Any]]):
    from . import Scenario  # the compiled extension: needed on the worker, not to import this module

    return Scenario.load(os.fspath(path), **dict(overrides or {}))


def map_shard(scenario: Union[str, os.PathLike], vary: Iterable[int], shard_k: int, shard_n: int, *,
              overrides: Optional[Mapping[str, Any]] = None, threads: int = 1, **options: Any) -> MapPart:
    """Part K of N of the map (``ffsr-optimize map --config FILE --vary ... --shard K/N``).

    scenario: the scenario file (read where the call runs); overrides: Scenario.load's keywords (the
    command's flags, e.g. ``{"joints_deg": [...]}``); options: Scenario.map's (range_deg, step_deg,
    max_points). threads: 1 by default, one part per worker thread (the values do not depend on it).
    """
    sc = _scenario(scenario, overrides)
    r = sc.map(list(vary), shard_k=shard_k, shard_n=shard_n, threads=threads, **options)
    return MapPart(int(r.first), int(r.end), int(r.points), np.array(r.angles_deg), np.array(r.M_ie),
                   np.array(r.f_max), r.to_dict())


def _check_cover(spans: List[tuple], total: int, what: str, name: str) -> None:
    """spans: (first, end) sorted by first; ValueError naming a gap, an overlap or a short cover."""
    nxt = 0
    for first, end in spans:
        if first > nxt:
            raise ValueError(f"{name}: {what} {nxt} to {first} are missing")
        if first < nxt:
            raise ValueError(f"{name}: {what} {first} to {min(nxt, end)} are in two parts")
        nxt = end
    if nxt != total:
        raise ValueError(f"{name}: the parts cover {what} 0 to {nxt} of {total}")


def merge_map(parts: Iterable[MapPart]) -> MapPart:
    """The whole map from its parts (any order): the rows concatenated in the grid's numbering, as the
    command's parts concatenated in the order 0..N-1 make the whole --csv, and the summary (--json) of
    one run over the whole grid: its extremes are the largest and smallest of the parts' (the first
    point on a tie, as one run). ValueError when the parts are not of one grid, or leave gaps or overlap.
    """
    ps = sorted(parts, key=lambda p: p.first)
    if not ps:
        raise ValueError("merge_map: no part to merge")
    head = ps[0].summary
    for p in ps:
        for key in _MAP_GRID_KEYS:
            if p.summary.get(key) != head.get(key):
                raise ValueError(f"merge_map: the parts differ in '{key}': they are not parts of one map")
        if p.points != ps[0].points or p.M_ie.shape != (p.end - p.first,):
            raise ValueError("merge_map: a part's rows do not match its span [first, end)")
    _check_cover([(p.first, p.end) for p in ps], ps[0].points, "points", "merge_map")
    summary = {k: head[k] for k in _MAP_GRID_KEYS if k in head}
    summary["shard"] = {"k": 0, "n": 1, "first": 0, "end": ps[0].points}
    held = [p.summary for p in ps if "max" in p.summary]  # an empty part has no extremes
    if held:  # strict comparisons in the grid's order: the first point wins a tie, as in one run
        hi, lo = held[0], held[0]
        for s in held[1:]:
            if s["max"]["integrated_effective_mass"] > hi["max"]["integrated_effective_mass"]:
                hi = s
            if s["min"]["integrated_effective_mass"] < lo["min"]["integrated_effective_mass"]:
                lo = s
        summary["max"], summary["min"] = hi["max"], lo["min"]
    return MapPart(0, ps[0].points, ps[0].points, np.concatenate([p.angles_deg for p in ps]),
                   np.concatenate([p.M_ie for p in ps]), np.concatenate([p.f_max for p in ps]), summary)


def robust_shard(scenario: Union[str, os.PathLike], shard_k: int, shard_n: int, *,
                 overrides: Optional[Mapping[str, Any]] = None, **options: Any) -> str:
    """Shard K of N of the Monte Carlo run (``ffsr-optimize robust --config FILE --shard K/N``): the
    command's --json of the shard, as text (every sample's F_max by index, what merge_robust needs).

    overrides: Scenario.load's keywords (``{"global": False}``); options: Scenario.robust's (samples,
    seed, force_model, threads, capture_joints_deg, ...).
    """
    return _scenario(scenario, overrides).robust(shard_k=shard_k, shard_n=shard_n, **options).to_json()


def merge_robust(parts: Iterable[Any]) -> Dict[str, Any]:
    """The summary of the shards together (any order), as ``ffsr-optimize robust --merge`` makes it (the
    library's merge_shards, through ffsr.merge_robust_shards): the samples concatenated by index and the
    percentiles, mean and tail computed again, those of the unsharded run to the bit. Returns the
    merged --json as a dict.

    parts: each shard's --json as text (robust_shard), as a dict, or a RobustResult. ffsr.InputError (a
    ValueError) when the shards are not of one run (seed, samples, laws, scenario) or leave gaps or
    overlaps.
    """
    import ffsr

    texts = []
    for p in parts:
        if hasattr(p, "to_json"):
            p = p.to_json()
        texts.append(p if isinstance(p, str) else json.dumps(p))
    if not texts:
        raise ValueError("merge_robust: no shard to merge")
    try:
        return ffsr.merge_robust_shards(texts).to_dict()
    except ffsr.InputError as e:
        raise ffsr.InputError(f"merge_robust: {e}") from None
