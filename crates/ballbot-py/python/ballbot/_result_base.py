"""The hand-written part of ``ballbot._results``: the result classes' base (``to_dict``, a
short ``repr``) and the conversion from the native module's plain form.

The native module converts a result in one way (``src/results.rs``): the Rust result's serde
form, as plain Python objects (``pythonize``), goes to :func:`_build`, which converts each
field by its annotation in the generated class: arrays from their ``{"dtype", "shape",
"data"}`` form, nested result classes, enums from their canonical names, ``Failure`` from its
parts, paths. A field the native module builds itself (a rollout's numpy arrays, a native
class) is taken as it is.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import sys
import typing
from pathlib import Path
from typing import Any, TypeVar, Union

import numpy as np
import numpy.typing as npt

from ballbot._core import Failure


def _plain(value: Any) -> Any:
    if isinstance(value, _Result):
        return value.to_dict()
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _short(value: Any) -> str:
    if isinstance(value, np.ndarray):
        return f"array(shape={value.shape}, dtype={value.dtype})"
    if isinstance(value, list):
        return f"[{len(value)} items]"
    if isinstance(value, dict):
        return f"{{{len(value)} entries}}"
    if isinstance(value, str) and "\n" in value:
        return f"<{len(value.splitlines())} lines>"
    return repr(value)


@dataclasses.dataclass(frozen=True, eq=False, repr=False)
class _Result:
    """Base of the result classes: ``to_dict`` and a short ``repr``."""

    def to_dict(self) -> dict[str, Any]:
        """The fields as a dict (nested results as dicts; arrays are not copied)."""
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def __repr__(self) -> str:
        fields = ", ".join(
            f"{f.name}={_short(getattr(self, f.name))}" for f in dataclasses.fields(self)
        )
        return f"{type(self).__name__}({fields})"


_CLASSES: dict[str, type[_Result]] = {}
_R = TypeVar("_R", bound="type[_Result]")


def _register(cls: _R) -> _R:
    """Registers a generated result class under its name, the Rust type's schema name (what
    the native module passes to :func:`_build`)."""
    _CLASSES[cls.__name__] = cls
    return cls


@functools.lru_cache(maxsize=None)
def _hints(cls: type) -> dict[str, Any]:
    module = sys.modules[cls.__module__]
    return typing.get_type_hints(cls, vars(module))


def _array(value: dict[str, Any]) -> npt.NDArray[Any]:
    """An owned, writable array of the ``{"dtype", "shape", "data"}`` form."""
    flat = np.frombuffer(value["data"], dtype=np.dtype(value["dtype"]))
    return flat.reshape(value["shape"]).copy()


def _arrays(value: Any) -> Any:
    """A JSON-shaped value (``dict[str, Any]`` fields) with the arrays in it made numpy arrays:
    an array's form is the only dict whose ``data`` is ``bytes`` (JSON has none)."""
    if isinstance(value, dict):
        if isinstance(value.get("data"), bytes) and value.keys() == {"dtype", "shape", "data"}:
            return _array(value)
        return {k: _arrays(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_arrays(v) for v in value]
    return value


def _decode(hint: Any, value: Any) -> Any:
    """``value`` (plain Python objects from the native module) as the annotation ``hint``
    says: the one place where the serde form becomes numpy arrays, result classes, enums and
    ``Failure``s."""
    if value is None:
        return None
    if hint is Any:
        return _arrays(value)
    origin = typing.get_origin(hint)
    args = typing.get_args(hint)
    if origin is Union:
        (inner,) = [a for a in args if a is not type(None)]
        return _decode(inner, value)
    if origin is np.ndarray:
        if isinstance(value, np.ndarray):
            return value
        return _array(value)
    if origin is list:
        return [_decode(args[0], v) for v in value]
    if origin is tuple:
        return tuple(_decode(a, v) for a, v in zip(args, value))
    if origin is dict:
        return {_decode(args[0], k): _decode(args[1], v) for k, v in value.items()}
    if isinstance(hint, type):
        if isinstance(value, hint):
            return value
        if issubclass(hint, _Result):
            return _build(hint.__name__, value)
        if issubclass(hint, enum.Enum):
            return hint(value)
        if hint is Failure:
            return Failure._from_parts(**value)
        if hint is Path:
            return Path(value)
    return value


def _build(class_name: str, data: dict[str, Any]) -> _Result:
    """The result class ``class_name`` from the native module's plain form of it (a dict
    with one entry per field, no other)."""
    cls: Any = _CLASSES[class_name]
    hints = _hints(cls)
    fields = {f.name: _decode(hints[f.name], data[f.name]) for f in dataclasses.fields(cls)}
    extra = data.keys() - fields.keys()
    if extra:
        raise TypeError(f"{class_name}: unexpected fields {sorted(extra)}")
    result: _Result = cls(**fields)
    return result
