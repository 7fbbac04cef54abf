"""Gains, the linear model and its exports from Python against the CLI's JSON, against column A's
pinned published numbers, and against numpy/python-control computing the same measures anew."""

import json

import numpy as np
import plantwide as pw
import pytest
from conftest import COLUMN_A, LV_INPUTS, LV_OUTPUTS

# MATLAB `cola` linearization of column A (the repo's tests/it/analysis.rs pins the same numbers);
# S&P eq. 12.17's idealized model [0.878 −0.864; 1.082 −1.096], λ11 = 35.1.
COLA = np.array([[0.8780, -0.8644], [1.0819, -1.0958]])
PUBLISHED = np.array([[0.878, -0.864], [1.082, -1.096]])


@pytest.fixture(scope="module")
def plant():
    return pw.load(COLUMN_A)


def gains_args(method="linear"):
    return ["gains", COLUMN_A, "--inputs", ",".join(LV_INPUTS), "--outputs", ",".join(LV_OUTPUTS), "--json", "--method", method]


@pytest.mark.parametrize("method", ["linear", "perturb"])
def test_gains_equal_the_cli(plant, cli_json, method):
    g = plant.gains(LV_INPUTS, LV_OUTPUTS, method=method)
    cli = cli_json(gains_args(method))
    assert g.method == cli["method"] == method
    assert np.array_equal(g.gain, np.array(cli["gain"]))
    assert np.array_equal(g.rga, np.array(cli["rga"]))
    assert np.array_equal(g.singular_values, np.array(cli["singular_values"]))
    assert g.condition_number == cli["condition_number"] and g.niederlinski == cli["niederlinski"]
    assert [list(s) for s in g.inputs] == [[s["path"], s["unit"]] for s in cli["inputs"]]
    if method == "perturb":
        assert g.perturbation == cli["perturbation"]


def test_column_a_gains_match_the_published_ones(plant):
    g = plant.gains(LV_INPUTS, LV_OUTPUTS)
    assert np.max(np.abs(g.gain - COLA) / np.abs(COLA)) < 0.01, g.gain
    assert np.max(np.abs(g.gain - PUBLISHED) / np.abs(PUBLISHED)) < 0.03, g.gain
    # Every measure recomputed from the gain by numpy.
    rga = g.gain * np.linalg.inv(g.gain).T
    assert np.allclose(g.rga, rga, rtol=1e-10) and abs(g.rga[0, 0] - 35.1) < 0.05 * 35.1
    assert np.isclose(g.niederlinski, np.linalg.det(g.gain) / np.prod(np.diag(g.gain)), rtol=1e-10)
    u, s, vt = np.linalg.svd(g.gain)
    assert np.allclose(g.singular_values, s, rtol=1e-10)
    assert np.isclose(g.condition_number, s[0] / s[-1], rtol=1e-10)
    U, S, V = g.svd
    assert np.allclose(U @ np.diag(S) @ V.T, g.gain, rtol=1e-10, atol=1e-14)


def test_perturbation_agrees_with_linearization(plant):
    lin, pert = (plant.gains(LV_INPUTS, LV_OUTPUTS, method=m).gain for m in ["linear", "perturb"])
    assert np.max(np.abs(pert - lin) / np.abs(lin)) < 1e-5


def test_linear_model_equals_the_cli_export(plant, cli, tmp_path):
    m = plant.linearize(LV_INPUTS, LV_OUTPUTS)
    out = tmp_path / "model.json"
    cli(["linearize", COLUMN_A, "--inputs", ",".join(LV_INPUTS), "--outputs", ",".join(LV_OUTPUTS), "--out", str(out)])
    doc = json.loads(out.read_text())
    for k in "ABCD":
        assert np.array_equal(getattr(m, k), np.array(doc[k])), k
    assert m.states == [s["path"] for s in doc["states"]]
    assert doc["names"] == {"states": m.state_names, "inputs": m.input_names, "outputs": m.output_names}
    assert doc["labels"] == m.labels
    A, B, C, D = m
    assert A.shape == (82, 82) and B.shape == (82, 2) and C.shape == (2, 82) and D.shape == (2, 2)
    # The steady-state gain of the model is the gain report's (same units): D − C A⁻¹ B.
    dc = D - C @ np.linalg.solve(A, B)
    assert np.allclose(dc, plant.gains(LV_INPUTS, LV_OUTPUTS).gain, rtol=1e-6)


def test_safe_names_and_python_control(plant):
    control = pytest.importorskip("control")
    m = plant.linearize(LV_INPUTS, LV_OUTPUTS)
    assert m.output_names == ["distillate_x_light", "bottoms_x_light"]
    assert m.input_names == ["column_reflux", "column_boilup"]
    assert all(n.isidentifier() for n in m.state_names + m.input_names + m.output_names)
    assert len(set(m.state_names)) == len(m.state_names)
    sys = m.to_control()
    assert isinstance(sys, control.StateSpace)
    assert sys.input_labels == m.input_names and sys.output_labels == m.output_names
    assert np.allclose(control.dcgain(sys), plant.gains(LV_INPUTS, LV_OUTPUTS).gain, rtol=1e-6)
    assert m.labels["outputs"]["distillate_x_light"] == "distillate.x[light]"


def test_npz_exports(plant, cli, tmp_path):
    m = plant.linearize(LV_INPUTS, LV_OUTPUTS)
    cli_npz, py_npz = tmp_path / "cli.npz", tmp_path / "py.npz"
    cli(["linearize", COLUMN_A, "--inputs", ",".join(LV_INPUTS), "--outputs", ",".join(LV_OUTPUTS), "--out", str(cli_npz)])
    m.to_npz(py_npz)
    a, b = np.load(cli_npz), np.load(py_npz)  # no pickles: allow_pickle stays False
    assert sorted(a.files) == sorted(b.files)
    for k in a.files:
        assert a[k].dtype.kind == b[k].dtype.kind and np.array_equal(a[k], b[k]), k
    assert list(a["output_names"]) == m.output_names and list(a["output_paths"]) == LV_OUTPUTS
    assert str(a["time_unit"]) == "s" and np.array_equal(a["A"], m.A)
