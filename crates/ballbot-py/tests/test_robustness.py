"""The reliability campaign from Python: typed results from the same record as
``ballbot robustness``'s robustness.json, run without the GIL."""

import json
from pathlib import Path

import ballbot
from ballbot.studies import FaultCell, Robustness, robustness


def test_quick_campaign_returns_typed_results_matching_the_json(tmp_path: Path) -> None:
    result = robustness(tmp_path, quick=True, seed=3)
    assert isinstance(result, Robustness)
    assert result.quick and result.seed == 3
    matrix = result.fault_matrix
    assert len(matrix.cells) == 102
    assert all(isinstance(c, FaultCell) for c in matrix.cells)
    # Every faulted run wrote a log that reads back whole.
    assert matrix.logs_read_back_whole == 102
    assert all(c.log is not None and c.log.path.exists() for c in matrix.cells)
    # A silent IMU ends in a protective stop at the 20 ms stale timeout, in every condition.
    stale = [c for c in matrix.cells if c.fault == "imu_stale"]
    assert stale and all(c.observed == "protective_stop" for c in stale)
    assert all(c.time_to_detect_ms is not None and 20.0 <= c.time_to_detect_ms < 22.5 for c in stale)
    assert all(c.seed == 3 for c in matrix.cells)
    # The same record as the file written next to the logs.
    written = json.loads((tmp_path / "robustness.json").read_text())
    assert written["fault_matrix"]["summary"]["as_expected"] == matrix.as_expected
    assert matrix.to_dict()["cells"][0]["fault"] == written["fault_matrix"]["cells"][0]["class"]
    # Monte Carlo: both controllers, each run re-runnable from its printed seed.
    assert set(result.monte_carlo) == {"paper", "design"}
    mc = result.monte_carlo["design"]
    assert mc.runs == 6 and 0.0 <= mc.recovery_rate <= 1.0
    assert mc.recovery_rate == written["monte_carlo"]["recovery_rate"]
    assert mc.recovery_rate_ci95[0] <= mc.recovery_rate <= mc.recovery_rate_ci95[1]
    assert len({r.seed for r in mc.all_runs}) == 6
    assert all(0.8 <= r.mismatch.com_height <= 1.2 for r in mc.all_runs)
    # Counted by falls (the slip and lift-off stop rules relaxed): the same runs, never fewer
    # staying up than by the stop rules.
    assert set(result.monte_carlo_by_falls) == {"paper", "design"}
    falls = result.monte_carlo_by_falls["design"]
    assert [r.seed for r in falls.all_runs] == [r.seed for r in mc.all_runs]
    assert falls.stayed_up >= mc.stayed_up
    assert falls.recovery_rate == written["monte_carlo"]["recovery_rate_by_falls"]
    # Fuzzing: the CI size, no panic, no bad command (seed 3 as well as the test command's
    # seed 1), and the bad commands are those of the bad-command invariants, as in the JSON.
    assert result.fuzz.outer_steps >= 100_000
    assert result.fuzz.panics == 0
    assert result.fuzz.bad_commands == 0, result.fuzz.invariants
    assert result.fuzz.bad_commands == written["fuzz"]["bad_commands"]
    assert result.fuzz.bad_commands == sum(
        i["breaks"] for i in result.fuzz.invariants if i["class"] == "bad_command"
    )
    # Each invariant names the hardening item it checks (0: the campaign's first invariants).
    assert all(
        {"key", "item", "class", "what", "breaks"} <= set(i) for i in result.fuzz.invariants
    )
    assert {i["item"] for i in result.fuzz.invariants} == set(range(10))
    assert [i["item"] for i in result.fuzz.invariants] == [
        i["item"] for i in written["fuzz"]["invariants"]
    ]
    assert 0 < result.fuzz.traction_on_episodes < result.fuzz.episodes
    assert result.fuzz.parsers["panics"] == 0


def test_bad_output_folder_is_a_file_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    try:
        robustness(blocker / "sub", quick=True)
    except ballbot.FileError as e:
        assert "sub" in str(e)
    else:
        raise AssertionError("expected a FileError")
