"""``python -m impulse.takes``: the command line of :mod:`impulse.takes`."""

import sys

from impulse.takes.cli import main

sys.exit(main())
