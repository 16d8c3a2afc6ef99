"""The ``impulse`` command of the Python package: the console script ``impulse`` and
``python -m impulse._cli`` run the command-line tool (``impulse run``, ``render``, ``export``,
``lcp``...; ``impulse --help``) compiled into the native module, with nothing else installed."""

from __future__ import annotations

import os
import sys

from ._impulse import _cli_main


def main(argv: list[str] | None = None) -> None:
    """Runs ``impulse`` with ``argv`` (default ``sys.argv[1:]``) and exits with its status.

    The command takes over Ctrl-C, SIGTERM and SIGHUP as the binary does: a run stops after the
    step under way and writes its files. A USD stage is read by this interpreter (``impulse.usd``)
    unless ``IMPULSE_PYTHON`` names another.
    """
    arguments = sys.argv[1:] if argv is None else argv
    if sys.executable:
        os.environ.setdefault("IMPULSE_PYTHON", sys.executable)
    sys.stdout.flush()
    sys.stderr.flush()
    sys.exit(_cli_main(["impulse", *arguments], signals=True))


if __name__ == "__main__":
    main()
