"""The Python examples in examples/python run to completion (short settings)."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "python"


@pytest.mark.parametrize(
    ("script", "args", "expect"),
    [
        ("design_lqr.py", [], "continuous gains k = [-234.849"),
        ("braking_trajectory.py", [], "J = 113.56 N^2 m^2 s"),
        ("heading_sweep.py", ["--step-deg", "90"], "steepest ramp"),
        ("piptb_comparison.py", ["--quick"], "LQR-PI"),
        ("world_heading_sweep.py", ["--step-deg", "120", "--top", "1.0"], "3 headings in"),
        ("sweep_capability_map.py", ["--quick"], "Dask, 2 workers:"),
        (
            "mechanism_failing_accel.py",
            ["--headings", "0", "--resolution", "0.25"],
            "axle_losses |    1.25 / 1.5",
        ),
    ],
)
def test_example_runs(script: str, args: list[str], expect: str, tmp_path: Path) -> None:
    if script in ("piptb_comparison.py", "sweep_capability_map.py"):
        args = [*args, "--out", str(tmp_path)]
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / script), *args],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    assert expect in done.stdout, done.stdout
