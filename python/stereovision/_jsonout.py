"""Strict JSON output lines, shared by ``eval --json`` and ``bench --json``.

A figure with nothing to measure (NaN: no ground-truth pixel, no sparse match on GT) or an
infinite one is written as ``null``, so every line parses with a strict JSON parser. This
module imports nothing from the package (only the standard library and numpy), so the CLI
and the commands it registers can both use it without a circular import.
"""

from __future__ import annotations

import json
import math
import os
from typing import Any

import numpy as np

__all__ = ["json_line", "json_ready"]


def json_ready(value: Any) -> Any:
    """``value`` with every non-finite float (NaN, inf) as None, NumPy scalars as Python's,
    NumPy arrays as (nested) lists and paths as strings, recursively.

    Parameters
    ----------
    value : Any
        A dict, list, tuple, number or bool (Python or NumPy), a NumPy array of any shape
        (0-d included), an :class:`os.PathLike` path, or any other JSON-serialisable value.

    Returns
    -------
    Any
        The same structure, dicts and lists rebuilt (tuples as lists); a NumPy array as the
        nested lists of its ``tolist`` (a 0-d one as its value), each element converted as a
        value is; a NumPy integer or bool as a Python int or bool; each finite float as a
        Python float and each non-finite one as None; a path as its string; a dict key that is
        a NumPy scalar as its Python value, a path key as its string, a NaN or infinite float
        key as ``"NaN"``, ``"Infinity"`` or ``"-Infinity"``; other values as given.

    Raises
    ------
    ValueError
        If two keys of one dict would be written as the same JSON string (a NaN key and
        ``"NaN"``, ``1`` and ``"1"``, ``True`` and ``"true"``, ``None`` and ``"null"``, two NaN
        keys): one value would be lost. The message names both keys.
    """
    if isinstance(value, dict):
        ready: dict[Any, Any] = {}
        seen: dict[str, Any] = {}  # the JSON text of each key -> the key as given
        for k, v in value.items():
            key = _json_key(k)
            text = _key_text(key)
            if text is not None:
                if text in seen:
                    raise ValueError(
                        f"JSON object keys {_shown(seen[text])} and {_shown(k)} are both "
                        f"written as {text!r}: one value would be lost"
                    )
                seen[text] = k
            ready[key] = json_ready(v)
        return ready
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        # nested lists of Python scalars (a 0-d array: its value), NaN and inf still floats
        return json_ready(value.tolist())
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def _json_key(key: Any) -> Any:
    """A dict key json.dumps takes: a NumPy scalar as its Python value, a path as its string
    (json.dumps raised TypeError for both), a NaN or infinite float as the string json.dumps
    writes for it, ``"NaN"``, ``"Infinity"`` or ``"-Infinity"`` (a key is a string in JSON;
    strict json.dumps raised ValueError)."""
    if isinstance(key, np.generic):
        key = key.item()
    if isinstance(key, os.PathLike):
        return os.fspath(key)
    if isinstance(key, float) and not math.isfinite(key):
        return "NaN" if math.isnan(key) else ("Infinity" if key > 0 else "-Infinity")
    return key


def _key_text(key: Any) -> str | None:
    """The string json.dumps writes for a key :func:`_json_key` gave (None for a key it
    refuses, whose TypeError it raises itself)."""
    if isinstance(key, str):
        return key
    if key is None or isinstance(key, bool):
        return {None: "null", True: "true", False: "false"}[key]
    if isinstance(key, int):
        return int.__repr__(key)
    if isinstance(key, float):
        return float.__repr__(key)
    return None


def _shown(key: Any) -> str:
    """A key as the collision message names it (a NumPy scalar as its Python value)."""
    return repr(key.item() if isinstance(key, np.generic) else key)


def json_line(row: dict[str, Any]) -> str:
    """One line of strict JSON (a figure with nothing to measure, NaN, is ``null``).

    Parameters
    ----------
    row : dict of str to Any
        The object to write.

    Returns
    -------
    str
        ``row`` as JSON, without a newline.

    Raises
    ------
    ValueError
        If a value is still not representable in strict JSON (never for floats), or two keys
        of one dict would be written alike (:func:`json_ready`).
    TypeError
        If a value is not JSON-serialisable.
    """
    return json.dumps(json_ready(row), allow_nan=False)
