"""Unpickling helpers referenced by the native classes' ``__reduce__`` (see
``crates/ballbot-py/src/pickle.rs``)."""

from __future__ import annotations

from typing import Any


def from_json(cls: Any, text: str) -> Any:
    """Re-creates a record from its JSON state (the class's ``_from_json``)."""
    return cls._from_json(text)


def from_toml(cls: Any, text: str) -> Any:
    """Re-creates a parameter file's object from its TOML (the class's ``from_toml``)."""
    return cls.from_toml(text)
