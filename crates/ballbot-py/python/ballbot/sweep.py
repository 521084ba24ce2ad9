"""Parameter sweeps on any ``concurrent.futures.Executor``: a laptop's threads by default, a Dask
cluster (``client.get_executor()``) or a Ray pool without changing the study.

A sweep calls a *study function* once per point. A point sets keyword arguments of the study
and, for keys starting with ``params.``, fields of a parameter object (``WorldParams``,
``BallbotParams``, ...) given as ``params``: ``"params.robot.drivetrain.wheel_ball_friction"``
replaces that field and passes the result as the study's ``params`` argument. Braces set
several fields to one value: ``"params.robot.{sagittal,frontal}.com_height_m"``.

The points are a grid (the cartesian product, the last key varying fastest) or ``n`` seeded
uniform random samples of ranges. The study returns a mapping (or a dataclass) of values;
the result is a table, ``SweepResult``: a columnar dict of numpy arrays, one row per point,
the point's columns first. Numbers become float or int columns, anything else (``None``,
strings, arrays of differing shape) an object column.

>>> from ballbot import WorldParams
>>> from ballbot.sweep import run
>>> def study(params, gain):
...     return {"mu_times_gain": params.robot.drivetrain.wheel_ball_friction * gain}
>>> table = run(study, params=WorldParams(),
...             grid={"params.robot.drivetrain.wheel_ball_friction": [0.5, 1.0], "gain": [2.0, 3.0]},
...             progress=False)
>>> table["mu_times_gain"].tolist()
[1.0, 1.5, 2.0, 3.0]

Resume: with ``cache_dir`` every finished point is written there at once (one pickle file per
point, named by a hash of the study's module and qualified name, the parameters and the
point); a later call with the same arguments skips the points found on disk. The name is what
identifies the study: give each study its own named function (two lambdas of one module share
the name ``<lambda>``), and a new directory after changing what a study computes.

The Rust studies release the GIL, so the default thread pool runs them on every core. For a
process pool, Dask or Ray the study, the parameters and the results must pickle: every
parameter and result class of ``ballbot`` does.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import hashlib
import itertools
import os
import pickle
import re
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence, Union

import numpy as np
from numpy.typing import NDArray

__all__ = ["SweepResult", "grid_points", "run", "sample_points"]

_PARAMS = "params."


@dataclasses.dataclass(frozen=True)
class SweepResult:
    """A sweep's table: ``columns`` maps each point key, then each result key, to an array with
    one row per point (in the order of the points). ``table["key"]`` reads a column."""

    columns: dict[str, NDArray[Any]]
    """The columns."""
    points: list[dict[str, Any]]
    """The points, in order."""
    seed: Optional[int]
    """The sampling seed (random samples), else ``None``."""
    wall_secs: float
    """Wall time of the call (s)."""
    resumed: int
    """Points read from ``cache_dir`` instead of run."""

    def __getitem__(self, key: str) -> NDArray[Any]:
        return self.columns[key]

    def __len__(self) -> int:
        return len(self.points)

    def keys(self) -> list[str]:
        """The column names."""
        return list(self.columns)


def grid_points(grid: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """The cartesian product of ``grid``'s values, the last key varying fastest."""
    keys = list(grid)
    for k in keys:
        if len(grid[k]) == 0:
            raise ValueError(f"sweep grid: `{k}` has no values")
    return [dict(zip(keys, values)) for values in itertools.product(*(grid[k] for k in keys))]


def sample_points(
    ranges: Mapping[str, tuple[float, float]], n: int, seed: int
) -> list[dict[str, Any]]:
    """``n`` points, each key uniform in its ``(lo, hi)`` range, from numpy's PCG64 seeded
    ``seed`` (keys drawn in their given order, point after point)."""
    if n < 1:
        raise ValueError(f"sweep samples: n must be >= 1, got {n}")
    for k, (lo, hi) in ranges.items():
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
            raise ValueError(f"sweep samples: `{k}` must be a finite range (lo, hi), lo <= hi")
    rng = np.random.Generator(np.random.PCG64(seed))
    return [
        {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in ranges.items()} for _ in range(n)
    ]


def _expand(path: str) -> list[str]:
    """``a.{b,c}.d`` -> ``["a.b.d", "a.c.d"]`` (one brace group)."""
    m = re.search(r"\{([^{}]*)\}", path)
    if m is None:
        return [path]
    return [path[: m.start()] + alt.strip() + path[m.end() :] for alt in m.group(1).split(",")]


def _nested(fields: Mapping[str, Any]) -> dict[str, Any]:
    """Dotted paths to a nested dict of overrides."""
    out: dict[str, Any] = {}
    for path, value in fields.items():
        for full in _expand(path):
            node = out
            *parents, leaf = full.split(".")
            for p in parents:
                node = node.setdefault(p, {})
                if not isinstance(node, dict):
                    raise ValueError(f"sweep: `{full}` sets a field inside a number")
            node[leaf] = value
    return out


def _call(study: Callable[..., Any], params: Any, point: Mapping[str, Any]) -> Any:
    """Runs the study at one point (module level, so that process pools pickle it by name)."""
    fields = {k[len(_PARAMS) :]: v for k, v in point.items() if k.startswith(_PARAMS)}
    kwargs = {k: v for k, v in point.items() if not k.startswith(_PARAMS)}
    if params is not None:
        kwargs["params"] = params.replace(**_nested(fields)) if fields else params
    elif fields:
        raise ValueError("sweep: `params.` keys need a `params` object to replace fields of")
    return study(**kwargs)


def _record(result: Any) -> dict[str, Any]:
    if dataclasses.is_dataclass(result) and not isinstance(result, type):
        return {f.name: getattr(result, f.name) for f in dataclasses.fields(result)}
    if isinstance(result, Mapping):
        return dict(result)
    raise TypeError(
        f"a sweep's study must return a mapping or a dataclass, got {type(result).__name__}"
    )


def _column(values: list[Any]) -> NDArray[Any]:
    """Numbers to a bool, int or float column; equal-shaped numeric sequences or arrays to a
    stacked (n, ...) array; anything else to an object column."""
    if all(isinstance(v, (bool, np.bool_)) for v in values):
        return np.array(values, dtype=bool)
    if all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in values):
        return np.array(values, dtype=np.int64)
    if all(isinstance(v, (int, float, np.integer, np.floating)) for v in values):
        return np.array(values, dtype=np.float64)
    if all(isinstance(v, (tuple, list, np.ndarray)) for v in values):
        try:
            stacked = np.array(values)
        except ValueError:  # ragged
            stacked = None
        if stacked is not None and stacked.dtype.kind in "biuf" and stacked.ndim > 1:
            return stacked
    column = np.empty(len(values), dtype=object)
    column[:] = values
    return column


def _key(study: Callable[..., Any], params: Any, point: Mapping[str, Any]) -> str:
    name = f"{getattr(study, '__module__', '')}.{getattr(study, '__qualname__', repr(study))}"
    base = params.to_dict() if params is not None and hasattr(params, "to_dict") else params
    text = repr(("ballbot.sweep/1", name, base, sorted(point.items())))
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def _save(path: Path, point: Mapping[str, Any], result: Any) -> None:
    """Writes atomically: a stop mid-write leaves no partial file under the final name."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=".pkl")
    with os.fdopen(fd, "wb") as f:
        pickle.dump({"point": dict(point), "result": result}, f)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _load(path: Path) -> Optional[Any]:
    try:
        with open(path, "rb") as f:
            return pickle.load(f)["result"]
    except (OSError, EOFError, pickle.UnpicklingError, KeyError):
        return None


class _Progress:
    """tqdm when installed, else a line on stderr every few points."""

    def __init__(self, total: int, desc: str, enabled: bool) -> None:
        self.enabled, self.total, self.done, self.desc = enabled, total, 0, desc
        self._bar: Any = None
        if enabled:
            try:
                from tqdm.auto import tqdm  # type: ignore[import-untyped,unused-ignore]

                self._bar = tqdm(total=total, desc=desc, unit="point")
            except ImportError:
                print(f"{desc}: {total} points", file=sys.stderr)
        self._lock = threading.Lock()

    def update(self, n: int = 1) -> None:
        with self._lock:
            self.done += n
            if self._bar is not None:
                self._bar.update(n)
            elif self.enabled and (self.done == self.total or self.done % 10 == 0):
                print(f"{self.desc}: {self.done}/{self.total}", file=sys.stderr)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


def run(
    study: Callable[..., Any],
    *,
    params: Any = None,
    grid: Optional[Mapping[str, Sequence[Any]]] = None,
    samples: Optional[Mapping[str, tuple[float, float]]] = None,
    n: int = 0,
    seed: int = 0,
    executor: Optional[cf.Executor] = None,
    cache_dir: Union[str, "os.PathLike[str]", None] = None,
    progress: bool = True,
) -> SweepResult:
    """Runs ``study`` at every point and returns the table.

    Args:
        study: called as ``study(**kwargs)``, plus ``params=`` when ``params`` is given.
        params: the parameter object whose fields ``params.``-keys replace (its ``replace``).
        grid: a value list per key (the cartesian product), or
        samples: a ``(lo, hi)`` range per key, with ``n`` points drawn with ``seed``.
        executor: where the points run; default a thread pool with one thread per core.
        cache_dir: resume directory (created if missing).
        progress: show a progress bar (tqdm) on stderr.

    Raises the first failing point's exception, with the point added to its message (the
    points finished before it stay in ``cache_dir``).
    """
    if (grid is None) == (samples is None):
        raise ValueError("sweep: give exactly one of `grid` and `samples`")
    points = grid_points(grid) if grid is not None else sample_points(samples or {}, n, seed)
    start = time.perf_counter()
    cache = Path(cache_dir) if cache_dir is not None else None
    if cache is not None:
        cache.mkdir(parents=True, exist_ok=True)
    results: list[Any] = [None] * len(points)
    todo: list[int] = []
    for i, point in enumerate(points):
        found = _load(cache / f"{_key(study, params, point)}.pkl") if cache else None
        if found is None:
            todo.append(i)
        else:
            results[i] = found
    resumed = len(points) - len(todo)
    desc = "sweep" if samples is None else f"sweep (seed {seed})"
    bar = _Progress(len(points), desc, progress)
    bar.update(resumed)
    own = executor is None
    pool = executor or cf.ThreadPoolExecutor(max_workers=os.cpu_count() or 1)
    try:
        futures = {pool.submit(_call, study, params, points[i]): i for i in todo}
        for future in cf.as_completed(futures):
            i = futures[future]
            try:
                results[i] = future.result()
            except Exception as e:
                for f in futures:
                    f.cancel()
                if hasattr(e, "add_note"):  # Python 3.11+
                    e.add_note(f"at sweep point {points[i]}")
                raise
            if cache is not None:
                _save(cache / f"{_key(study, params, points[i])}.pkl", points[i], results[i])
            bar.update()
    finally:
        bar.close()
        if own:
            pool.shutdown(wait=True, cancel_futures=True)
    records = [_record(r) for r in results]
    columns: dict[str, NDArray[Any]] = {}
    for key in points[0]:
        columns[key] = _column([p[key] for p in points])
    for key in records[0] if records else []:
        if key in columns:
            raise ValueError(f"sweep: the study's result key `{key}` is also a point key")
        columns[key] = _column([r.get(key) for r in records])
    return SweepResult(
        columns=columns,
        points=points,
        seed=seed if samples is not None else None,
        wall_secs=time.perf_counter() - start,
        resumed=resumed,
    )
