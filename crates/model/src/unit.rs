//! The unit interface.
//!
//! A unit reads one contiguous *local vector* laid out as
//! `[own variables | inlet stream 0 | inlet stream 1 | … | inputs | signals]`, where
//! - *own variables* are its outlet streams (in outlet-port order, `nc + 4` each) followed by its
//!   internal variables ([`UnitModel::internal_vars`]);
//! - *inputs* are its declared manipulable inputs (valve openings, flows, duties): constants from
//!   the flowsheet or the output variable of a controller;
//! - *signals* are measured variables (controllers only), resolved from variable paths.
//!
//! It writes [`UnitModel::n_equations`] residuals. Residual `k < n_own` belongs to own variable `k`;
//! for a differential variable it is that variable's time derivative, so the mass matrix of the plant
//! has a 1 at (equation of `k`, variable `k`). Units that share a flow with a neighbour (a vessel
//! whose outflow a downstream valve sets) may own more variables than equations or the reverse; the
//! plant as a whole is square.

use num_dual::{Dual64, HyperDual64};
use plantwide_thermo::ThermoPackage;
use plantwide_units::Dimension;

use crate::capability::{Boundary, Duty, MaterialFlows, Shape, UtilityFlow};
use crate::{InputError, Scalar, Stream, StreamLayout, VarSpec};

/// A manipulable input declared by a unit.
#[derive(Debug, Clone, PartialEq)]
pub struct InputSpec {
    /// Local name (`"opening"`, `"duty"`, `"F"`); the path is `unit.name`.
    pub name: String,
    /// SI dimension.
    pub dim: Dimension,
    /// Value from the flowsheet (SI), used when no controller drives the input.
    pub value: f64,
}

/// A measured variable a controller reads, by path.
#[derive(Debug, Clone, PartialEq)]
pub struct SignalSpec {
    /// Role in the controller (`"pv"`, `"sp"`, `"in1"`, …).
    pub role: String,
    /// Variable path to read (`"tank.level"`, `"distillate.x[light]"`).
    pub path: String,
}

/// Offsets of the blocks of a unit's local vector.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LocalLayout {
    /// Stream block layout.
    pub stream: StreamLayout,
    /// Number of outlet streams.
    pub n_outlets: usize,
    /// Number of internal variables.
    pub n_internal: usize,
    /// Number of inlet streams.
    pub n_inlets: usize,
    /// Number of inputs.
    pub n_inputs: usize,
    /// Number of signals.
    pub n_signals: usize,
}

impl LocalLayout {
    /// Number of own variables.
    pub fn n_own(&self) -> usize {
        self.n_outlets * self.stream.len() + self.n_internal
    }
    /// Offset of the first inlet stream.
    pub fn inlets_offset(&self) -> usize {
        self.n_own()
    }
    /// Offset of the first input.
    pub fn inputs_offset(&self) -> usize {
        self.inlets_offset() + self.n_inlets * self.stream.len()
    }
    /// Offset of the first signal.
    pub fn signals_offset(&self) -> usize {
        self.inputs_offset() + self.n_inputs
    }
    /// Length of the local vector.
    pub fn len(&self) -> usize {
        self.signals_offset() + self.n_signals
    }
    /// True if the unit reads nothing and owns nothing.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// What a unit sees during evaluation.
#[derive(Debug, Clone, Copy)]
pub struct UnitIo<'a, S> {
    /// The local vector (see the module documentation).
    pub local: &'a [S],
    /// Its layout.
    pub layout: &'a LocalLayout,
    /// Thermodynamic package of the flowsheet.
    pub thermo: &'a ThermoPackage,
    /// Simulation time [s] (0 at steady state).
    pub time: f64,
}

impl<'a, S: Scalar> UnitIo<'a, S> {
    /// Outlet stream `k` (own variables).
    pub fn outlet(&self, k: usize) -> Stream<'a, S> {
        let n = self.layout.stream.len();
        Stream { v: &self.local[k * n..(k + 1) * n] }
    }
    /// Internal variable `i`.
    pub fn var(&self, i: usize) -> S {
        self.local[self.layout.n_outlets * self.layout.stream.len() + i]
    }
    /// Internal variables `i..i+len`.
    pub fn vars(&self, i: usize, len: usize) -> &'a [S] {
        let o = self.layout.n_outlets * self.layout.stream.len() + i;
        &self.local[o..o + len]
    }
    /// Inlet stream `k`.
    pub fn inlet(&self, k: usize) -> Stream<'a, S> {
        let n = self.layout.stream.len();
        let o = self.layout.inlets_offset() + k * n;
        Stream { v: &self.local[o..o + n] }
    }
    /// Input `k`.
    pub fn input(&self, k: usize) -> S {
        self.local[self.layout.inputs_offset() + k]
    }
    /// Signal `k`.
    pub fn signal(&self, k: usize) -> S {
        self.local[self.layout.signals_offset() + k]
    }
    /// Number of components.
    pub fn n_comp(&self) -> usize {
        self.layout.stream.n_comp
    }
}

/// A unit model, written once and generic over the scalar so that dual numbers give its exact
/// Jacobian. Implement this; the object-safe [`Unit`] follows from a blanket implementation.
pub trait UnitModel: Send + Sync + std::fmt::Debug {
    /// Type name as in flowsheet files (`"mixer"`).
    fn type_name(&self) -> &'static str;
    /// Inlet port names, in local order (default none: controllers).
    fn inlet_ports(&self) -> Vec<String> {
        Vec::new()
    }
    /// Outlet port names, in local order (default none: controllers, sinks).
    fn outlet_ports(&self) -> Vec<String> {
        Vec::new()
    }
    /// Internal (non-stream) variables, after the outlet streams in the own block.
    fn internal_vars(&self) -> Vec<VarSpec> {
        Vec::new()
    }
    /// Declared manipulable inputs.
    fn inputs(&self) -> Vec<InputSpec> {
        Vec::new()
    }
    /// Measured signals (controllers).
    fn signals(&self) -> Vec<SignalSpec> {
        Vec::new()
    }
    /// Number of equations relative to the own variables (default 0: square).
    fn extra_equations(&self) -> isize {
        0
    }
    /// Name of equation `k` for diagnostics (default: balance of own variable `k`).
    fn equation_name(&self, k: usize, own_names: &[String]) -> String {
        own_names.get(k).map(|n| format!("equation for {n}")).unwrap_or_else(|| format!("equation {k}"))
    }
    /// Structural nonzeros `(equation, local column)` of the local Jacobian; `None` (the default)
    /// means dense. A declared pattern must contain every entry that can ever be nonzero; the
    /// Jacobian is then computed with one dual pass per column colour.
    fn pattern(&self, _layout: &LocalLayout) -> Option<Vec<(usize, usize)>> {
        None
    }
    /// Residuals at the local vector `io.local` into `r`.
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]);
    /// Own algebraic variables the unit computes in closed form ([`UnitModel::complete`]), in the
    /// order it computes them: own variable `k` is given by its own equation `k`, which must read
    /// no explicit variable later in this list (default: none). The dynamic integrator then
    /// iterates on the other variables only and recomputes these after every update.
    fn explicit(&self, _layout: &LocalLayout) -> Vec<usize> {
        Vec::new()
    }
    /// Overwrite the [`UnitModel::explicit`] variables of `own` (the unit's own variables) so
    /// that their equations hold exactly, computing them in the declared order from the other
    /// own variables (read from `own`: the own block of `io.local` is not filled here), the
    /// inlets and the inputs, and leaving every other entry of `own` as it is (default: nothing).
    fn complete(&self, _io: &UnitIo<'_, f64>, _own: &mut [f64]) {}
    /// The residuals of the equations that are not [`UnitModel::explicit`], at own variables
    /// `own` whose explicit ones [`UnitModel::complete`] has just set (read from `own`, as
    /// `complete` does: the own block of `io.local` is not filled here, which saves the
    /// integrator a copy of the block per residual); the explicit equations' rows of `r` may be
    /// left as they are, and so may the rows `k` with `skip[k]` (equations of output-only
    /// variables the dynamic integrator solves only when they are asked for; `skip` empty: none)
    /// (default: [`UnitModel::eval`] on a copy of the local vector with `own` in place).
    fn eval_kept(&self, io: &UnitIo<'_, f64>, own: &[f64], r: &mut [f64], _skip: &[bool]) {
        let mut local = io.local.to_vec();
        local[..own.len()].copy_from_slice(own);
        self.eval(&UnitIo { local: &local, ..*io }, r);
    }
    /// Initial guess of the own variables from the inlets and inputs in `local` (its own block holds
    /// whatever was there before: defaults or a previous solution).
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]);
    /// Problems at the plant's cold-start guess `io` (the unit's own block as it guessed it, its
    /// inlets the upstream units' guesses, its inputs at their values), each as (field below the
    /// unit's JSON path, message): what would stop Newton at its first step, such as a division
    /// by zero (default: none). Called once at load for the units whose
    /// [`UnitModel::checks_guess`] is true.
    fn check_guess(&self, _io: &UnitIo<'_, f64>) -> Vec<(String, String)> {
        Vec::new()
    }
    /// Whether the unit has a [`UnitModel::check_guess`] (default false): the load computes the
    /// plant's guess only if some unit has.
    fn checks_guess(&self) -> bool {
        false
    }
    /// Component amounts `n_c` [mol] held by the unit at the local vector `io.local`, one per
    /// component; `None` (the default) for a unit that holds no material. The dynamic driver
    /// checks the plant's balance with it: `Σ_units Δn_c = ∫ (Σ_feeds F z_c − Σ_products F z_c) dt`.
    fn holdup(&self, _io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        None
    }
    /// Whether the unit turns components into one another (reactions; default false). A plant with
    /// such a unit conserves mass `Σ_c MW_c n_c` [kg], not moles per component, and the steady-state
    /// certificate checks its mass balance.
    fn reacts(&self) -> bool {
        false
    }
    /// A controller whose output rests on a limit while its measurement is off its setpoint, at the
    /// point `io` (default: never).
    fn saturation(&self, _io: &UnitIo<'_, f64>) -> Option<Saturation> {
        None
    }
    /// Check the unit's input values (SI, in [`UnitModel::inputs`] order) for what only the unit
    /// knows, beyond each value's physical range. Run on the file's values and after `--set`
    /// (default: nothing to check).
    ///
    /// # Errors
    /// [`InputError`] naming the input and why its value is refused.
    fn check_inputs(&self, _thermo: &ThermoPackage, _inputs: &[f64]) -> Result<(), InputError> {
        Ok(())
    }
    /// This controller with its output limits removed, if it has any (default: none). A clamped
    /// output no longer depends on its measurement, so the Jacobian of a well-posed plant can be
    /// singular where a limit is active: the numerical degrees-of-freedom probe judges the plant
    /// with its controllers in their linear range.
    fn without_limits(&self) -> Option<Self>
    where
        Self: Sized,
    {
        None
    }
    /// A controller's output limits `(op_min, op_max)` (SI; infinite where there is none), drawn
    /// on trend plots of its output (default: none).
    fn output_limits(&self) -> Option<(f64, f64)> {
        None
    }
    /// The physical range `[lo, hi]` (SI) of input `k` when the unit knows a narrower one than
    /// its name and dimension give ([`crate::limits::input_range`]): a controller's setpoint takes
    /// its measurement's range (a mole fraction's 0 … 1), its manual output that of the input it
    /// drives (default: none, the input's own range).
    fn input_range(&self, _k: usize) -> Option<(f64, f64)> {
        None
    }
    /// Its place at the plant's boundary, for the certificate and the conservation check
    /// (default: interior; a feed is a source, a product a sink).
    fn boundary(&self) -> Boundary {
        Boundary::Interior
    }
    /// The duties it books in an energy balance of utilities, in the order reported (default:
    /// none; a unit with a heat duty must declare it, or `compare` leaves it out of the energy use).
    fn duties(&self) -> Vec<Duty> {
        Vec::new()
    }
    /// The utilities it uses that are flows, not duties (default: none).
    fn utility_flows(&self) -> &'static [UtilityFlow] {
        &[]
    }
    /// Whether it moves heat between process streams (a condenser–reboiler): a duty input it
    /// drives is recovered heat, not a utility (default: false).
    fn moves_process_heat(&self) -> bool {
        false
    }
    /// How the browser simulator draws it; [`Shape::Column`] also marks the unit whose stage
    /// temperatures sensor selection reads (default: a block).
    fn shape(&self) -> Shape {
        Shape::Block
    }
    /// The inventories it holds and what sets the flows that fill and drain them, for the
    /// consistency check of inventory control (default: no holdup, every outlet passes what
    /// enters).
    fn material_flows(&self) -> MaterialFlows {
        MaterialFlows::default()
    }
}

/// Object-safe view of a [`UnitModel`], used by assembly and solvers.
pub trait Unit: Send + Sync + std::fmt::Debug {
    /// See [`UnitModel::type_name`].
    fn type_name(&self) -> &'static str;
    /// See [`UnitModel::inlet_ports`].
    fn inlet_ports(&self) -> Vec<String>;
    /// See [`UnitModel::outlet_ports`].
    fn outlet_ports(&self) -> Vec<String>;
    /// See [`UnitModel::internal_vars`].
    fn internal_vars(&self) -> Vec<VarSpec>;
    /// See [`UnitModel::inputs`].
    fn inputs(&self) -> Vec<InputSpec>;
    /// See [`UnitModel::signals`].
    fn signals(&self) -> Vec<SignalSpec>;
    /// See [`UnitModel::extra_equations`].
    fn extra_equations(&self) -> isize;
    /// See [`UnitModel::equation_name`].
    fn equation_name(&self, k: usize, own_names: &[String]) -> String;
    /// See [`UnitModel::pattern`].
    fn pattern(&self, layout: &LocalLayout) -> Option<Vec<(usize, usize)>>;
    /// Residuals in `f64`.
    fn residual(&self, io: &UnitIo<'_, f64>, r: &mut [f64]);
    /// Residuals and the local Jacobian `jac[k][j] = ∂r_k/∂local_j` (row-major, `n_eq × len`; only
    /// entries of the pattern are written, the rest stay as the caller set them), exact by
    /// forward-mode dual numbers: one pass per column colour of the pattern.
    fn jacobian(&self, io: &UnitIo<'_, f64>, r: &mut [f64], jac: &mut [f64]) {
        let coloring = self.pattern(io.layout).map(|p| Coloring::new(&p, r.len(), io.local.len()));
        self.jacobian_colored(io, r, jac, coloring.as_ref());
    }
    /// [`Unit::jacobian`] with the colouring of the unit's pattern computed once by the caller
    /// (`None` for a dense unit); assembly caches it per block.
    fn jacobian_colored(&self, io: &UnitIo<'_, f64>, r: &mut [f64], jac: &mut [f64], coloring: Option<&Coloring>);
    /// The second derivative of the residuals along two directions of the local vector,
    /// `out_k = Σ_ij ∂²r_k/∂local_i ∂local_j · a_i · b_j`, exact by one pass of hyper-dual numbers
    /// (`local + ε₁a + ε₂b`, the `ε₁ε₂` part). The curvature the optimizer's reduced Hessian and
    /// the self-optimizing `Juu`, `Jud` are made of.
    fn curvature(&self, io: &UnitIo<'_, f64>, a: &[f64], b: &[f64], out: &mut [f64]);
    /// See [`UnitModel::guess`].
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]);
    /// See [`UnitModel::check_guess`].
    fn check_guess(&self, io: &UnitIo<'_, f64>) -> Vec<(String, String)>;
    /// See [`UnitModel::checks_guess`].
    fn checks_guess(&self) -> bool;
    /// See [`UnitModel::explicit`].
    fn explicit(&self, layout: &LocalLayout) -> Vec<usize>;
    /// See [`UnitModel::complete`].
    fn complete(&self, io: &UnitIo<'_, f64>, own: &mut [f64]);
    /// See [`UnitModel::eval_kept`].
    fn residual_kept(&self, io: &UnitIo<'_, f64>, own: &[f64], r: &mut [f64], skip: &[bool]);
    /// See [`UnitModel::without_limits`].
    fn without_limits(&self) -> Option<Box<dyn Unit>>;
    /// See [`UnitModel::output_limits`].
    fn output_limits(&self) -> Option<(f64, f64)>;
    /// See [`UnitModel::holdup`].
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>>;
    /// See [`UnitModel::reacts`].
    fn reacts(&self) -> bool;
    /// See [`UnitModel::saturation`].
    fn saturation(&self, io: &UnitIo<'_, f64>) -> Option<Saturation>;
    /// See [`UnitModel::check_inputs`].
    fn check_inputs(&self, thermo: &ThermoPackage, inputs: &[f64]) -> Result<(), InputError>;
    /// See [`UnitModel::input_range`].
    fn input_range(&self, k: usize) -> Option<(f64, f64)>;
    /// See [`UnitModel::boundary`].
    fn boundary(&self) -> Boundary;
    /// See [`UnitModel::duties`].
    fn duties(&self) -> Vec<Duty>;
    /// See [`UnitModel::utility_flows`].
    fn utility_flows(&self) -> &'static [UtilityFlow];
    /// See [`UnitModel::moves_process_heat`].
    fn moves_process_heat(&self) -> bool;
    /// See [`UnitModel::shape`].
    fn shape(&self) -> Shape;
    /// See [`UnitModel::material_flows`].
    fn material_flows(&self) -> MaterialFlows;
}

/// A controller output held at a limit with the measurement off its setpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct Saturation {
    /// The limit reached: `"op_min"` or `"op_max"`.
    pub limit: &'static str,
    /// Its value (SI, the output's dimension).
    pub value: f64,
    /// Measurement minus setpoint (SI, the measurement's dimension).
    pub offset: f64,
}

impl<U: UnitModel + 'static> Unit for U {
    fn type_name(&self) -> &'static str {
        UnitModel::type_name(self)
    }
    fn boundary(&self) -> Boundary {
        UnitModel::boundary(self)
    }
    fn duties(&self) -> Vec<Duty> {
        UnitModel::duties(self)
    }
    fn utility_flows(&self) -> &'static [UtilityFlow] {
        UnitModel::utility_flows(self)
    }
    fn moves_process_heat(&self) -> bool {
        UnitModel::moves_process_heat(self)
    }
    fn shape(&self) -> Shape {
        UnitModel::shape(self)
    }
    fn material_flows(&self) -> MaterialFlows {
        UnitModel::material_flows(self)
    }
    fn reacts(&self) -> bool {
        UnitModel::reacts(self)
    }
    fn saturation(&self, io: &UnitIo<'_, f64>) -> Option<Saturation> {
        UnitModel::saturation(self, io)
    }
    fn check_inputs(&self, thermo: &ThermoPackage, inputs: &[f64]) -> Result<(), InputError> {
        UnitModel::check_inputs(self, thermo, inputs)
    }
    fn input_range(&self, k: usize) -> Option<(f64, f64)> {
        UnitModel::input_range(self, k)
    }
    fn inlet_ports(&self) -> Vec<String> {
        UnitModel::inlet_ports(self)
    }
    fn outlet_ports(&self) -> Vec<String> {
        UnitModel::outlet_ports(self)
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        UnitModel::internal_vars(self)
    }
    fn inputs(&self) -> Vec<InputSpec> {
        UnitModel::inputs(self)
    }
    fn signals(&self) -> Vec<SignalSpec> {
        UnitModel::signals(self)
    }
    fn extra_equations(&self) -> isize {
        UnitModel::extra_equations(self)
    }
    fn equation_name(&self, k: usize, own_names: &[String]) -> String {
        UnitModel::equation_name(self, k, own_names)
    }
    fn residual(&self, io: &UnitIo<'_, f64>, r: &mut [f64]) {
        self.eval(io, r);
    }
    fn pattern(&self, layout: &LocalLayout) -> Option<Vec<(usize, usize)>> {
        UnitModel::pattern(self, layout)
    }
    fn jacobian_colored(&self, io: &UnitIo<'_, f64>, r: &mut [f64], jac: &mut [f64], coloring: Option<&Coloring>) {
        let n = io.local.len();
        let m = r.len();
        let mut local: Vec<Dual64> = io.local.iter().map(|&v| Dual64::from_re(v)).collect();
        let mut rd = vec![Dual64::from_re(0.0); m];
        let eval = |local: &[Dual64], rd: &mut [Dual64]| {
            let dio = UnitIo { local, layout: io.layout, thermo: io.thermo, time: io.time };
            self.eval(&dio, rd);
        };
        match coloring {
            None => {
                for j in 0..n {
                    local[j].eps = 1.0;
                    eval(&local, &mut rd);
                    for k in 0..m {
                        jac[k * n + j] = rd[k].eps;
                    }
                    local[j].eps = 0.0;
                }
            }
            Some(c) => {
                for color in 0..c.n_colors {
                    // Seed this colour's columns, unseeding the last colour's (all others are
                    // zero already): a pass over the colour's columns, not over every column.
                    if color > 0 {
                        c.columns_of_color[color - 1].iter().for_each(|&j| local[j].eps = 0.0);
                    }
                    c.columns_of_color[color].iter().for_each(|&j| local[j].eps = 1.0);
                    eval(&local, &mut rd);
                    for &j in &c.columns_of_color[color] {
                        for &k in &c.rows_of_col[j] {
                            jac[k * n + j] = rd[k].eps;
                        }
                    }
                }
                if c.n_colors == 0 {
                    local.iter_mut().for_each(|v| v.eps = 0.0);
                    eval(&local, &mut rd);
                }
            }
        }
        if n == 0 {
            self.eval(io, r);
        } else {
            for k in 0..m {
                r[k] = rd[k].re;
            }
        }
    }
    fn curvature(&self, io: &UnitIo<'_, f64>, a: &[f64], b: &[f64], out: &mut [f64]) {
        let local: Vec<HyperDual64> =
            io.local.iter().zip(a).zip(b).map(|((&v, &da), &db)| HyperDual64::new(v, da, db, 0.0)).collect();
        let mut r = vec![HyperDual64::from_re(0.0); out.len()];
        self.eval(&UnitIo { local: &local, layout: io.layout, thermo: io.thermo, time: io.time }, &mut r);
        out.iter_mut().zip(&r).for_each(|(o, v)| *o = v.eps1eps2);
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        UnitModel::guess(self, io, own);
    }
    fn check_guess(&self, io: &UnitIo<'_, f64>) -> Vec<(String, String)> {
        UnitModel::check_guess(self, io)
    }
    fn checks_guess(&self) -> bool {
        UnitModel::checks_guess(self)
    }
    fn explicit(&self, layout: &LocalLayout) -> Vec<usize> {
        UnitModel::explicit(self, layout)
    }
    fn complete(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        UnitModel::complete(self, io, own);
    }
    fn residual_kept(&self, io: &UnitIo<'_, f64>, own: &[f64], r: &mut [f64], skip: &[bool]) {
        UnitModel::eval_kept(self, io, own, r, skip);
    }
    fn without_limits(&self) -> Option<Box<dyn Unit>> {
        UnitModel::without_limits(self).map(|u| Box::new(u) as Box<dyn Unit>)
    }
    fn output_limits(&self) -> Option<(f64, f64)> {
        UnitModel::output_limits(self)
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        UnitModel::holdup(self, io)
    }
}

/// A distance-2 colouring of the columns of a unit's Jacobian pattern: columns of one colour share
/// no row, so one dual pass seeded on all of them yields each of their entries exactly.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Coloring {
    /// Colour of each local column (`usize::MAX` for a column in no row).
    pub colors: Vec<usize>,
    /// Number of colours (dual passes).
    pub n_colors: usize,
    /// Columns of each colour.
    pub columns_of_color: Vec<Vec<usize>>,
    /// Rows in which each column has a structural entry.
    pub rows_of_col: Vec<Vec<usize>>,
}

impl Coloring {
    /// Greedy colouring of an `m × n` pattern given as `(row, column)` entries.
    pub fn new(pattern: &[(usize, usize)], m: usize, n: usize) -> Coloring {
        let mut cols_of_row: Vec<Vec<usize>> = vec![Vec::new(); m];
        let mut rows_of_col: Vec<Vec<usize>> = vec![Vec::new(); n];
        for &(k, j) in pattern {
            cols_of_row[k].push(j);
            rows_of_col[j].push(k);
        }
        for v in cols_of_row.iter_mut().chain(rows_of_col.iter_mut()) {
            v.sort_unstable();
            v.dedup();
        }
        let mut colors = vec![usize::MAX; n];
        let mut n_colors = 0;
        let mut forbidden: Vec<usize> = Vec::new();
        for j in 0..n {
            if rows_of_col[j].is_empty() {
                continue;
            }
            forbidden.clear();
            for &k in &rows_of_col[j] {
                forbidden.extend(cols_of_row[k].iter().map(|&j2| colors[j2]).filter(|&c| c != usize::MAX));
            }
            forbidden.sort_unstable();
            forbidden.dedup();
            let c = (0..).find(|c| forbidden.binary_search(c).is_err()).unwrap_or(0);
            colors[j] = c;
            n_colors = n_colors.max(c + 1);
        }
        let mut columns_of_color = vec![Vec::new(); n_colors];
        for (j, &c) in colors.iter().enumerate() {
            if c != usize::MAX {
                columns_of_color[c].push(j);
            }
        }
        Coloring { colors, n_colors, columns_of_color, rows_of_col }
    }
}
