"""``World.diagnostics``: the last step's diagnostics, a dict with a one-line repr."""

from __future__ import annotations

__all__ = ["Diagnostics"]


class Diagnostics(dict):
    """The last step's ``impulse::StepDiagnostics`` as a dict (keys as ``World.diagnostics``
    lists them). ``repr`` and ``print`` give a one-line summary (the island count, not every
    island); ``d["islands"]`` or ``dict(d)`` give everything. Compares equal to a plain dict
    of the same items."""

    __slots__ = ()

    def __repr__(self) -> str:
        fields = [
            f"step={self.get('step')}",
            f"contacts={self.get('contacts')}",
            f"rows={self.get('rows')}",
            f"islands={len(self.get('islands') or ())}",
            f"iterations={self.get('iterations')}",
            f"natural_map_residual={_short(self.get('natural_map_residual'))}",
            f"max_depth={_short(self.get('max_depth'))}",
            f"kinetic_energy={_short(self.get('kinetic_energy'))}",
        ]
        return f"Diagnostics({', '.join(fields)})"

    __str__ = __repr__

    def __reduce__(self):
        return (Diagnostics, (dict(self),))


def _short(value: object) -> str:
    """A float in 4 significant digits (other values as they are)."""
    return f"{value:.4g}" if isinstance(value, float) else repr(value)
