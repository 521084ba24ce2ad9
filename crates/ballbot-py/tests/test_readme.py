"""The README's Python example runs as written."""

import contextlib
import io
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"
ROOT_README = Path(__file__).resolve().parents[3] / "README.md"


def python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_readme_example_runs_and_prints_the_model_md_numbers() -> None:
    blocks = python_blocks(README.read_text())
    assert blocks, "the README has no ```python block"
    out = io.StringIO()
    namespace: dict[str, object] = {"__name__": "__readme__"}
    with contextlib.redirect_stdout(out):
        for block in blocks:
            exec(compile(block, str(README), "exec"), namespace)
    printed = out.getvalue()
    assert "unstable pole 8.04 rad/s" in printed
    assert "['-234.8', '-45.7', '-3.162']" in printed
    assert "['-19.5', '-4.78', '-2.06']" in printed
    worst = float(re.search(r"worst final tilt (\S+) rad", printed).group(1))  # type: ignore[union-attr]
    assert worst < 1e-3
    assert re.search(r"^True 0\.0\d\d m/s$", printed, flags=re.M), "the braking run stops"


def test_root_readme_python_example_prints_the_model_md_gains() -> None:
    blocks = python_blocks(ROOT_README.read_text())
    assert blocks, "the root README has no ```python block"
    out = io.StringIO()
    namespace: dict[str, object] = {"__name__": "__readme__"}
    with contextlib.redirect_stdout(out):
        for block in blocks:
            exec(compile(block, str(ROOT_README), "exec"), namespace)
    assert "[-234.85, -45.7, -3.16]" in out.getvalue()
