"""Where the tests find their data: the repository (samples, configs, examples), the shared
reference data (``RETARGET_SHARED``, relative to the repository root) and the CLI binary
(``RETARGET_CLI``). Under CI (``CI`` set) a missing one is a failure, never a skip."""

from __future__ import annotations

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
IN_CI = os.environ.get("CI", "") not in ("", "false")


def _need(path: pathlib.Path | None, what: str) -> pathlib.Path:
    if path is not None and path.exists():
        return path
    message = f"{what} not found ({path})"
    if IN_CI:
        pytest.fail(message + ": CI must run every test")
    pytest.skip(message)


@pytest.fixture(scope="session")
def root() -> pathlib.Path:
    return ROOT


@pytest.fixture(scope="session")
def shared() -> pathlib.Path:
    value = os.environ.get("RETARGET_SHARED")
    path = None if value is None else (ROOT / value if not os.path.isabs(value) else pathlib.Path(value))
    return _need(path if path is None else path / "DESIGN.md", "RETARGET_SHARED").parent


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    value = os.environ.get("RETARGET_CLI")
    path = None if value is None else (ROOT / value if not os.path.isabs(value) else pathlib.Path(value))
    return _need(path, "the retarget binary (RETARGET_CLI)")


@pytest.fixture(scope="session")
def walk() -> pathlib.Path:
    return _need(ROOT / "data/samples/lafan1_walk.bvh", "the LAFAN1 walk sample (scripts/fetch-samples)")
