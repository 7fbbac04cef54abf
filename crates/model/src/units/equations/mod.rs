//! A unit written as equations in the flowsheet file (issue 57): parameters with units, its own
//! differential and algebraic variables, equations as text, inlet and outlet ports and inputs.
//!
//! ```json
//! {"type": "equations",
//!  "parameters": {"area": "0.5 m2", "rho": "1e4 mol/m3", "k": "2 mol/(s*m)"},
//!  "variables": {"M": {"kind": "differential", "unit": "mol", "guess": 5000},
//!                "level": {"kind": "algebraic", "unit": "m", "guess": 1, "lower": 0}},
//!  "equations": ["der(M) = in.F - out.F", "level*area*rho = M"],
//!  "ports": {"inlets": ["in"],
//!            "outlets": {"out": {"F": "k*level", "T": "in.T", "P": "in.P", "x[A]": "in.x[A]", "x[B]": "in.x[B]"}}}}
//! ```
//!
//! # Names in equations
//! Parameters and inputs by their names, own variables by theirs, and every port's stream
//! quantities as `<port>.F`, `<port>.T`, `<port>.P`, `<port>.h` and `<port>.x[<component>]`.
//!
//! # Thermodynamic functions of a port's state
//! The flowsheet's thermodynamic package, called with a port's name (an inlet's or an outlet's):
//!
//! | call | value | unit | reads |
//! |---|---|---|---|
//! | `h_L(port)` | liquid molar enthalpy `Σ x_i h_L,i(T)` | J/mol | `T`, `x` |
//! | `h_V(port)` | vapour molar enthalpy `Σ x_i h_ig,i(T)` (the port's `x` as the vapour) | J/mol | `T`, `x` |
//! | `K(port, c)` | K-value `y_c/x_c` of component `c` at the port's `T`, `P`, `x` | 1 | `T`, `P`, `x` |
//! | `rho_L(port)` | liquid **molar** density `1/v_L(T, x)` | mol/m³ | `T`, `x` |
//! | `mw(port)` | mean molar mass `Σ x_i M_i` (so `mw(p)*rho_L(p)` is the mass density) | kg/mol | `x` |
//! | `T_bubble(port)` | bubble temperature at the port's `P` and `x/Σx` | K | `P`, `x` |
//!
//! `K` and `T_bubble` take an optional last argument naming a pressure variable or input of the
//! unit to use instead of the port's `P`: `K(liquid, benzene, P)` is the K-value of the liquid in
//! a drum at pressure `P` whose liquid outlet leaves at the valve's downstream pressure.
//! Components are written as in `x[…]` (`K(out, o-xylene)`). The arguments are names, not
//! expressions. A parameter, input, variable or table of the file that takes one of these names
//! hides the function.
//!
//! Derivatives are exact: the expression layer asks each call for its value and its partial
//! derivatives with respect to the port quantities it reads (the package's functions evaluated
//! over dual numbers, one pass per quantity; the bubble temperature's by the implicit-function
//! theorem on the bubble-point residual `Σ K_i x_i − 1` at the converged temperature, as
//! `ThermoPackage::bubble_t` converges it to machine precision). Each call's row of the sparsity
//! pattern holds exactly the quantities in the table's last column.
//!
//! # Tables
//! `"tables": {"cp": {"x": [300, 350, 400], "y": [1.0, 1.5, 3.0], "x_unit": "K",
//! "y_unit": "kJ/(kg*K)", "interpolation": "spline"}}` declares `cp(expr)`: `expr` must have the
//! dimension of `x_unit`, the value has that of `y_unit` (both default dimensionless).
//! `interpolation` is `linear` (default) or `spline`, the natural cubic spline (zero second
//! derivative at both ends, as SciPy's `CubicSpline(bc_type="natural")`); beyond the ends the
//! table continues along its end tangent. At load, fewer than 2 points, `x` and `y` of unequal
//! lengths, an `x` not strictly increasing, or a value not finite in SI are refused at the
//! offending point (`units.u.tables.cp.x[2]`).

//! # Layout and the mass matrix
//! Own variables are the outlet streams (`[F, T, P, h, x…]` each, ports in name order), then the
//! `variables` in name order. Every name is bound to its slot of the unit's *local vector*, so the
//! compiled tapes read [`UnitIo::local`] directly (no copy) with an empty `dx`.
//!
//! The engine's DAE is semi-explicit, `M x' = f(x)`: the residual of a differential variable is
//! its time derivative. So each differential variable needs exactly one equation
//! `der(x) = rhs` with `rhs` free of `der()`; its residual is `rhs` (not `der(x) − rhs`), written
//! at the variable's own row, where the mass matrix has its 1. Every other equation is algebraic,
//! residual `lhs − rhs`, placed at the row of the algebraic unknown a perfect matching assigns it
//! (as `check_structure` in dynamic mode, the closed outlet enthalpies included): so the unit is
//! square and its rows pair with unknowns. In dynamic mode a differential variable is a known
//! state, so `der(x) = rhs` can only take `der(x)`: its row is always `x`'s own.
//!
//! # Ports
//! Inlets are read as known values. Each outlet maps some of its stream quantities to
//! expressions, each the equation `out.Q = expr`; a quantity it does not map (`F`, `T`, `P`,
//! `x[c]`) is an unknown the `equations` must determine (`U = M*out.h` gives `out.T`), else the set
//! is refused as structurally singular naming it. An unmapped `h` is closed by the unit with the
//! equation `out.h = h_L(out)`, compiled like the others (the same exact derivatives and the
//! same sparsity: `h`, `T` and every `x`); the matching places it like the others (with
//! `U = M*out.h` it takes `out.T`'s row and the balance `h`'s).
//!
//! # Material
//! `holdup` gives each component's amount \[mol\] as an expression (for a dynamic run's
//! conservation check) and `reacts: true` makes the steady-state certificate check mass instead
//! of each component; without them the unit is taken to hold nothing and to conserve every
//! component.
//!
//! # Checks at load
//! Names, dimensions (both sides, each outlet mapping against its stream quantity), the `der()`
//! form, a structurally singular set (dynamic mode), bad tables, unknown ports or components in
//! thermodynamic calls, and each equation evaluated at the guesses: a division by zero, a
//! logarithm of a non-positive number or a thermodynamic function that cannot be evaluated
//! there is refused with its position. The guesses are the variables' `guess`es and the outlets
//! the unit's own guess; the inlets hold the stream the engine starts every stream from before
//! it guesses the units (1 mol/s, 300 K, 1 atm, uniform `x`, its liquid enthalpy), because a
//! unit is built before the plant is wired and the upstream guesses are not known then.

use std::collections::BTreeMap;

use plantwide_expr::{Equation, Expression, SymbolTable, parse_equation};
use plantwide_units::{Dimension, QuantityValue};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::stream::{F, H, P, T, Z0};
use crate::{InputSpec, LocalLayout, Scalar, UnitIo, UnitModel, VarSpec};

mod build;
mod thermo;
#[cfg(test)]
mod thermo_tests;

/// Whether a variable of an equations unit has a time derivative.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum EqVarKind {
    /// Given by one equation `der(x) = rhs`.
    Differential,
    /// Determined by the algebraic equations.
    Algebraic,
}

/// One variable of an equations unit; `guess`, `nominal`, `lower` and `upper` are in `unit`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EqVariableConfig {
    /// Differential or algebraic.
    pub kind: EqVarKind,
    /// Unit of the values below and hence the variable's dimension (`"mol"`, `"K"`,
    /// `"mol/m3"`; default dimensionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
    /// Typical magnitude, for scaling (default: |guess|, or 1 if that is 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal: Option<f64>,
    /// Initial guess (default: the nominal, else 0 … within the bounds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub guess: Option<f64>,
    /// Lower bound Newton honours (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    /// Upper bound Newton honours (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
}

/// How a table of an equations unit interpolates.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum EqInterpolation {
    /// Straight lines between the points (the default).
    #[default]
    Linear,
    /// The natural cubic spline (second derivative zero at both ends).
    Spline,
}

/// A table `y(x)` of an equations unit, called in equations as `name(expr)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EqTableConfig {
    /// The argument's values, strictly increasing, in `x_unit` (at least 2).
    pub x: Vec<f64>,
    /// The values at each `x`, in `y_unit` (as many as `x`).
    pub y: Vec<f64>,
    /// Unit of `x` and hence the argument's dimension (`"K"`, `"m"`; default dimensionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_unit: Option<String>,
    /// Unit of `y` and hence the value's dimension (`"kJ/mol"`, `"m3"`; default dimensionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_unit: Option<String>,
    /// `linear` (default) or `spline`.
    #[serde(default)]
    pub interpolation: EqInterpolation,
}

/// The ports of an equations unit.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EqPortsConfig {
    /// Inlet port names; their stream quantities (`in.F`, `in.x[A]`, …) are known values.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inlets: Vec<String>,
    /// Outlet ports by name, each mapping some of its stream quantities (`F`, `T`, `P`, `x[<c>]`,
    /// `h`) to expressions; the equations determine the others, and an unmapped `h` is closed as
    /// `h = h_L(out)`, the liquid enthalpy at the outlet's `T` and `x`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub outlets: BTreeMap<String, BTreeMap<String, String>>,
}

/// Flowsheet description of a unit written as equations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EquationsConfig {
    /// Constants by name, with units (`"0.5 m3"`, `"80 kJ/mol"`; a bare number is dimensionless).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub parameters: BTreeMap<String, QuantityValue>,
    /// Manipulable inputs by name, with units and their value when no controller drives them.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub inputs: BTreeMap<String, QuantityValue>,
    /// The unit's own variables by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub variables: BTreeMap<String, EqVariableConfig>,
    /// Tables `y(x)` by name, called in equations as `name(expr)`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub tables: BTreeMap<String, EqTableConfig>,
    /// Equations as text (`"der(M) = in.F - out.F"`).
    pub equations: Vec<String>,
    /// Inlet and outlet ports.
    #[serde(default)]
    pub ports: EqPortsConfig,
    /// Names of the variables that can be measured (default none listed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<String>,
    /// The amount (mol) of each component the unit holds, as an expression (`{"A": "NA"}`;
    /// unlisted components hold none); without it the unit holds no material, and a dynamic
    /// run's conservation check would miss what it accumulates.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub holdup: BTreeMap<String, String>,
    /// The heat duties \[W\] it takes from utilities, by name: own variables or inputs, heating
    /// when positive (as the built-in CSTR's jacket `Q`), so that `compare` books them in the
    /// plant's energy use and utility cost (default none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub duties: Vec<String>,
    /// Whether the equations turn components into one another (default false): the steady-state
    /// certificate then checks the plant's mass balance, not each component's.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reacts: bool,
}

impl crate::registry::UnitConfig for EquationsConfig {
    fn ports() -> &'static str {
        "the inlets and outlets its `ports` name"
    }
    /// A unit that holds a level is a vessel to `size` when its parameters give the geometry by
    /// the built-in vessels' names: `area` or `diameter`, and `height`; `size` sets the one
    /// written (`--set tank.area=…` reaches a parameter) and reads the unit's `level`, `M` and
    /// `V` as it does a tank's.
    fn vessel(&self) -> Option<crate::registry::VesselGeometry<'_>> {
        let (diameter, area) = (self.parameters.get("diameter"), self.parameters.get("area"));
        let holds_level = self.variables.contains_key("level");
        (holds_level && (diameter.is_some() || area.is_some())).then(|| crate::registry::VesselGeometry {
            diameter,
            area,
            height: self.parameters.get("height"),
        })
    }
}

/// How a compiled equation writes its residual.
#[derive(Debug, Clone, PartialEq)]
enum Row {
    /// `der(x) = rhs`: the residual is `rhs` (the time derivative of own variable `row`).
    Derivative { row: usize, rhs: Expression },
    /// `lhs = rhs`: the residual is `lhs − rhs`.
    Algebraic { row: usize, eq: Equation },
}

/// A unit written as equations.
#[derive(Debug, Clone)]
pub struct Equations {
    inlets: Vec<String>,
    outlets: Vec<String>,
    internal: Vec<VarSpec>,
    guesses: Vec<f64>,
    inputs: Vec<InputSpec>,
    rows: Vec<Row>,
    /// The field each row comes from (`equations[2]`, `ports.outlets.out.F`).
    fields: Vec<String>,
    /// The outlets' mappings `out.Q = expr` by the local index of `out.Q`, for the guess.
    maps: Vec<(usize, Equation)>,
    /// Names of own rows, for diagnostics.
    row_names: BTreeMap<usize, String>,
    outputs: Vec<String>,
    /// The duties `duties` names.
    duties: Vec<crate::capability::Duty>,
    reacts: bool,
    /// Per component, the expression of its holdup \[mol\] (`None`: none held); empty: no holdup.
    holdup: Vec<Option<Expression>>,
}

/// Stream quantities of a port, with their offsets in a stream block and dimensions.
fn stream_names(port: &str, components: &[String]) -> Vec<(String, usize, Dimension)> {
    let mut v = vec![
        (format!("{port}.F"), F, Dimension::MOLAR_FLOW),
        (format!("{port}.T"), T, Dimension::TEMPERATURE),
        (format!("{port}.P"), P, Dimension::PRESSURE),
        (format!("{port}.h"), H, Dimension::MOLAR_ENERGY),
    ];
    v.extend(components.iter().enumerate().map(|(i, c)| (format!("{port}.x[{c}]"), Z0 + i, Dimension::DIMENSIONLESS)));
    v
}

impl Equations {
    /// The names the file declares measurable (`outputs`).
    pub fn outputs(&self) -> &[String] {
        &self.outputs
    }

    /// Structural nonzeros `(row, local column)`: what each row's tape reads.
    fn row_reads(&self) -> Vec<(usize, usize)> {
        let mut p = Vec::new();
        for row in &self.rows {
            let (r, vars) = match row {
                Row::Derivative { row, rhs } => (*row, rhs.variables()),
                Row::Algebraic { row, eq } => (*row, eq.variables()),
            };
            p.extend(vars.iter().map(|&j| (r, j)));
        }
        p
    }
}

/// The right-hand side of `text` compiled alone if `text` reads `der(name) = rhs` with `rhs`
/// free of `der()`.
fn der_form(text: &str, symbols: &SymbolTable) -> Option<Expression> {
    let ast = parse_equation(text).ok()?;
    if !matches!(ast.lhs.kind, plantwide_expr::ast::ExprKind::Der { .. }) {
        return None;
    }
    let rhs = Expression::new(ast.rhs.span.slice(text), symbols).ok()?;
    rhs.derivatives().is_empty().then_some(rhs)
}

impl UnitModel for Equations {
    fn type_name(&self) -> &'static str {
        "equations"
    }
    fn inlet_ports(&self) -> Vec<String> {
        self.inlets.clone()
    }
    fn outlet_ports(&self) -> Vec<String> {
        self.outlets.clone()
    }
    fn duties(&self) -> Vec<crate::capability::Duty> {
        self.duties.clone()
    }
    fn boundary(&self) -> crate::Boundary {
        // By its ports, as the flowsheet's boundaries go: no inlet (a port-less model too) is a
        // source, no outlet a sink.
        match (self.inlets.is_empty(), self.outlets.is_empty()) {
            (true, _) => crate::Boundary::Source,
            (false, true) => crate::Boundary::Sink,
            (false, false) => crate::Boundary::Interior,
        }
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        self.internal.clone()
    }
    fn inputs(&self) -> Vec<InputSpec> {
        self.inputs.clone()
    }
    fn reacts(&self) -> bool {
        self.reacts
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        if self.holdup.is_empty() {
            return None;
        }
        Some(self.holdup.iter().map(|e| e.as_ref().map_or(0.0, |e| e.value(io.local, &[]))).collect())
    }
    fn equation_name(&self, k: usize, own_names: &[String]) -> String {
        match (self.row_names.get(&k), own_names.get(k)) {
            (Some(text), Some(own)) => format!("{text} (row of {own})"),
            (Some(text), None) => text.clone(),
            (None, _) => format!("equation {k}"),
        }
    }
    fn pattern(&self, _layout: &LocalLayout) -> Option<Vec<(usize, usize)>> {
        Some(self.row_reads())
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        for row in &self.rows {
            match row {
                Row::Derivative { row, rhs } => r[*row] = rhs.value(io.local, &[]),
                Row::Algebraic { row, eq } => r[*row] = eq.residual(io.local, &[]),
            }
        }
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let len = io.layout.stream.len();
        let n_out = self.outlets.len();
        own[n_out * len..].copy_from_slice(&self.guesses);
        // Outlets: a copy of the first inlet (else a representative stream), then each mapping
        // evaluated at that guess, then the liquid enthalpy where the unit closes it.
        for k in 0..n_out {
            let s = &mut own[k * len..(k + 1) * len];
            if self.inlets.is_empty() {
                build::cold_start_stream(io.thermo, s);
            } else {
                s.copy_from_slice(io.inlet(0).v);
            }
        }
        let mut local = io.local.to_vec();
        local[..own.len()].copy_from_slice(own);
        for (i, eq) in &self.maps {
            // `out.Q = expr`: the residual is out.Q − expr, so out.Q − residual is expr.
            let v = local[*i] - eq.residual(&local, &[]);
            if v.is_finite() {
                local[*i] = v;
            }
        }
        own.copy_from_slice(&local[..own.len()]);
    }
    /// Every equation evaluated at the plant's guess, with the inlets the upstream units guessed:
    /// a zero denominator, a logarithm out of its domain or a thermodynamic function that fails
    /// there would stop Newton at its first step, and is refused with its position.
    fn check_guess(&self, io: &UnitIo<'_, f64>) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for (row, field) in self.rows.iter().zip(&self.fields) {
            let result = match row {
                Row::Derivative { rhs, .. } => rhs.check_at(io.local, &[]),
                Row::Algebraic { eq, .. } => eq.check_at(io.local, &[]),
            };
            if let Err(e) = result {
                out.push((field.clone(), format!("at the guess: {}", e.render())));
            }
        }
        out
    }
    fn checks_guess(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::outflow::test_support::{at_guess, build_unit, solve_own};
    use super::*;
    use crate::testing::{binary_package, jacobian_error};
    use crate::{BuildCx, FieldError, Unit};

    /// A surge tank as equations: holdup `M` \[mol\], level from a constant molar density, outflow
    /// proportional to the level.
    const TANK: &str = r#"{
        "parameters": {"area": "0.5 m2", "rho": "1e4 mol/m3", "k": "2 mol/(s*m)"},
        "variables": {"M": {"kind": "differential", "unit": "kmol", "guess": 5, "lower": 0},
                      "level": {"kind": "algebraic", "unit": "m", "guess": 1, "lower": 0}},
        "equations": ["der(M) = in.F - out.F", "level*area*rho = M"],
        "ports": {"inlets": ["in"],
                  "outlets": {"out": {"F": "k*level", "T": "in.T", "P": "in.P",
                                      "x[light]": "in.x[light]", "x[heavy]": "in.x[heavy]"}}},
        "outputs": ["level"],
        "holdup": {"light": "M*out.x[light]", "heavy": "M*out.x[heavy]"}
    }"#;

    fn feed(thermo: &plantwide_thermo::ThermoPackage) -> [f64; 6] {
        [10.0, 320.0, 2e5, thermo.h_liq(320.0, &[0.4, 0.6]), 0.4, 0.6]
    }

    #[test]
    fn tank_residuals_and_exact_jacobian() {
        let thermo = binary_package();
        let u = build_unit(TANK, &thermo, Equations::build);
        let vars: Vec<String> = UnitModel::internal_vars(&u).iter().map(|v| v.name.clone()).collect();
        assert_eq!(vars, ["M", "level"]);
        assert_eq!(UnitModel::internal_vars(&u)[0].kind, crate::VarKind::Differential);
        assert_eq!(UnitModel::internal_vars(&u)[0].nominal, 5000.0);
        let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
        // Own: out [F, T, P, h, x_l, x_h] = 0..6, M = 6, level = 7; inlet 8..14.
        let (m, level, fout) = (4000.0, 1.3, 2.9);
        local[6] = m;
        local[7] = level;
        local[0] = fout;
        local[1] = 330.0;
        let n = local.len();
        let (mut r, mut jac) = (vec![0.0; 8], vec![0.0; 8 * n]);
        u.jacobian(&UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut r, &mut jac);
        let (area, rho, k) = (0.5, 1e4, 2.0);
        assert_eq!(r[6], 10.0 - fout, "der(M) row: the time derivative, in − out");
        assert_eq!(r[7], level * area * rho - m);
        assert_eq!(r[0], fout - k * level);
        assert_eq!(r[1], 330.0 - 320.0);
        assert_eq!(r[3], local[3] - thermo.h_liq(330.0, &local[4..6]));
        let mut want = vec![0.0; 8 * n];
        let mut set = |row: usize, col: usize, v: f64| want[row * n + col] = v;
        set(6, 8, 1.0); // ∂(in.F − out.F)/∂in.F
        set(6, 0, -1.0);
        set(7, 7, area * rho);
        set(7, 6, -1.0);
        set(0, 0, 1.0);
        set(0, 7, -k);
        for (row, own, inlet) in [(1, 1, 9), (2, 2, 10), (4, 4, 12), (5, 5, 13)] {
            set(row, own, 1.0);
            set(row, inlet, -1.0);
        }
        for row in [0, 1, 2, 4, 5, 6, 7] {
            for col in 0..n {
                assert_eq!(jac[row * n + col], want[row * n + col], "∂r{row}/∂x{col}");
            }
        }
        let err = jacobian_error(&u, &lay, &thermo, &local, 8);
        assert!(err < 1e-8, "{err}");
        // The declared pattern holds every nonzero.
        let pattern = UnitModel::pattern(&u, &lay).unwrap();
        for row in 0..8 {
            for col in 0..n {
                if jac[row * n + col] != 0.0 {
                    assert!(pattern.contains(&(row, col)), "({row}, {col}) missing from the pattern");
                }
            }
        }
    }

    #[test]
    fn boundary_follows_the_ports() {
        let thermo = binary_package();
        let boundary = |json: &str| UnitModel::boundary(&build_unit(json, &thermo, Equations::build));
        assert_eq!(boundary(TANK), crate::Boundary::Interior);
        let sink = r#"{"variables": {"M": {"kind": "differential", "unit": "mol", "guess": 1}},
                       "equations": ["der(M) = in.F"], "ports": {"inlets": ["in"]}}"#;
        assert_eq!(boundary(sink), crate::Boundary::Sink);
        let portless = r#"{"parameters": {"tau": "1 s"}, "variables": {"y": {"kind": "differential", "guess": 1}}, "equations": ["der(y) = -y/tau"]}"#;
        assert_eq!(boundary(portless), crate::Boundary::Source);
    }

    #[test]
    fn tank_steady_state() {
        let thermo = binary_package();
        let u = build_unit(TANK, &thermo, Equations::build);
        let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
        assert_eq!(local[0], 2.0, "outlet flow guessed from its mapping at the guessed level");
        let norm = solve_own(&u, &lay, &thermo, &mut local);
        assert!(norm < 1e-12, "{norm}");
        // F_out = F_in = k·level, M = level·area·rho.
        assert!((local[7] - 5.0).abs() < 1e-12 && (local[6] - 25_000.0).abs() < 1e-9, "{:?}", &local[..8]);
        assert!((local[3] - thermo.h_liq(320.0, &[0.4, 0.6])).abs() < 1e-9);
        let n = UnitModel::holdup(&u, &UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }).unwrap();
        assert!((n[0] - 10_000.0).abs() < 1e-8 && (n[1] - 15_000.0).abs() < 1e-8, "{n:?}");
    }

    fn build_err(json: &str) -> Vec<FieldError> {
        let thermo = binary_package();
        let names = ["light".to_string(), "heavy".to_string()];
        let mut v: serde_json::Value = serde_json::from_str(TANK).unwrap();
        let patch: serde_json::Value = serde_json::from_str(json).unwrap();
        for (k, x) in patch.as_object().unwrap() {
            v[k] = x.clone();
        }
        let c: EquationsConfig = serde_json::from_value(v).unwrap();
        Equations::build(&c, BuildCx::new(&names, &thermo, "units.u"), ()).unwrap_err()
    }

    #[test]
    fn errors_name_the_field_and_the_position() {
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "level*area = M"]}"#);
        assert_eq!(e[0].path, "units.u.equations[1]");
        assert!(e[0].message.contains("found m3 and mol\nlevel*area = M\n^^^^^^^^^^^^^^"), "{}", e[0].message);
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "levl*area*rho = M"]}"#);
        assert!(e[0].message.contains("did you mean `level`"), "{}", e[0].message);
        let e = build_err(r#"{"equations": ["2*der(M) = in.F - out.F", "level*area*rho = M"]}"#);
        assert_eq!(e[0].path, "units.u.equations[0]");
        assert!(
            e[0].message.contains("write the equation of a differential variable as `der(M) ="),
            "{}",
            e[0].message
        );
        let e = build_err(r#"{"equations": ["level*area*rho = M"]}"#);
        assert_eq!(e[0].path, "units.u.variables.M");
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "der(M) = in.F", "level*area*rho = M"]}"#);
        assert!(e[0].message.contains("already given by equations[0]"), "{}", e[0].message);
        // Structurally singular: level is read by no equation once its equation names only M.
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "M = area*rho*in.F/k"]}"#);
        assert_eq!(e[0].path, "units.u.equations");
        assert!(e[0].message.contains("structurally singular"), "{}", e[0].message);
        // A zero denominator at the guess (level = 1 m), whatever the inlet.
        let thermo = binary_package();
        let names = ["light".to_string(), "heavy".to_string()];
        let mut v: serde_json::Value = serde_json::from_str(TANK).unwrap();
        v["parameters"]["l0"] = "1 m".into();
        v["equations"] = serde_json::json!(["der(M) = in.F - out.F", "area*rho = M/(level - l0)"]);
        let c: EquationsConfig = serde_json::from_value(v).unwrap();
        let u = Equations::build(&c, BuildCx::new(&names, &thermo, "units.u"), ()).unwrap();
        let (lay, local) = at_guess(&u, &thermo, &feed(&thermo));
        let e = Unit::check_guess(&u, &UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 });
        assert_eq!(e[0].0, "equations[1]");
        assert!(e[0].1.starts_with("at the guess:") && e[0].1.contains("^"), "{}", e[0].1);
        let e = build_err(
            r#"{"ports": {"inlets": ["in"], "outlets": {"out": {"F": "k*level", "T": "in.T", "P": "in.P"}}}}"#,
        );
        assert!(e[0].path == "units.u.equations" && e[0].message.contains("`out.x[light]`"), "{}", e[0].message);
        let e = build_err(r#"{"holdup": {"light": "level"}}"#);
        assert!(e[0].path == "units.u.holdup.light" && e[0].message.contains("found m"), "{}", e[0].message);
        let e = build_err(r#"{"outputs": ["levle"]}"#);
        assert!(e[0].message.contains("did you mean `level`"), "{}", e[0].message);
        assert!(serde_json::from_str::<EquationsConfig>(r#"{"equations": [], "volume": 1}"#).is_err());
    }
}

#[cfg(test)]
mod timing {
    use std::time::Instant;

    use super::super::cstr::Cstr;
    use super::super::outflow::test_support::{at_guess, build_unit};
    use super::*;
    use crate::Unit;
    use crate::testing::binary_package;

    /// The reactor of a flowsheet file, its components renamed to the test package's.
    fn reactor(rel: &str) -> String {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel);
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let mut r = v["units"]["reactor"].clone();
        r.as_object_mut().unwrap().remove("type");
        r.to_string()
            .replace("[A]", "[light]")
            .replace("[B]", "[heavy]")
            .replace("\"A\":", "\"light\":")
            .replace("\"B\":", "\"heavy\":")
    }

    fn per_call(u: &dyn Unit, thermo: &plantwide_thermo::ThermoPackage) -> f64 {
        let feed = [10.0, 300.0, 2e6, thermo.h_liq(300.0, &[1.0, 0.0]), 1.0, 0.0];
        let (lay, local) = at_guess(u, thermo, &feed);
        let (n, m) = (local.len(), lay.n_own());
        let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * n]);
        let io = UnitIo { local: &local, layout: &lay, thermo, time: 0.0 };
        let reps = 20_000;
        let t0 = Instant::now();
        for _ in 0..reps {
            u.residual(&io, &mut r);
            u.jacobian(&io, &mut r, &mut jac);
        }
        t0.elapsed().as_secs_f64() / reps as f64
    }

    /// Issue 57 asks the equation version's residual + Jacobian within 3× of the built-in's.
    #[test]
    #[ignore = "timing: cargo test -p plantwide-model --lib timing -- --ignored --nocapture"]
    fn cstr_residual_and_jacobian_time() {
        let mut thermo = binary_package();
        thermo.components[1] =
            plantwide_thermo::Component::hypothetical("heavy", 1.0, 0.05, 3.0e4, 350.0, 150.0, 1.0e-4);
        let builtin = build_unit(&reactor("flowsheets/cstr_multiplicity.json"), &thermo, Cstr::build);
        let eqs = build_unit(&reactor("tests/data/cstr_equations.json"), &thermo, Equations::build);
        let (tb, te) = (per_call(&builtin, &thermo), per_call(&eqs, &thermo));
        eprintln!(
            "residual + Jacobian: built-in cstr {:.2} µs, equations {:.2} µs, ratio {:.2}",
            tb * 1e6,
            te * 1e6,
            te / tb
        );
    }
}
