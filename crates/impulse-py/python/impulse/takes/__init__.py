"""Directable takes: state the outcome, and impulse searches for physically plausible takes of a
scene that reach it.

A take is the scene with a small perturbation θ of its bodies' initial state (a
:class:`Variation`: position, orientation, linear and angular velocity offsets; Barzel, Hughes &
Wood 1996). Goals (``ends_inside``, ``rests_with_axis_up``, ``passes_through``, ``touches``,
``never_touches``, ``stays_inside``, ``tilted``, or :func:`custom`) give each take a cost that
is 0 when met. :func:`search` samples takes with the cross-entropy method on the sweep's
backends (a local process pool or Ray), writes one Parquet row per take to ``out`` and stops
once enough takes meet every goal; :func:`load` reads them back, ``load(out)[take_id].scene()``
is the take's exact scene (``impulse run`` of it reproduces the take to the bit), and
:func:`sheet` draws a contact sheet to browse them, and :func:`refine` searches around a
chosen take.

Command line: ``python -m impulse.takes --help``. Docs: docs/takes.md.
"""

from impulse.takes._goals import MET, Goal, Record, custom, goal_from_dict, goals_from_json
from impulse.takes._search import Take, Takes, evaluate, load, refine, search, simulate_take
from impulse.takes._sheet import sheet
from impulse.takes._variation import Variation

__all__ = [
    "MET",
    "Goal",
    "Record",
    "Take",
    "Takes",
    "Variation",
    "custom",
    "evaluate",
    "goal_from_dict",
    "goals_from_json",
    "load",
    "refine",
    "search",
    "sheet",
    "simulate_take",
]
