"""Self-optimizing control from Python: ``plantwide select --matrices``."""

from __future__ import annotations

import json
import os

from . import _plantwide as _native


def select(
    matrices: str | os.PathLike,
    size: int,
    *,
    best: int = 5,
    criterion: str = "worst",
    max_nodes: int = 200_000,
) -> dict:
    """``plantwide select --matrices FILE --size N --json``: the ``best`` subsets of ``size``
    candidate measurements to combine into controlled variables, by the exact local method
    (``criterion`` ``"worst"``: ½σ̄(M)², or ``"average"``: ½‖M‖²_F) and bidirectional branch and
    bound, from published linear data (a JSON file with ``inputs``, ``disturbances``,
    ``measurements``, ``Gy``, ``Gyd``, ``Juu``, ``Jud``, ``Wd``, ``Wn``). Returns the dict the CLI
    prints: ``criterion``, ``size``, ``subsets`` (best first: ``measurements``,
    ``worst_case_loss``, ``average_loss``, ``H``), ``nodes``. Bad data or a size out of range raise
    ``InputError``; a search out of its ``max_nodes`` budget raises ``ConvergenceError``."""
    text = _native.select(os.fspath(matrices), size, best, criterion, max_nodes)
    return json.loads(text)
