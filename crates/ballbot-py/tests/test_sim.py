"""The planar simulator and the PIPTB experiment from Python, and reading their MCAP logs
back into numpy arrays."""

from pathlib import Path

import numpy as np
import pytest

import ballbot

SCENARIO = """
seed = 7
duration_secs = 2.0
[friction]
stiction_torque_nm = 0.5
coulomb_torque_nm = 0.35
[controller]
kind = "lqr_pi"
[command]
kind = "piptb"
"""


def test_scenario_runs_and_its_log_reads_back(tmp_path: Path) -> None:
    scenario = ballbot.Scenario.from_toml(SCENARIO)
    assert scenario.seed == 7 and scenario.controller == "lqr_pi"
    log = tmp_path / "run.mcap"
    run = scenario.run(log_path=log)
    n = run.time_secs.size
    assert n == pytest.approx(2.0 * 400, abs=2)
    assert run.state.shape == (n, 4) and run.command.shape == (n, 3)
    assert run.fault is None and run.end_time_secs == pytest.approx(2.0)
    assert Path(run.log_path) == log
    # Deterministic: the same seed gives the same trajectory.
    assert np.array_equal(scenario.run().state, run.state)
    read = ballbot.McapLog(log)
    assert read.is_complete and read.message_count > 0
    topics = read.topics()
    assert topics and all(isinstance(t, str) for t in topics)
    counts = {c["topic"]: c["message_count"] for c in read.channels()}
    busiest = max(counts, key=lambda t: counts[t])
    series = read.numeric_series(busiest)
    assert series["time_secs"].shape == (counts[busiest],)
    assert all(v.shape == series["time_secs"].shape for v in series.values())
    times, messages = read.messages(busiest)
    assert len(messages) == times.size == counts[busiest]


def test_piptb_experiment_returns_the_reports_numbers(tmp_path: Path) -> None:
    result = ballbot.piptb_experiment(quick=True, log_dir=tmp_path)
    c = result.controllers
    assert set(c) == {"lqr", "pi_pd", "lqr_pi"}
    for entry in c.values():
        assert np.isfinite(entry["j_p"]) and entry["j_p"] > 0.0
        assert entry["j_p_n2mm2s"] == pytest.approx(entry["j_p"] * 1e6)
        assert isinstance(entry["stopped_all"], bool)
        assert len(entry["trials"]) == 1
    # The paper's numbers travel with the result (it gives none for the LQR).
    assert c["lqr_pi"]["paper_j_p_n2mm2s"] == pytest.approx([8.2e5, 0.2e5])
    assert c["pi_pd"]["paper_stopped"] is False and c["lqr"]["paper_j_p_n2mm2s"] is None
    # Seeded: the same call gives the same effort.
    again = ballbot.piptb_experiment(quick=True, controllers=["lqr_pi"])
    assert again.controllers["lqr_pi"]["j_p"] == c["lqr_pi"]["j_p"]
    trial = c["lqr_pi"]["trials"][0]
    assert trial["series"]["time_secs"].shape == trial["series"]["torque_nm"].shape
    assert Path(trial["log_path"]).exists()
    assert result.brake_end_secs - result.brake_start_secs == pytest.approx(1.4)


def test_piptb_until_stopped_reads_the_same_trials_to_the_stop() -> None:
    # The same numbers as the Rust reading (scripts/reference/reproduce-quick-summary.json,
    # `piptb_until_stopped`): PI-PD ends the fixed window at -0.17 m/s and stops 50 ms later.
    result = ballbot.piptb_experiment(quick=True)
    fixed, until = result.controllers, result.controllers_until_stopped
    assert set(until) == set(fixed)
    t3_fixed = result.brake_end_secs
    for key in fixed:
        f, u = fixed[key]["trials"][0], until[key]["trials"][0]
        assert set(u) == set(f)
        assert f["t3_secs"] == pytest.approx(t3_fixed) and not f["t3_capped"]
        # The running effort at the until-stopped t3 is its J_P; longer phase, more effort.
        s = u["series"]
        k = int(np.argmin(np.abs(s["time_secs"] - u["t3_secs"])))
        assert u["j_p"] == s["effort_n2m2s"][k]
        if not f["stopped"]:
            assert u["t3_secs"] > t3_fixed and u["j_p"] >= f["j_p"]
    assert until["pi_pd"]["trials"][0]["t3_secs"] - t3_fixed == pytest.approx(0.05)
    # A hold longer than the run leaves cannot be confirmed: capped, not stopped.
    capped = ballbot.piptb_experiment(quick=True, controllers=["lqr"], stop_hold_secs=5.0)
    trial = capped.controllers_until_stopped["lqr"]["trials"][0]
    assert trial["t3_capped"] and not trial["stopped"]
    with pytest.raises(ballbot.ParameterError, match="stop.hold_secs"):
        ballbot.piptb_experiment(quick=True, stop_hold_secs=-1.0)


def test_bad_scenarios_and_logs_raise_documented_errors(tmp_path: Path) -> None:
    with pytest.raises(ballbot.ParameterError, match="stiction_nm"):
        ballbot.Scenario.from_toml('[controller]\nkind = "lqr"\n[friction]\nstiction_nm = 1.0')
    with pytest.raises(ballbot.FileError, match="missing.toml"):
        ballbot.Scenario.load(tmp_path / "missing.toml")
    with pytest.raises(ballbot.ParameterError, match="unknown controller `mpc`"):
        ballbot.piptb_experiment(quick=True, controllers=["mpc"])
    with pytest.raises(ballbot.FileError, match="missing.mcap"):
        ballbot.McapLog(tmp_path / "missing.mcap")
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"not an mcap file at all")
    with pytest.raises(ballbot.FileError, match="garbage.mcap"):
        ballbot.McapLog(garbage)
    log = tmp_path / "ok.mcap"
    ballbot.Scenario.from_toml(SCENARIO.replace("2.0", "0.1")).run(log_path=log)
    with pytest.raises(ballbot.ParameterError, match="no channel with topic /nope"):
        ballbot.McapLog(log).numeric_series("/nope")
    # A truncated log (a killed writer) is recovered, not an error.
    data = log.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    partial = ballbot.McapLog(cut)
    assert not partial.is_complete and partial.stop_reason
