"""Sweeps: many independent solves of one flowsheet, in this process (rayon, the GIL released)
or, given ``client=`` (a ``dask.distributed.Client``), one task per point on that cluster.

A task carries the flowsheet's text and its own ``set`` assignments (picklable strings); the
worker loads the plant and calls the same library function as in-process, so the results do not
depend on where they ran: they equal ``plantwide steady --json --set …`` bit for bit."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from . import _plantwide as _native
from .plant import Plant, _answer, assignments, load


def _source(flowsheet: str | os.PathLike | Plant) -> tuple[str, str]:
    """The flowsheet's text and name, read once here (a worker needs no access to the file)."""
    plant = flowsheet if isinstance(flowsheet, Plant) else load(flowsheet)
    return plant.text, plant.file


def _steady_task(text: str, name: str, sets: list[str], outputs: list[str], method: str) -> list[float]:
    """One sweep point (runs on a worker)."""
    return _native.sweep(text, name, [sets], outputs, method)[0]


def _gather(client, fn, argument_lists: list[tuple]) -> list:
    """Submit ``fn(*args)`` for each argument tuple to ``client`` and gather the results in order
    (a failed task raises its exception here)."""
    futures = [client.submit(fn, *args, pure=False) for args in argument_lists]
    return client.gather(futures)


def sweep(
    path: str | os.PathLike | Plant,
    sets: Sequence[Mapping[str, Any]],
    outputs: Sequence[str],
    client=None,
    method: str = "auto",
) -> np.ndarray:
    """The steady value (SI) of each of ``outputs`` for each ``set`` dict: an array of
    ``len(sets) × len(outputs)``, rows in the order of ``sets``. Each point is one independent
    task; with ``client`` the tasks run on that Dask cluster, otherwise in parallel here."""
    text, name = _source(path)
    outputs = list(outputs)
    point_sets = [assignments(s) for s in sets]
    if client is None:
        rows = _native.sweep(text, name, point_sets, outputs, method)
    else:
        rows = _gather(client, _steady_task, [(text, name, s, outputs, method) for s in point_sets])
    return np.array(rows, dtype=float).reshape(len(point_sets), len(outputs))


def _sensitivity_task(text: str, name: str, sets: list[str], disturb: str, outputs: list[str], points: int) -> dict:
    """One disturbance's curve (runs on a worker)."""
    return _native.sensitivity(text, name, sets, [disturb], outputs, points)[0]


def sensitivity(
    path: str | os.PathLike | Plant,
    disturb: Sequence[str],
    outputs: Sequence[str],
    points: int = 21,
    *,
    set: Mapping[str, Any] | None = None,
    client=None,
) -> list[dict]:
    """``plantwide sensitivity``: each disturbance ``PATH=LOW:HIGH`` swept by continuation with the
    control structure active. One curve per disturbance, each a dict with ``path``, ``base``,
    ``values`` (SI), ``outputs`` (points × outputs, NaN where a point did not converge),
    ``output_paths`` and ``failures``. Each disturbance is one task (on ``client`` if given)."""
    text, name = _source(path)
    sets, outputs, disturb = assignments(set), list(outputs), list(disturb)
    if client is None:
        curves = _native.sensitivity(text, name, sets, disturb, outputs, points)
    else:
        curves = _gather(client, _sensitivity_task, [(text, name, sets, d, outputs, points) for d in disturb])
    for c in curves:
        c["values"] = np.array(c["values"], dtype=float)
        c["outputs"] = np.array([[np.nan] * len(outputs) if y is None else y for y in c["outputs"]], dtype=float)
    return curves


def _screen_task(text: str, name: str, sets: list[str], column: str, outputs: list[str]) -> dict:
    """One operating point's screening (runs on a worker)."""
    request = json.dumps({"column": column, "outputs": outputs, "steady_only": True})
    return _answer(*_native.screen(text, name, sets, request))


def screen(
    path: str | os.PathLike | Plant,
    column: str,
    outputs: Sequence[str],
    sets: Sequence[Mapping[str, Any]] | None = None,
    client=None,
) -> list[dict]:
    """``plantwide screen --column --steady-only --json`` at each operating point of ``sets``
    (default: the file's own): the column's inventory configurations ranked by their steady-state
    measures (the CLI's fast path; its default also runs the dynamic check), one dict per point
    (the CLI's JSON). Each point is one task (on ``client`` if given)."""
    text, name = _source(path)
    point_sets = [assignments(s) for s in (sets if sets is not None else [{}])]
    args = [(text, name, s, column, list(outputs)) for s in point_sets]
    if client is None:
        return [_screen_task(*a) for a in args]
    return _gather(client, _screen_task, args)


def _pairing_shard_task(text: str, name: str, sets: list[str], args: str, shard: tuple[int, int]) -> dict:
    """One shard of a pairing screen's dynamic tests (runs on a worker)."""
    return json.loads(_native.screen(text, name, sets, args, shard)[0])


def screen_pairings(
    path: str | os.PathLike | Plant,
    cvs: Sequence[str],
    mvs: Sequence[str],
    *,
    throughput: Sequence[str] = (),
    disturbances: Sequence[str] = (),
    candidates: int = 4,
    duration: str | None = None,
    measurement_dead_time: str = "1 min",
    set: Mapping[str, Any] | None = None,
    client=None,
) -> dict:
    """``plantwide screen --cvs … --mvs … --json``: the pairings of ``cvs`` to ``mvs`` filtered at
    steady state and the best ``candidates`` tested dynamically (each disturbance ``PATH`` or
    ``PATH=±x%`` stepped on the nonlinear plant). With ``client``, the dynamic tests are split
    into one shard per worker (as ``--shard I/N``), run on the cluster, and scored together here
    (as ``plantwide merge``): the result equals the one-process screen."""
    text, name = _source(path)
    sets = assignments(set)
    args = json.dumps(
        {
            "cvs": list(cvs),
            "mvs": list(mvs),
            "throughput": list(throughput),
            "disturbances": list(disturbances),
            "candidates": int(candidates),
            "measurement_dead_time": measurement_dead_time,
            **({} if duration is None else {"duration": duration}),
        }
    )
    if client is None or not disturbances:
        return _answer(*_native.screen(text, name, sets, args))
    n = max(1, min(int(candidates), len(client.scheduler_info()["workers"])))
    parts = _gather(client, _pairing_shard_task, [(text, name, sets, args, (i, n)) for i in range(n)])
    merged: dict[str, Any] = {}
    for p in parts:
        merged.update(p["results"])
    tasks = parts[0]["tasks"]
    if sorted(int(t) for t in merged) != list(range(tasks)):
        raise RuntimeError(f"screen_pairings: the shards returned tasks {sorted(merged)} of {tasks}")
    return _answer(*_native.screen(text, name, sets, args, None, json.dumps(merged)))
