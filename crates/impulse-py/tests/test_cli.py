"""The ``impulse`` command that comes with the package: the console script ``impulse``
(``impulse._cli``, the command compiled into the native module) and the contact sheet's previews
drawn with it when nothing else is installed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import sysconfig
import time

import impulse
import pytest
from impulse._impulse import _cli_main
from impulse.takes import load, search, sheet
from impulse.takes._sheet import _cli
from test_takes import SCENE  # a ball on a frictionless floor

#: Its takes must end 0.3-0.6 m along x.
TARGET = {
    "type": "ends_inside",
    "body": "ball",
    "region": {"box": {"min": [0.3, 0.0, -0.2], "max": [0.6, 0.3, 0.2]}},
}


@pytest.fixture(scope="module")
def console_script() -> str:
    """The ``impulse`` script ``pip install`` put beside the interpreter. Missing (the package
    imported from a source tree), the tests that need it are skipped, unless
    IMPULSE_REQUIRE_CLI=1 (as in CI), where they fail."""
    name = "impulse.exe" if os.name == "nt" else "impulse"
    script = os.path.join(sysconfig.get_path("scripts"), name)
    if os.path.isfile(script) and os.access(script, os.X_OK):
        return script
    message = f"no console script {script}: the package is not installed with pip"
    if os.environ.get("IMPULSE_REQUIRE_CLI") == "1":
        pytest.fail(message)
    pytest.skip(message)


def _without_impulse_on_path() -> str:
    """``PATH`` with every directory holding an ``impulse`` command left out."""
    kept = [
        folder
        for folder in os.environ.get("PATH", "").split(os.pathsep)
        if folder and not os.path.exists(os.path.join(folder, "impulse"))
    ]
    return os.pathsep.join(kept)


def test_the_console_script_is_the_command(console_script, tmp_path):
    version = subprocess.run(
        [console_script, "--version"], capture_output=True, text=True, check=False
    )
    assert version.returncode == 0, version.stderr
    assert version.stdout.strip() == f"impulse {impulse.__version__}"
    run = subprocess.run(
        [console_script, "run", "pyramid20", "--steps", "5", "--out", "x.csv", "--quiet"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("pyramid20")
    lines = (tmp_path / "x.csv").read_text().splitlines()
    assert len(lines) > 1 and "," in lines[0]


def test_the_console_script_keeps_the_commands_exit_codes(console_script, tmp_path):
    bad_option = subprocess.run(
        [console_script, "run", "pyramid20", "--no-such-option"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert bad_option.returncode == 2
    assert "--no-such-option" in bad_option.stderr and not bad_option.stdout
    missing = subprocess.run(
        [console_script, "run", str(tmp_path / "missing.json")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert missing.returncode == 1
    assert missing.stderr.startswith("error: ")


def test_the_console_script_matches_the_binary(console_script, impulse_cli, tmp_path):
    for name, command in (("script.csv", console_script), ("binary.csv", impulse_cli)):
        subprocess.run(
            [command, "run", "stack30", "--steps", "20", "--out", name, "--quiet"],
            cwd=tmp_path,
            check=True,
            capture_output=True,
        )
    assert (tmp_path / "script.csv").read_bytes() == (tmp_path / "binary.csv").read_bytes()


@pytest.mark.parametrize("sent", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_stops_the_console_scripts_run_with_status_130(console_script, tmp_path, sent):
    # Python's own handlers would leave the run stepping (SIGINT: a KeyboardInterrupt raised
    # once the native call returns) or kill the process by the signal (SIGTERM: status -15).
    started = subprocess.Popen(
        [console_script, "run", "pyramid20", "--steps", "1000000", "--out", "x.csv", "--quiet"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        time.sleep(2.0)
        started.send_signal(sent)
        _, err = started.communicate(timeout=60)
    finally:
        started.kill()
    assert started.returncode == 130, err
    if "impulse: interrupted" not in err:
        # Stopped while stepping: after the step under way, with its files written.
        assert (tmp_path / "x.csv").stat().st_size > 0


def test_the_native_entry_returns_instead_of_exiting(capfd):
    # A bad command line, help and an error: statuses, not SystemExit or a dead interpreter.
    assert _cli_main(["impulse", "--no-such-option"]) == 2
    assert _cli_main(["impulse", "--help"]) == 0
    assert _cli_main(["impulse", "run", "no-such-scene-or-file"]) == 1
    out, err = capfd.readouterr()
    assert "Usage: impulse" in out
    assert "--no-such-option" in err and "error: " in err


def test_the_signal_handler_is_installed_once_per_process():
    # The console script's second call in one process keeps the first call's handler.
    code = (
        "from impulse._impulse import _cli_main\n"
        "print(_cli_main(['impulse', '--version'], signals=True))\n"
        "print(_cli_main(['impulse', 'scenes'], signals=True))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "0"
    assert "pyramid20" in done.stdout


def test_the_sheet_draws_previews_with_the_packages_command(tmp_path, monkeypatch):
    monkeypatch.delenv("IMPULSE_CLI", raising=False)
    monkeypatch.setenv("PATH", _without_impulse_on_path())
    command, environment = _cli()
    assert command == [sys.executable, "-m", "impulse._cli"]
    assert environment is not None
    out = tmp_path / "t"
    search(
        SCENE,
        [TARGET],
        {"bodies": ["ball"], "velocity": 0.3},
        budget=16,
        steps=30,
        out=out,
        workers=1,
        population=8,
        stop_after=2,
        progress=False,
    )
    sheet(out, count=2, every=5, size="64x48")
    shown = load(out).best(2)
    assert shown
    for take in shown:
        (gif,) = (out / "previews").glob(f"{take.take_id}-*.gif")
        assert gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a")


def test_a_missing_impulse_cli_is_named(tmp_path, monkeypatch):
    monkeypatch.setenv("IMPULSE_CLI", str(tmp_path / "no-such-impulse"))
    with pytest.raises(FileNotFoundError, match="no-such-impulse"):
        _cli()
