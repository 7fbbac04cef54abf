"""A flowsheet loaded from Python, and the results of its steady state, gains, linear model and runs."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from typing import Any, Iterator

import numpy as np

from . import _plantwide as _native
from ._plantwide import ConvergenceError


def assignments(set: Mapping[str, Any] | None) -> list[str]:
    """``{path: "value unit"}`` as the CLI's ``--set PATH=VALUE`` strings, in order.

    A number is taken in SI; a string is parsed like the CLI's value (``"1.01 kmol/min"``)."""
    if set is None:
        return []
    if not isinstance(set, Mapping):
        raise TypeError(f"set: expected a mapping {{path: value}}, got {type(set).__name__}")
    out = []
    for path, value in set.items():
        if not isinstance(path, str):
            raise TypeError(f"set: a path must be a string, got {path!r}")
        # float.__repr__ round-trips every double (numpy's float64 repr would add its type name).
        out.append(f"{path}={float.__repr__(value)}" if isinstance(value, float) else f"{path}={value}")
    return out


class SteadyState(Mapping):
    """A steady state: every variable and free input path → its SI value (a read-only mapping).

    ``.warnings`` lists the library's warnings (loops saturated off setpoint); ``.to_dict()``
    gives a plain dict."""

    def __init__(self, values: list[tuple[str, float]], warnings: list[str]):
        self._values = dict(values)
        self.warnings = list(warnings)

    def __getitem__(self, path: str) -> float:
        try:
            return self._values[path]
        except KeyError:
            raise KeyError(f"`{path}`: not a variable or free input of this steady state") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def to_dict(self) -> dict[str, float]:
        """A plain dict path → SI value."""
        return dict(self._values)

    def __repr__(self) -> str:
        return f"<SteadyState: {len(self)} values, {len(self.warnings)} warnings>"


class Gains:
    """Steady-state gains in display units and their interaction measures (numpy arrays).

    ``gain`` (outputs × inputs), ``rga`` (None when the gain is singular), ``svd`` =
    ``(U, singular values, V)``, ``singular_values``, ``condition_number`` (inf when singular),
    ``niederlinski`` and ``rga_number`` of the pairing (None unless square and regular),
    ``inputs``/``outputs`` as ``(path, unit)``; ``perturbation`` the check of perturbation gains."""

    def __init__(self, d: dict):
        self.method: str = d["method"]
        self.inputs: list[tuple[str, str]] = [tuple(s) for s in d["inputs"]]
        self.outputs: list[tuple[str, str]] = [tuple(s) for s in d["outputs"]]
        self.gain = np.array(d["gain"], dtype=float)
        self.rga = None if d["rga"] is None else np.array(d["rga"], dtype=float)
        self.singular_values = np.array(d["singular_values"], dtype=float)
        self.svd = (np.array(d["u"], dtype=float), self.singular_values, np.array(d["v"], dtype=float))
        self.condition_number: float = d["condition_number"]
        self.min_condition_number: float | None = d["min_condition_number"]
        self.niederlinski: float | None = d["niederlinski"]
        self.rga_number: float | None = d["rga_number"]
        self.pairing: list[int] | None = d["pairing"]
        self.perturbation: dict | None = None if d["perturbation"] is None else json.loads(d["perturbation"])

    def __repr__(self) -> str:
        return f"<Gains ({self.method}) {self.gain.shape[0]}×{self.gain.shape[1]}: NI {self.niederlinski}>"


class LinearModel:
    """``dx/dt = A x + B u``, ``y = C x + D u`` in deviations from the steady state (time in s,
    states in SI, inputs and outputs in their display units), as ``plantwide linearize --out``
    exports it.

    ``A, B, C, D`` are numpy arrays; ``states``, ``inputs``, ``outputs`` the paths (with units for
    inputs and outputs); ``state_names``, ``input_names``, ``output_names`` python-control-safe
    names and ``labels`` the path of each safe name."""

    def __init__(self, d: dict):
        self.name: str = d["name"]
        self.A, self.B, self.C, self.D = (np.array(d[k], dtype=float).reshape(_shape(d, k)) for k in "ABCD")
        g = d["steady_state_gain"]
        self.steady_state_gain = None if g is None else np.array(g, dtype=float)
        self.states: list[str] = list(d["states"])
        self.inputs: list[tuple[str, str]] = [tuple(s) for s in d["inputs"]]
        self.outputs: list[tuple[str, str]] = [tuple(s) for s in d["outputs"]]
        self.state_names: list[str] = list(d["state_names"])
        self.input_names: list[str] = list(d["input_names"])
        self.output_names: list[str] = list(d["output_names"])
        self.labels: dict[str, dict[str, str]] = {
            "states": dict(zip(self.state_names, self.states)),
            "inputs": dict(zip(self.input_names, (p for p, _ in self.inputs))),
            "outputs": dict(zip(self.output_names, (p for p, _ in self.outputs))),
        }
        self.state_values = np.array(d["state_values"], dtype=float)
        self.input_values = np.array(d["input_values"], dtype=float)
        self.output_values = np.array(d["output_values"], dtype=float)
        self.eigenvalues = np.array([complex(re, im) for re, im in d["eigenvalues"]], dtype=complex)
        self._json: str = d["json"]

    def __iter__(self):
        """``A, B, C, D = plant.linearize(...)``."""
        return iter((self.A, self.B, self.C, self.D))

    def to_control(self):
        """A python-control ``StateSpace`` with the safe signal names (``labels`` maps them back)."""
        try:
            import control
        except ImportError as e:
            raise ImportError("to_control() needs python-control: pip install control") from e
        return control.ss(
            self.A,
            self.B,
            self.C,
            self.D,
            states=self.state_names,
            inputs=self.input_names,
            outputs=self.output_names,
            name=_safe_system_name(self.name),
        )

    def to_json(self, path: str | os.PathLike) -> None:
        """Write the export ``plantwide linearize --out model.json`` writes."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self._json + "\n")

    def to_npz(self, path: str | os.PathLike) -> None:
        """Write ``A, B, C, D``, the names, paths, units and steady values as a numpy ``.npz``
        (the keys ``plantwide linearize --out model.npz`` writes)."""
        arrays = {"A": self.A, "B": self.B, "C": self.C, "D": self.D, "eigenvalues": self.eigenvalues}
        if self.steady_state_gain is not None:
            arrays["steady_state_gain"] = self.steady_state_gain
        arrays.update(
            state_names=np.array(self.state_names, dtype=str),
            input_names=np.array(self.input_names, dtype=str),
            output_names=np.array(self.output_names, dtype=str),
            state_paths=np.array(self.states, dtype=str),
            input_paths=np.array([p for p, _ in self.inputs], dtype=str),
            output_paths=np.array([p for p, _ in self.outputs], dtype=str),
            input_units=np.array([u for _, u in self.inputs], dtype=str),
            output_units=np.array([u for _, u in self.outputs], dtype=str),
            state_values=self.state_values,
            input_values=self.input_values,
            output_values=self.output_values,
            time_unit=np.array("s"),
        )
        np.savez(path, **arrays)

    def __repr__(self) -> str:
        return f"<LinearModel of {self.name}: {len(self.states)} states, {len(self.inputs)} inputs, {len(self.outputs)} outputs>"


def _shape(d: dict, key: str) -> tuple[int, int]:
    """The shape of matrix ``key`` (empty rows keep their width: a model without states)."""
    n, m, p = len(d["states"]), len(d["inputs"]), len(d["outputs"])
    return {"A": (n, n), "B": (n, m), "C": (p, n), "D": (p, m)}[key]


def _safe_system_name(name: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in name) or "plant"


class Plant:
    """A flowsheet, loaded and validated. Every method applies its ``set`` overrides to the file's
    description and calls the library as the matching CLI command does."""

    def __init__(self, text: str, name: str):
        self._text, self._name = text, name
        self.name, self.inputs, self.variables = _native.check(text, name)

    @property
    def file(self) -> str:
        """The flowsheet's file name, as messages give it."""
        return self._name

    @property
    def text(self) -> str:
        """The flowsheet's text (what a task sent to another process carries)."""
        return self._text

    def steady(self, set: Mapping[str, Any] | None = None, method: str = "auto") -> SteadyState:
        """``plantwide steady --json --set …``: path → SI value (``method``: auto, eo or sm)."""
        values, warnings = _native.steady(self._text, self._name, assignments(set), method)
        return SteadyState(values, warnings)

    def gains(
        self,
        inputs: list[str],
        outputs: list[str],
        method: str = "linear",
        *,
        set: Mapping[str, Any] | None = None,
        pairing: str | None = None,
        step: float | None = None,
    ) -> Gains:
        """``plantwide gains``: inputs and outputs as ``PATH[@unit]`` (``method``: linear or perturb)."""
        d = _native.gains(self._text, self._name, assignments(set), list(inputs), list(outputs), method, step, pairing)
        return Gains(d)

    def linearize(self, inputs: list[str], outputs: list[str], *, set: Mapping[str, Any] | None = None) -> LinearModel:
        """``plantwide linearize``: the state-space model at the steady state (time in s)."""
        return LinearModel(_native.linearize(self._text, self._name, assignments(set), list(inputs), list(outputs)))

    def run(self, scenario: str | os.PathLike | Mapping, *, set: Mapping[str, Any] | None = None):
        """``plantwide run``: the scenario (a file, or its description as a dict) from the steady
        state. Returns a pandas DataFrame indexed by time [s] with one SI column per recorded path
        when pandas is installed, else a dict ``{"time": array, path: array, …}``."""
        if isinstance(scenario, Mapping):
            text, name = json.dumps(scenario), "<scenario>"
        else:
            name = os.fspath(scenario)
            text = _native.read_text(name)
        d = _native.run(self._text, self._name, assignments(set), text, name)
        columns = {"time": np.array(d["time"], dtype=float)}
        rows = np.array(d["rows"], dtype=float).reshape(len(d["time"]), len(d["columns"]))
        for k, (path, _unit) in enumerate(d["columns"]):
            columns[path] = rows[:, k]
        try:
            import pandas as pd
        except ImportError:
            return columns
        frame = pd.DataFrame(columns).set_index("time")
        frame.attrs["units"] = {path: unit for path, unit in d["columns"]}
        frame.attrs["events"] = d["events"]
        return frame

    def size(
        self,
        vessel: str | None = None,
        *,
        level_band: str | float,
        disturbance: str | None = None,
        max_outflow_rate: str | float | None = None,
        candidates: Sequence[str] | None = None,
        scenario: str | os.PathLike | Mapping | None = None,
        ramp: str | float | None = None,
        sine: str | float | None = None,
        attenuation: float | None = None,
        period: str | float | None = None,
        duration: str | float | None = None,
        set: Mapping[str, Any] | None = None,
        report: str | os.PathLike | None = None,
        units: str = "si",
    ) -> dict:
        """``plantwide size --json``: the cross-section and level controller (P, critically damped
        PI, optimal averaging) that keep ``vessel``'s level within ``±level_band`` and its outflow's
        rate under ``max_outflow_rate`` for ``disturbance`` (``"PATH=+10%"``), each verified by a
        nonlinear run; or ``candidates`` ranked by the surge volume they need. Quantities are text
        with units (``"0.3 m"``, ``"5 kmol/h/min"``) or SI numbers; ``scenario`` (a file or a
        dict) gives the disturbance as its one step, ramp or sinusoid. Returns the dict the CLI
        prints (SI); ``report`` writes the CLI's ``--report`` folder in ``units`` (si, metric,
        field). Parts without an answer raise ``ConvergenceError`` after the report is written,
        the result kept as the error's ``result``."""
        request = {"level_band": level_band}
        for key, value in (
            ("vessel", vessel),
            ("disturbance", disturbance),
            ("max_outflow_rate", max_outflow_rate),
            ("ramp", ramp),
            ("sine", sine),
            ("attenuation", attenuation),
            ("period", period),
            ("duration", duration),
        ):
            if value is not None:
                request[key] = value
        if candidates is not None:
            request["candidates"] = list(candidates)
        if scenario is not None:
            if isinstance(scenario, Mapping):
                request["scenario"] = dict(scenario)
            else:
                request["scenario"] = json.loads(_native.read_text(os.fspath(scenario)))
        folder = None if report is None else os.fspath(report)
        text, failed = _native.size(self._text, self._name, assignments(set), json.dumps(request), folder, units)
        return _answer(text, failed)

    def optimize(
        self,
        objective: str | None = None,
        *,
        vary: Mapping[str, Any] | Sequence[str] | None = None,
        constraints: Mapping[str, Any] | None = None,
        maximize: bool = False,
        set: Mapping[str, Any] | None = None,
    ) -> dict:
        """``plantwide optimize --json``: the economic optimum of the flowsheet's
        ``"optimization"`` section, with ``objective`` (a tag or ``PATH[@unit]``), ``vary`` (paths,
        or ``{path: {"min": …, "max": …}}``, replacing the file's) and ``constraints``
        (``{path: {"min": …, "max": …}}``, added to the file's) applied as the CLI's flags are.
        Returns the dict the CLI prints: ``objective``, ``values`` (SI), ``active``,
        ``multipliers`` (shadow prices ∂J*/∂limit in display units), ``kkt_residual``, and
        ``limits``, ``reduced_hessian``, …. A request that does not fit the plant raises
        ``InputError``; no feasible point or no certified optimum raises ``ConvergenceError``."""
        request = self._problem(objective, vary, constraints, maximize)
        return json.loads(_native.optimize(self._text, self._name, assignments(set), request))

    def _problem(self, objective, vary, constraints, maximize) -> str:
        """The file's ``"optimization"`` section with the keywords applied as the CLI's flags are."""
        request = dict(json.loads(self._text).get("optimization") or {})
        if objective is not None:
            request["objective"] = objective
        if maximize:
            request["sense"] = "maximize"
        if vary is not None:
            request["vary"] = dict(vary) if isinstance(vary, Mapping) else {path: {} for path in vary}
        if constraints is not None:
            request["constraints"] = {**request.get("constraints", {}), **dict(constraints)}
        return json.dumps(request)

    def select(
        self,
        disturbances: Sequence[str],
        candidates: Sequence[str],
        errors: Sequence[str],
        size: int,
        *,
        best: int = 5,
        criterion: str = "worst",
        max_nodes: int = 200_000,
        objective: str | None = None,
        vary: Mapping[str, Any] | Sequence[str] | None = None,
        constraints: Mapping[str, Any] | None = None,
        maximize: bool = False,
        set: Mapping[str, Any] | None = None,
    ) -> dict:
        """``plantwide select FILE --json``: self-optimizing control at the optimum of the
        flowsheet's ``"optimization"`` section, with ``objective``, ``vary``, ``constraints`` and
        ``maximize`` applied as in :meth:`optimize`. ``disturbances`` are ``"PATH=±Δ"``, ``candidates``
        ``"PATH[@unit]"``, ``errors`` ``"PATH=±e"`` (one per candidate). Returns the dict the CLI
        prints: ``criterion``, ``size``, ``subsets`` (best first, each with ``measurements``,
        losses, ``H`` and its ``nonlinear`` verification points), ``nodes``, ``optimum`` and
        ``local_model``. A verification point without an answer raises ``ConvergenceError`` with
        the result as its ``result``."""
        text, failed = _native.select_plant(
            self._text,
            self._name,
            assignments(set),
            self._problem(objective, vary, constraints, maximize),
            list(disturbances),
            list(candidates),
            list(errors),
            size,
            best,
            criterion,
            max_nodes,
        )
        return _answer(text, failed)

    def tune(
        self,
        loops: str | Sequence[str],
        method: str,
        *,
        measurement_dead_time: str | float | None = None,
        measurement_lag: str | float | None = None,
        relay_amplitude: str | float | None = None,
        hysteresis: str | float | None = None,
        scan: str | float | None = None,
        step: str | float | None = None,
        model: str | None = None,
        tau_c: str | float | None = None,
        pid: bool = False,
        level_band: str | float | None = None,
        flow_change: str | float | None = None,
        form: str = "p",
        time_unit: str = "s",
        set: Mapping[str, Any] | None = None,
        report: str | os.PathLike | None = None,
        write: str | os.PathLike | None = None,
    ) -> dict:
        """``plantwide tune FILE --json``: PI(D) settings of the PID ``loops`` (a name or a list) by
        ``method`` (blt, zn, tl, relay, simc, imc, averaging), each with the test behind it and its
        margins on the plant's linear model; times in ``time_unit``, as the CLI prints them.
        Quantities are text with units (``"30 s"``) or SI numbers. ``report`` writes the CLI's
        ``--report`` folder; ``write`` the flowsheet with the tuned settings. Loops whose own
        margins refute their settings raise ``ConvergenceError`` (nothing written), the result
        kept as the error's ``result``."""
        request = {
            "loops": [loops] if isinstance(loops, str) else list(loops),
            "method": method,
            "pid": pid,
            "form": form,
            "time_unit": time_unit,
        }
        for key, value in (
            ("measurement_dead_time", measurement_dead_time),
            ("measurement_lag", measurement_lag),
            ("relay_amplitude", relay_amplitude),
            ("hysteresis", hysteresis),
            ("scan", scan),
            ("step", step),
            ("model", model),
            ("tau_c", tau_c),
            ("level_band", level_band),
            ("flow_change", flow_change),
        ):
            if value is not None:
                request[key] = value
        folder = None if report is None else os.fspath(report)
        out = None if write is None else os.fspath(write)
        text, failed = _native.tune(self._text, self._name, assignments(set), json.dumps(request), folder, out)
        return _answer(text, failed)

    def identify(
        self,
        inputs: Sequence[str],
        outputs: Sequence[str],
        *,
        design: str = "directional",
        noise: float | Sequence[float] = (),
        seed: int = 1,
        duration: str | float | None = None,
        sample_time: str | float | None = None,
        tau_dom: str | float | None = None,
        amplitude: float | Sequence[float] = (),
        alpha: float = 2.0,
        beta: float = 3.0,
        high_gain_boost: float = 2.0,
        closed_loop: bool = False,
        units: str = "si",
        set: Mapping[str, Any] | None = None,
        report: str | os.PathLike | None = None,
        force: bool = False,
    ) -> dict:
        """``plantwide identify FILE --json``: a plant test of ``inputs`` on ``outputs`` (each
        ``PATH[@unit]``) on the nonlinear model, FIR/ARX/OE fits, their validation on a fresh test
        and a verdict (the reference book's chapter 7). ``noise`` and ``amplitude`` are in the
        signals' display units (``units``: si, metric, field, for a signal that names none).
        Returns the dict the CLI prints; ``report`` writes the CLI's ``--report`` folder (with
        ``step_model.json`` when the model is usable, or ``force``). A model the verdict finds not
        usable raises ``ConvergenceError`` after the report, the result kept as its ``result``."""
        listed = lambda v: [v] if isinstance(v, (int, float)) else list(v)
        request = {
            "inputs": list(inputs),
            "outputs": list(outputs),
            "design": design,
            "noise": listed(noise),
            "seed": seed,
            "amplitude": listed(amplitude),
            "alpha": alpha,
            "beta": beta,
            "high_gain_boost": high_gain_boost,
            "closed_loop": closed_loop,
            "units": units,
        }
        for key, value in (("duration", duration), ("sample_time", sample_time), ("tau_dom", tau_dom)):
            if value is not None:
                request[key] = value
        folder = None if report is None else os.fspath(report)
        text, failed = _native.identify(self._text, self._name, assignments(set), json.dumps(request), folder, force)
        return _answer(text, failed)

    def screen(
        self,
        column: str | None = None,
        outputs: Sequence[str] = (),
        *,
        cvs: Sequence[str] = (),
        mvs: Sequence[str] = (),
        throughput: Sequence[str] = (),
        disturbances: Sequence[str] = (),
        watch: Sequence[str] = (),
        steady_only: bool = False,
        keep_flowsheets: bool = False,
        allowed_deviation: Sequence[str | float] = (),
        candidates: int = 4,
        measurement_dead_time: str | float = "1 min",
        duration: str | float | None = None,
        mpc: Mapping | None = None,
        set: Mapping[str, Any] | None = None,
        report: str | os.PathLike | None = None,
        units: str = "si",
    ) -> dict:
        """``plantwide screen FILE … --json``: ``column``'s inventory configurations for its two
        ``outputs`` (top, bottom), ranked by a dynamic check or (``steady_only``) by their
        steady-state measures; or the pairings of ``cvs`` to ``mvs`` filtered at steady state and
        the best ``candidates`` tested on the nonlinear plant for ``disturbances``. Returns the dict
        the CLI prints; ``report`` writes the CLI's ``--report`` folder in ``units``. Parts without
        an answer raise ``ConvergenceError``, the result kept as the error's ``result``. For a
        pairing screen spread over a Dask cluster, see :func:`plantwide.screen_pairings`."""
        request = {
            "outputs": list(outputs),
            "cvs": list(cvs),
            "mvs": list(mvs),
            "throughput": list(throughput),
            "disturbances": list(disturbances),
            "watch": list(watch),
            "steady_only": steady_only,
            "keep_flowsheets": keep_flowsheets,
            "allowed_deviation": list(allowed_deviation),
            "candidates": int(candidates),
            "measurement_dead_time": measurement_dead_time,
        }
        for key, value in (("column", column), ("duration", duration), ("mpc", mpc)):
            if value is not None:
                request[key] = dict(value) if isinstance(value, Mapping) else value
        folder = None if report is None else os.fspath(report)
        text, failed = _native.screen(
            self._text, self._name, assignments(set), json.dumps(request), None, None, folder, units
        )
        return _answer(text, failed)

    def __repr__(self) -> str:
        return f"<Plant {self.name} ({self._name}): {len(self.variables)} variables, {len(self.inputs)} free inputs>"


def _answer(text: str, failed: str | None) -> dict:
    """A study's JSON as a dict; parts without an answer raise ``ConvergenceError`` with the same
    message as the CLI's exit 2, the result kept as its ``result``."""
    result = json.loads(text)
    if failed is not None:
        error = ConvergenceError(failed)
        error.result = result
        raise error
    return result


def load(path: str | os.PathLike) -> Plant:
    """Read and validate the flowsheet at ``path`` (``InputError`` lists every problem with its
    JSON path)."""
    name = os.fspath(path)
    return Plant(_native.read_text(name), name)


def compare(
    schemes: Sequence[str | os.PathLike | Plant],
    disturbances: Sequence[str],
    outputs: Sequence[str],
    *,
    loops: Sequence[str] = (),
    measurement_dead_time: str | float = "1 min",
    tuning: str = "blt",
    duration: str | float | None = None,
    heating_price: float | None = None,
    cooling_price: float | None = None,
    hours: float | None = None,
    report: str | os.PathLike | None = None,
    units: str = "si",
) -> dict:
    """``plantwide compare A.json B.json … --json``: two or more schemes (files or plants) side by
    side (energy and its yearly cost, control structure, stability, recycles, sensitivity,
    closed-loop responses, a verdict) for ``disturbances`` (``"PATH=±10%"``) and ``outputs``
    (``PATH[@unit]``). Returns the dict the CLI prints (SI); ``report`` writes the CLI's
    ``--report`` folder in ``units`` (si, metric, field). Parts without an answer raise
    ``ConvergenceError`` after the report is written, the result kept as the error's ``result``."""
    plants = [s if isinstance(s, Plant) else load(s) for s in schemes]
    request = {
        "disturbances": list(disturbances),
        "outputs": list(outputs),
        "loops": list(loops),
        "measurement_dead_time": measurement_dead_time,
        "tuning": tuning,
    }
    for key, value in (
        ("duration", duration),
        ("heating_price", heating_price),
        ("cooling_price", cooling_price),
        ("hours", hours),
    ):
        if value is not None:
            request[key] = value
    folder = None if report is None else os.fspath(report)
    text, failed = _native.compare([(p.text, p.file) for p in plants], json.dumps(request), folder, units)
    return _answer(text, failed)
