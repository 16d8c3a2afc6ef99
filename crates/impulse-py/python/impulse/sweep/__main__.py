"""``python -m impulse.sweep``: a parameter sweep from the command line (see ``--help``)."""

from impulse.sweep.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
