"""Exceptions. Every user-facing error renders as one line."""

from __future__ import annotations


class DemcheckError(Exception):
    """Base class of demcheck's own errors."""

    exit_code = 1


class ConfigError(DemcheckError):
    """A bad case file, override or command-line value: names the key, the value and the rule."""

    exit_code = 2

    def __init__(self, key: str, value: object, rule: str):
        self.key, self.value, self.rule = key, value, rule
        super().__init__(f"{key} = {_show(value)}: {rule}")


class UnsupportedByEngine(DemcheckError):
    """The engine cannot express the case's model; says why."""

    exit_code = 2


class EngineNotFound(DemcheckError):
    exit_code = 1


class EngineFailed(DemcheckError):
    exit_code = 1


class EngineInterrupted(EngineFailed):
    """An engine run stopped by an interrupt (SIGINT/SIGTERM of demcheck), not by a fault of its own."""

    exit_code = 130


class ParseError(DemcheckError):
    exit_code = 1


def _show(value: object) -> str:
    if value is None:
        return "(missing)"
    text = repr(value) if isinstance(value, str) else str(value)
    return text if len(text) <= 80 else text[:77] + "..."
