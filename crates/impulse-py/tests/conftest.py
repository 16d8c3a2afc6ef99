"""Shared fixtures: the repository root and the `impulse` command to compare against."""

import os
import pathlib
import shutil
import sysconfig

import pytest

REPOSITORY = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def repository() -> pathlib.Path:
    return REPOSITORY


@pytest.fixture(scope="session")
def impulse_cli() -> str:
    """The `impulse` command: $IMPULSE_CLI, else the repository's release build, else PATH,
    else the package's console script (installed by pip beside the interpreter).

    Missing, the tests that need it are skipped, unless IMPULSE_REQUIRE_CLI=1 (as in CI),
    where they fail.
    """
    candidates = [
        os.environ.get("IMPULSE_CLI"),
        str(REPOSITORY / "target" / "release" / "impulse"),
        shutil.which("impulse"),
        os.path.join(sysconfig.get_path("scripts"), "impulse"),
    ]
    for candidate in candidates:
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    message = "the impulse command is not built (cargo build --release -p impulse-cli)"
    if os.environ.get("IMPULSE_REQUIRE_CLI") == "1":
        pytest.fail(message)
    pytest.skip(message)
