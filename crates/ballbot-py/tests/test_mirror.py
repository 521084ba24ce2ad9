"""The generated Python mirror (``ballbot._results``, ``ballbot._enums``) against the Rust
types: the committed schema bundle must be the one the built extension exports (the first
half of the drift check; ``scripts/gen-python-mirror.py --check`` in ``scripts/test.sh`` is
the second: the committed Python files must be the bundle's)."""

from __future__ import annotations

import json
from pathlib import Path

import ballbot
from ballbot import _core, _enums, _result_base, _results

ROOT = Path(__file__).resolve().parents[3]
SCHEMA = ROOT / "schemas" / "python-mirror.schema.json"
REGENERATE = "python3 scripts/gen-python-mirror.py --from-extension"


def test_committed_schema_is_the_extensions() -> None:
    committed = SCHEMA.read_text()
    built = _core._mirror_schema()
    assert json.loads(built) == json.loads(committed), (
        f"{SCHEMA.relative_to(ROOT)} differs from the Rust types; run `{REGENERATE}` "
        "with the extension built"
    )
    assert built == committed


def test_every_result_class_is_generated_and_registered() -> None:
    bundle = json.loads(SCHEMA.read_text())
    assert sorted(bundle["x-python-results"]) == sorted(_results.__all__)
    for name in bundle["x-python-results"]:
        cls = getattr(_results, name)
        assert _result_base._CLASSES[name] is cls
        assert getattr(ballbot, name, cls) is cls


def test_enum_members_are_the_rust_names() -> None:
    assert [m.value for m in _enums.StepStatus] == list(_core.STEP_STATUS_NAMES)
    assert [m.value for m in _enums.FailureKind] == list(_core.FAILURE_KIND_NAMES)
    bundle = json.loads(SCHEMA.read_text())
    for name in bundle["x-python-enums"]:
        members = [m["name"] for m in bundle["definitions"][name]["x-python-enum"]]
        assert [m.value for m in getattr(_enums, name)] == members


def test_every_settings_class_is_generated() -> None:
    from ballbot import _settings

    bundle = json.loads(SCHEMA.read_text())
    assert sorted(bundle["x-python-settings"]) == sorted(_settings.__all__)
    for name in bundle["x-python-settings"]:
        fields = bundle["definitions"][name]["required"]
        cls = getattr(_settings, name)
        assert [f for f in cls.__dataclass_fields__] == fields
        assert getattr(ballbot, name) is cls
