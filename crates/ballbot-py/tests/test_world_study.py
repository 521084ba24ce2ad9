"""The 3D world's experiments from Python: the maximum-speed study's entry points (the numbers
of docs/world.md) and the MCAP log of a world run (what `ballbot world` writes)."""

from pathlib import Path

import numpy as np
import pytest

import ballbot


def test_failing_acceleration_towards_ow1_is_1_75() -> None:
    # docs/world.md: towards OW1 the ramp survives 1.75 m/s^2 and OW2/OW3 slip from 1.8.
    found = ballbot.failing_acceleration(
        heading_deg=0.0, accel_bracket_m_per_s2=(1.5, 2.0), accel_resolution_m_per_s2=0.05
    )
    assert found["largest_surviving_m_per_s2"] == pytest.approx(1.75)
    assert found["smallest_failing_m_per_s2"] == pytest.approx(1.8)
    assert found["text"] == "1.75" and not found["censored"] and found["runs"] >= 3
    failing = found["failing"]
    assert failing is not None and failing["failure"] is not None
    assert failing["failure"].kind == "sustained_slip" and failing["failure"].wheel in (1, 2)
    run = found["failing_run"]
    assert run is not None and run["failure"] == failing["failure"]
    surviving = found["surviving"]
    assert surviving is not None and surviving["censored"]
    assert surviving["peak_cone_utilisation"] < 1.0


def test_slow_ramp_trial_is_seeded_and_reports_its_outcome() -> None:
    a = ballbot.slow_ramp_trial(heading_deg=180.0, seed=2)
    b = ballbot.slow_ramp_trial(heading_deg=180.0, seed=2)
    assert np.array_equal(a["speed_m_per_s"], b["speed_m_per_s"])
    outcome = a["outcome"]
    assert outcome["seed"] == 2 and outcome["accel_m_per_s2"] == 0.25
    assert outcome["max_speed_m_per_s"] == a["max_speed_m_per_s"] > 2.0
    assert outcome["censored"] == (a["failure"] is None)
    assert outcome["min_normal_force_n"] == pytest.approx(float(np.min(a["normal_force_n"])))


def test_max_speed_study_returns_the_summary_record() -> None:
    study = ballbot.max_speed_study(
        quick=True,
        trial_headings_deg=[180.0],
        map_headings_deg=[180.0],
        accel_bracket_m_per_s2=(2.0, 2.4),
        accel_resolution_m_per_s2=0.2,
    )
    assert study["protocol"]["seeds"] == [1]
    assert [t["heading_deg"] for t in study["trials"]] == [180.0]
    trial = study["trials"][0]["trials"][0]
    assert study["max_speed_by_heading"]["180"] == trial["max_speed_m_per_s"]
    series = study["first_runs"][180.0]
    assert series["max_speed_m_per_s"] == trial["max_speed_m_per_s"]
    assert series["normal_force_n"].shape == (series["time_s"].size, 3)
    assert "180" in study["table"]
    assert study["sensitivity"] == [] and len(study["map"]) == 1


def test_world_runs_write_mcap_logs_that_read_back(tmp_path: Path) -> None:
    path = tmp_path / "loop.mcap"
    sim = ballbot.WorldLoop()
    run = sim.run(800, [0.3, 0.0, 0.0], log_path=path)
    assert Path(run["log_path"]) == path
    log = ballbot.McapLog(path)
    assert log.is_complete
    counts = {c["topic"]: c["message_count"] for c in log.channels()}
    telemetry = max(counts, key=lambda t: counts[t])
    assert counts[telemetry] == 800, counts
    assert sum(1 for t in counts if counts[t] == 800 // 20) >= 1, "the 400 Hz controller"
    series = log.numeric_series(telemetry)
    assert series["time_secs"].shape == (800,)
    compact = tmp_path / "open.mcap"
    world = ballbot.World()
    out = world.run(800, log_path=compact, log_compact=True)
    assert Path(out["log_path"]) == compact
    counts = {c["topic"]: c["message_count"] for c in ballbot.McapLog(compact).channels()}
    assert max(counts.values()) == 100, counts
    assert world.run(10)["log_path"] is None


def test_bad_study_input_raises_documented_errors(tmp_path: Path) -> None:
    with pytest.raises(ballbot.ParameterError, match="accel_bracket_m_per_s2"):
        ballbot.failing_acceleration(accel_bracket_m_per_s2=(2.0, 1.0))
    with pytest.raises(ballbot.ParameterError, match="accel_resolution_m_per_s2"):
        ballbot.failing_acceleration(accel_resolution_m_per_s2=0.0)
    with pytest.raises(ballbot.ParameterError, match="fast_top_m_per_s"):
        ballbot.max_speed_study(quick=True, fast_top_m_per_s=float("nan"))
    with pytest.raises(ballbot.ParameterError, match="seeds"):
        ballbot.max_speed_study(quick=True, seeds=[])
    with pytest.raises(ballbot.ParameterError, match="sensitivity_mu"):
        ballbot.max_speed_study(quick=True, sensitivity_mu=[float("inf")])
    with pytest.raises(ballbot.FileError, match="missing"):
        ballbot.World().run(10, log_path=tmp_path / "missing" / "dir" / "x.mcap")
