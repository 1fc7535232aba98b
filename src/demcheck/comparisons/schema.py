"""The shape of every JSON file demcheck reads back: a run's results.json and a baseline file (comparisons/diff.py).

Each is checked against its JSON Schema (jsonschema, draft 2020-12) before any of it is used, so that a file of
the right syntax and the wrong shape — a case name that is a number, metrics or verdicts as lists, a comparison
without its metric, a scale that is text, a verdict that is not one of demcheck's words — is one error line naming
the file, the place in it (a JSON path) and the rule, exit 2, before any work. Only what demcheck reads is
constrained; other keys (plots, curves, a later release's additions) are left alone.

Strict JSON only: demcheck writes non-finite numbers as null (io.plain), so NaN, Infinity and a number too large
for a float (1e999) are refused as they are parsed; so is nesting too deep for Python's parser.
"""

from __future__ import annotations

import json
import math

from ..errors import ConfigError
from . import verdicts

TEXT = {"type": "string"}
NAME = {"type": "string", "minLength": 1}
TEXT_OR_NULL = {"type": ["string", "null"]}
NUMBER_OR_NULL = {"type": ["number", "null"]}
TOLERANCE = {"type": "number", "minimum": 0}
VERDICT = {"enum": list(verdicts.VERDICTS)}
SCALES = {"type": ["object", "null"], "additionalProperties": {"type": ["number", "null"], "exclusiveMinimum": 0}}
ABOUT = {"run_id": TEXT_OR_NULL, "started": TEXT_OR_NULL, "demcheck": TEXT_OR_NULL, "partial": {"type": "boolean"}}

RESULTS = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "demcheck results.json (what diff and verify --baseline read)",
    "type": "object",
    "required": ["cases"],
    "properties": {
        **ABOUT,
        "engines": {"type": ["object", "null"], "additionalProperties": {
            "type": "object", "properties": {"found": {"type": "boolean"}, "version": TEXT_OR_NULL}}},
        "cases": {"type": "array", "items": {
            "type": "object",
            "required": ["case"],
            "properties": {
                "case": NAME,
                "case_hash": TEXT_OR_NULL,
                "scales": SCALES,
                "sources": {"type": ["object", "null"], "additionalProperties": {
                    "type": "object",
                    "properties": {"status": TEXT_OR_NULL, "engine_version": TEXT_OR_NULL,
                                   "metrics": {"type": ["object", "null"]}}}},
                "comparisons": {"type": "array", "items": {
                    "type": "object",
                    "required": ["source", "metric", "verdict"],
                    "properties": {"source": NAME, "metric": NAME, "verdict": VERDICT}}},
            }}},
    },
}

BASELINE = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "demcheck baseline (verify --write-baseline)",
    "type": "object",
    "required": ["format", "version", "cases"],
    "properties": {
        **ABOUT,
        "format": {"const": "demcheck-baseline"},
        "version": {"type": "integer"},
        "command": {"type": ["array", "null"], "items": TEXT},
        "engines": {"type": ["object", "null"], "additionalProperties": TEXT_OR_NULL},
        "tolerances": {"type": ["object", "null"], "properties": {
            "default": {"type": ["number", "null"], "minimum": 0},
            "metrics": {"type": ["object", "null"], "additionalProperties": TOLERANCE}}},
        "cases": {"type": "object", "additionalProperties": {
            "type": "object",
            "properties": {
                "hash": TEXT_OR_NULL,
                "scales": SCALES,
                "sources": {"type": ["object", "null"], "additionalProperties": {
                    "type": "object",
                    "properties": {"status": TEXT_OR_NULL, "version": TEXT_OR_NULL,
                                   "metrics": {"type": ["object", "null"], "additionalProperties": NUMBER_OR_NULL},
                                   "tolerances": {"type": ["object", "null"], "additionalProperties": TOLERANCE}}}},
                "verdicts": {"type": ["object", "null"], "additionalProperties": {
                    "type": "object", "additionalProperties": VERDICT}},
            }}},
    },
}


def _refuse_constant(text: str):
    raise ValueError(f"{text} is not a JSON number (demcheck writes a missing value as null)")


def _finite_float(text: str) -> float:
    x = float(text)
    if not math.isfinite(x):
        raise ValueError(f"the number {text[:40]} is too large for a float")
    return x


def parse(text: str, key: str, path: str):
    """``text`` as strict JSON; anything else is a ConfigError naming ``key`` and ``path``."""
    try:
        return json.loads(text, parse_constant=_refuse_constant, parse_float=_finite_float)
    except RecursionError:
        raise ConfigError(key, path, "cannot be read as JSON (nested deeper than demcheck reads)") from None
    except ValueError as exc:  # json.JSONDecodeError is a ValueError
        raise ConfigError(key, path, f"cannot be read as JSON ({_short(str(exc))})") from None


def check(data, schema: dict, key: str, path: str) -> None:
    """``data`` against ``schema``; the first fault (jsonschema's best match) is a ConfigError naming ``key``,
    ``path``, where in the file and the rule."""
    from jsonschema import Draft202012Validator
    from jsonschema.exceptions import best_match

    try:
        error = best_match(Draft202012Validator(schema).iter_errors(data))
    except RecursionError:
        raise ConfigError(key, path, "is nested deeper than demcheck reads") from None
    if error is not None:
        raise ConfigError(key, path, f"is not a demcheck results.json or baseline: as a {_kind(schema)}, at "
                                     f"{error.json_path}: {_short(error.message)}")


def _kind(schema: dict) -> str:
    return "baseline" if schema is BASELINE else "results.json"


def _short(text: str, limit: int = 160) -> str:
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit - 1] + "…"
