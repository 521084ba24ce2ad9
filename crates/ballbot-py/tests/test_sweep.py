"""``ballbot.sweep``: points, columns, resume, errors, and the same results on a thread pool of
one or two threads and on a two-worker Dask ``LocalCluster``, bit for bit."""

import concurrent.futures as cf
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ballbot
from ballbot import studies
from ballbot.sweep import grid_points, run, sample_points

MU = "params.robot.drivetrain.wheel_ball_friction"
COM = "params.robot.{sagittal,frontal}.com_height_m"


def fields(params: ballbot.WorldParams, k: float) -> dict[str, Any]:
    r = params.robot
    return {
        "mu": r.drivetrain.wheel_ball_friction,
        "com": (r.sagittal.com_height_m, r.frontal.com_height_m),
        "k2": k * k,
    }


def failing(params: ballbot.WorldParams, heading_deg: float) -> dict[str, Any]:
    """A module-level study (process pools pickle it by name)."""
    r = studies.failing_acceleration(params, heading_deg=heading_deg)
    return {
        "failing_m_per_s2": r.smallest_failing_m_per_s2,
        "surviving_m_per_s2": r.largest_surviving_m_per_s2,
        "runs": r.runs,
        "text": r.text,
    }


def test_grid_points_are_the_cartesian_product_last_key_fastest() -> None:
    pts = grid_points({"a": [1, 2], "b": ["x", "y", "z"]})
    assert [(p["a"], p["b"]) for p in pts] == [
        (1, "x"), (1, "y"), (1, "z"), (2, "x"), (2, "y"), (2, "z"),
    ]
    with pytest.raises(ValueError, match="`a` has no values"):
        grid_points({"a": []})


def test_samples_are_seeded_and_in_range() -> None:
    a = sample_points({"x": (0.0, 1.0), "y": (-2.0, -1.0)}, 50, seed=4)
    assert a == sample_points({"x": (0.0, 1.0), "y": (-2.0, -1.0)}, 50, seed=4)
    assert a != sample_points({"x": (0.0, 1.0), "y": (-2.0, -1.0)}, 50, seed=5)
    assert all(0 <= p["x"] <= 1 and -2 <= p["y"] <= -1 for p in a)
    with pytest.raises(ValueError, match="finite range"):
        sample_points({"x": (1.0, 0.0)}, 3, seed=0)


def test_params_fields_and_keywords_reach_the_study() -> None:
    table = run(
        fields,
        params=ballbot.WorldParams(),
        grid={MU: [0.4, 0.7], COM: [0.35], "k": [3.0, 4.0]},
        progress=False,
    )
    assert table.keys() == [MU, COM, "k", "mu", "com", "k2"]
    assert table["mu"].tolist() == [0.4, 0.4, 0.7, 0.7]
    assert table["k2"].tolist() == [9.0, 16.0, 9.0, 16.0]
    assert table["com"].shape == (4, 2) and np.all(table["com"] == 0.35)
    assert table.seed is None and len(table) == 4


def test_a_failing_point_raises_and_the_finished_ones_stay_on_disk(tmp_path: Path) -> None:
    with pytest.raises(ballbot.ParameterError, match="wheel_ball_friction"):
        run(fields, params=ballbot.WorldParams(), grid={MU: [0.5, -1.0], "k": [1.0]},
            cache_dir=tmp_path, progress=False, executor=cf.ThreadPoolExecutor(1))
    assert len(list(tmp_path.glob("*.pkl"))) == 1
    with pytest.raises(ValueError, match="exactly one"):
        run(fields, grid={"k": [1.0]}, samples={"k": (0.0, 1.0)}, n=2)


def test_resume_skips_the_points_on_disk(tmp_path: Path) -> None:
    calls: list[float] = []

    def study(k: float) -> dict[str, float]:
        calls.append(k)
        return {"k3": k**3}

    grid = {"k": [1.0, 2.0, 3.0]}
    first = run(study, grid=grid, cache_dir=tmp_path, progress=False)
    assert sorted(calls) == [1.0, 2.0, 3.0] and first.resumed == 0
    again = run(study, grid=grid, cache_dir=tmp_path, progress=False)
    assert len(calls) == 3 and again.resumed == 3
    assert again["k3"].tolist() == first["k3"].tolist()
    next(iter(sorted(tmp_path.glob("*.pkl")))).unlink()
    third = run(study, grid=grid, cache_dir=tmp_path, progress=False)
    assert len(calls) == 4 and third.resumed == 2


def test_threads_and_a_dask_cluster_give_the_same_table_bit_for_bit() -> None:
    import distributed  # the `dask` extra, installed by the test command
    grid = {MU: [0.5, 0.8], "heading_deg": [0.0, 60.0]}
    params = ballbot.WorldParams()
    tables = [
        run(failing, params=params, grid=grid, executor=cf.ThreadPoolExecutor(t), progress=False)
        for t in (1, 2)
    ]
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        tables.append(
            run(failing, params=params, grid=grid, executor=client.get_executor(), progress=False)
        )
    ref = tables[0]
    assert ref["surviving_m_per_s2"].dtype == np.float64  # every bracket had a surviving end
    for other in tables[1:]:
        assert other.keys() == ref.keys()
        for key in ref.keys():
            assert np.array_equal(other[key], ref[key]), key
    # The friction changes the failing acceleration: the study saw the replaced field.
    assert ref["failing_m_per_s2"][0] != ref["failing_m_per_s2"][2]
