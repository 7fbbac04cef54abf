"""Reference values of the natural cubic spline for plantwide-expr's table tests.

Prints the table `crates/expr/tests/it/tables.rs` pins (`SPLINE_REFERENCE`): for the knots below,
SciPy's `CubicSpline(x, y, bc_type="natural")` (second derivative zero at both ends, the boundary
condition of `Interpolation::CubicSpline`) evaluated at points inside every interval, with its
first derivative.

Run: /work/main/target/ci-venv/bin/python tools/spline_reference.py
"""

import numpy as np
import scipy
from scipy.interpolate import CubicSpline

# Uneven knots and a curved, non-polynomial y (a vapour-pressure-like curve), so that every
# interval's cubic differs.
X = [300.0, 310.0, 325.0, 345.0, 350.0, 380.0]
Y = [0.35, 0.52, 0.91, 1.73, 2.01, 4.12]
POINTS = [301.0, 305.0, 309.5, 312.0, 317.5, 324.0, 330.0, 340.0, 346.0, 348.5, 351.0, 365.0, 379.0]

spline = CubicSpline(np.array(X), np.array(Y), bc_type="natural")
print(f"// scipy {scipy.__version__}, numpy {np.__version__}: CubicSpline(x, y, bc_type=\"natural\")")
print("const SPLINE_REFERENCE: [(f64, f64, f64); %d] = [" % len(POINTS))
for p in POINTS:
    print(f"    ({p!r}, {float(spline(p))!r}, {float(spline(p, 1))!r}),")
print("];")
