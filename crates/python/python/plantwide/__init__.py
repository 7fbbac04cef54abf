"""plantwide from Python: the library the ``plantwide`` command line runs on.

>>> import plantwide as pw
>>> plant = pw.load("flowsheets/column_a.json")
>>> plant.steady()["distillate.x[A]"]                      # SI, as ``plantwide steady --json``
>>> g = plant.gains(["column.reflux", "column.boilup"], ["distillate.x[A]", "bottoms.x[A]"])
>>> g.gain, g.rga, g.niederlinski
>>> plant.tune(["top_composition", "bottom_composition"], "blt")   # as ``plantwide tune --json``
>>> pw.compare(["a.json", "b.json"], disturbances=["feed.F=±10%"], outputs=["product.F"], report="out")
>>> pw.select("evaporator.json", size=3)["subsets"][0]["measurements"]   # as ``plantwide select --json``
>>> pw.sweep("flowsheets/column_a.json", sets=[{"feed_source.F": "1.01 kmol/min"}], outputs=["distillate.x[A]"])

Every call goes through the same library functions as the CLI, so the numbers are the CLI's
(bit for bit for steady states). The GIL is released while the library works. Errors are
:class:`PlantwideError`: :class:`InputError` where the CLI exits 1 (a bad file, field, path or
value; an ill-posed plant), :class:`ConvergenceError` where it exits 2, with the library's message.
"""

from ._plantwide import ConvergenceError, InputError, PlantwideError
from .plant import Gains, LinearModel, Plant, SteadyState, compare, load
from .soc import select
from .sweeps import screen, screen_pairings, sensitivity, sweep

__all__ = [
    "ConvergenceError",
    "Gains",
    "InputError",
    "LinearModel",
    "Plant",
    "PlantwideError",
    "SteadyState",
    "compare",
    "load",
    "screen",
    "screen_pairings",
    "select",
    "sensitivity",
    "sweep",
]
