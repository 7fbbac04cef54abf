//! Assembly of a validated flowsheet into one plant DAE `M dx/dt = f(x, u)`: the global variable
//! vector, the equation blocks of every unit and controller, the inputs `u`, and the paths that name
//! every variable and input.

use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use plantwide_model::stream::StreamLayout;
use plantwide_model::{Coloring, LocalLayout, Unit, UnitIo, VarKind, VarSpec};
use plantwide_thermo::ThermoPackage;
use plantwide_units::Dimension;

use crate::spec::FlowsheetSpec;

/// Where one entry of a unit's local vector (beyond its own variables) comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Read {
    /// Global variable index.
    Var(usize),
    /// Free input index (not driven by a controller).
    Input(usize),
}

/// Whether a block is a process unit, a controller or a tag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlockKind {
    /// A process unit.
    Unit,
    /// A controller.
    Controller,
    /// A tag: a quantity computed from plant variables by an expression
    /// ([`plantwide_model::tag`]).
    Tag,
}

impl BlockKind {
    /// The flowsheet file's section of such blocks: `units`, `controllers` or `tags`.
    pub fn section(self) -> &'static str {
        match self {
            BlockKind::Unit => "units",
            BlockKind::Controller => "controllers",
            BlockKind::Tag => "tags",
        }
    }

    /// The word for one such block in reports: `unit`, `controller` or `tag`.
    pub fn label(self) -> &'static str {
        match self {
            BlockKind::Unit => "unit",
            BlockKind::Controller => "controller",
            BlockKind::Tag => "tag",
        }
    }
}

/// One unit or controller in the assembled plant.
#[derive(Debug, Clone)]
pub struct Block {
    /// Name in the flowsheet.
    pub name: String,
    /// Unit or controller.
    pub kind: BlockKind,
    /// The model.
    pub unit: Arc<dyn Unit>,
    /// Its local layout.
    pub layout: LocalLayout,
    /// First global variable it owns.
    pub own_offset: usize,
    /// First global equation it writes.
    pub eq_offset: usize,
    /// Number of equations.
    pub n_eq: usize,
    /// Sources of the local entries after the own variables.
    pub reads: Vec<Read>,
    /// Global input indices of its declared inputs, in declaration order.
    pub input_ids: Vec<usize>,
    /// Declared local sparsity pattern (`None`: dense).
    pub pattern: Option<Vec<(usize, usize)>>,
    /// Column colouring of the pattern, computed once at assembly.
    pub coloring: Option<Coloring>,
}

/// A global variable.
#[derive(Debug, Clone, PartialEq)]
pub struct VarInfo {
    /// Path (`feed.F`, `tank.level`, `lc1.op`).
    pub path: String,
    /// Description from the owning unit.
    pub spec: VarSpec,
    /// Owning block.
    pub block: usize,
}

/// A declared input of some unit: a manipulated variable or disturbance.
#[derive(Debug, Clone, PartialEq)]
pub struct InputInfo {
    /// Path (`valve.opening`, `fresh.F`).
    pub path: String,
    /// SI dimension.
    pub dim: Dimension,
    /// Value used when no controller drives it (SI).
    pub value: f64,
    /// The controller output variable that drives it, if any.
    pub driven_by: Option<usize>,
    /// Owning block.
    pub block: usize,
}

/// A material stream of the plant.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamInfo {
    /// Name.
    pub name: String,
    /// Source block and outlet port index.
    pub from: (usize, usize),
    /// Destination block and inlet port index.
    pub to: (usize, usize),
    /// First global variable (`F`) of its block.
    pub offset: usize,
    /// Marked as a preferred tear.
    pub tear: bool,
}

/// The streams entering and leaving each block: `into[b]`, `out_of[b]` (stream indices in file
/// order).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct StreamEnds {
    into: Vec<Vec<usize>>,
    out_of: Vec<Vec<usize>>,
}

impl StreamEnds {
    /// The index of `streams` over `n_blocks` blocks.
    pub(crate) fn new(n_blocks: usize, streams: &[StreamInfo]) -> StreamEnds {
        let mut ends = StreamEnds { into: vec![Vec::new(); n_blocks], out_of: vec![Vec::new(); n_blocks] };
        for (k, s) in streams.iter().enumerate() {
            ends.into[s.to.0].push(k);
            ends.out_of[s.from.0].push(k);
        }
        ends
    }
}

/// A tag named as a path: what its name reads and moves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TagRef {
    /// Global index of its value variable `<tag>.value`.
    pub var: usize,
    /// Its unit (`"reactor.P@kPag"`, or the `unit` field), in which its value is shown.
    pub unit: Option<String>,
    /// The input its expression is, when the expression is one input's path.
    pub input: Option<usize>,
}

/// The assembled plant.
#[derive(Debug, Clone)]
pub struct Plant {
    /// File the plant came from (for messages).
    pub(crate) file: String,
    /// Name of the plant.
    pub(crate) name: String,
    /// Component names.
    pub(crate) components: Vec<String>,
    /// Thermodynamic package.
    pub(crate) thermo: ThermoPackage,
    /// Stream layout.
    pub(crate) stream_layout: StreamLayout,
    /// Units and controllers.
    pub(crate) blocks: Vec<Block>,
    /// Global variables (shared between copies: a simulation copies the plant to rewire its
    /// inputs, never its variables).
    pub(crate) vars: Arc<Vec<VarInfo>>,
    /// Declared inputs.
    pub(crate) inputs: Vec<InputInfo>,
    /// Streams.
    pub(crate) streams: Vec<StreamInfo>,
    /// The streams entering and leaving each block, in file order (indexed once at assembly).
    pub(crate) stream_ends: Arc<StreamEnds>,
    /// Named inputs (`alias → input index`).
    pub(crate) aliases: Arc<HashMap<String, usize>>,
    /// Tags by name.
    pub(crate) tags: Arc<HashMap<String, TagRef>>,
    pub(crate) var_index: Arc<HashMap<String, usize>>,
    pub(crate) input_index: HashMap<String, usize>,
    /// The description the plant was assembled from (after field overrides): structure variants
    /// are edits of it, assembled again ([`Plant::variant`]).
    pub(crate) spec: Arc<FlowsheetSpec>,
    /// The input values as assembled from `spec`: a variant keeps only the values changed since.
    pub(crate) assembled_inputs: Vec<f64>,
    /// Design specifications still to be met ([`crate::design`]).
    pub(crate) specs: Vec<crate::design::DesignSpec>,
    /// Notes on the description: numbers without a unit read in SI (`units.feed.T: 80 has no
    /// unit …`), from the file and from overrides.
    pub(crate) notes: Vec<String>,
}

impl Plant {
    /// Notes on its description for the user: numbers without a unit read in SI, each as
    /// `` `path`: what it was read as and what to write ``.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }
    /// File the plant came from (for messages).
    pub fn file(&self) -> &str {
        &self.file
    }
    /// Name of the plant.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Component names, in the order of every composition.
    pub fn components(&self) -> &[String] {
        &self.components
    }
    /// Thermodynamic package.
    pub fn thermo(&self) -> &ThermoPackage {
        &self.thermo
    }
    /// Layout of every stream's variables.
    pub fn stream_layout(&self) -> StreamLayout {
        self.stream_layout
    }
    /// Units and controllers, units first, in file order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }
    /// Global variables.
    pub fn vars(&self) -> &[VarInfo] {
        &self.vars
    }
    /// Declared inputs (manipulated variables, disturbances, setpoints; held measurements last).
    pub fn inputs(&self) -> &[InputInfo] {
        &self.inputs
    }
    /// Material streams.
    pub fn streams(&self) -> &[StreamInfo] {
        &self.streams
    }
    /// The streams entering block `b` (indices into [`Plant::streams`], in file order).
    pub fn streams_into(&self, b: usize) -> &[usize] {
        &self.stream_ends.into[b]
    }
    /// The streams leaving block `b` (indices into [`Plant::streams`], in file order).
    pub fn streams_out_of(&self, b: usize) -> &[usize] {
        &self.stream_ends.out_of[b]
    }
    /// Named inputs (`alias → input index`).
    pub fn aliases(&self) -> &HashMap<String, usize> {
        &self.aliases
    }
    /// The description the plant was assembled from (after field overrides).
    pub fn spec(&self) -> &FlowsheetSpec {
        &self.spec
    }
    /// Index of the block named `name`.
    pub fn block_index(&self, name: &str) -> Option<usize> {
        self.blocks.iter().position(|b| b.name == name)
    }
    /// Number of variables (= number of equations in a well-posed plant).
    pub fn n_vars(&self) -> usize {
        self.vars.len()
    }
    /// Number of equations.
    pub fn n_eqs(&self) -> usize {
        self.blocks.iter().map(|b| b.n_eq).sum()
    }
    /// Global index of the variable at `path` (`stream.x[comp]` and `stream.z[comp]` both work), or
    /// of a tag's value named by the tag's name.
    pub fn var(&self, path: impl AsRef<str>) -> Option<usize> {
        let path = path.as_ref();
        self.tags.get(path).map(|t| t.var).or_else(|| crate::path::VarPath::parse(path).find(&self.var_index))
    }
    /// Index of the input at `path`, named by an alias, or by a tag whose expression is its path.
    pub fn input(&self, path: impl AsRef<str>) -> Option<usize> {
        let path = path.as_ref();
        let tagged = || self.tags.get(path).and_then(|t| t.input);
        self.input_index.get(path).or_else(|| self.aliases.get(path)).copied().or_else(tagged)
    }
    /// Tags by name: the variable each reads, its unit, the input it names.
    pub fn tags(&self) -> &HashMap<String, TagRef> {
        &self.tags
    }
    /// The unit of tag `name`, if it is a tag with one: the unit a path named by it is shown in.
    pub fn tag_unit(&self, name: &str) -> Option<&str> {
        self.tags.get(name)?.unit.as_deref()
    }
    /// Current values of all inputs (SI).
    pub fn input_values(&self) -> Vec<f64> {
        self.inputs.iter().map(|i| i.value).collect()
    }
    /// Differential flags of the variables (the diagonal of M).
    pub fn differential(&self) -> Vec<bool> {
        self.vars.iter().map(|v| v.spec.kind == VarKind::Differential).collect()
    }
    /// Name of global equation `eq` for diagnostics: `unit: equation for <var>`.
    pub fn equation_name(&self, eq: usize) -> String {
        let Some(b) = self.blocks.iter().find(|b| eq >= b.eq_offset && eq < b.eq_offset + b.n_eq) else {
            return format!("equation {eq}");
        };
        let own: Vec<String> =
            self.vars[b.own_offset..b.own_offset + b.layout.n_own()].iter().map(|v| v.path.clone()).collect();
        format!("{}: {}", b.name, b.unit.equation_name(eq - b.eq_offset, &own))
    }

    /// The physical range `[lo, hi]` of input `i` (SI) that every value it is given is checked
    /// against ([`crate::overrides::check_input_value`]): its block's declared range (a
    /// controller's setpoint: its measurement's), else its name's and dimension's.
    pub fn input_range(&self, i: usize) -> (f64, f64) {
        crate::assemble::input_range_of(&self.blocks, &self.inputs, i)
    }

    /// The physical range `[lo, hi]` of variable `v`'s values (SI): what a setpoint on it may ask.
    pub fn var_range(&self, v: usize) -> (f64, f64) {
        crate::assemble::physical_range(&self.vars[v].spec)
    }

    /// The own variable that equation `eq` belongs to (for diagnostics).
    pub fn equation_variable(&self, eq: usize) -> Option<usize> {
        let b = self.blocks.iter().find(|b| eq >= b.eq_offset && eq < b.eq_offset + b.n_eq)?;
        let k = eq - b.eq_offset;
        (k < b.layout.n_own()).then_some(b.own_offset + k)
    }

    /// Fill `local` with block `b`'s local vector from `x` and inputs `u`.
    pub fn gather(&self, b: &Block, x: &[f64], u: &[f64], local: &mut Vec<f64>) {
        local.clear();
        local.extend_from_slice(&x[b.own_offset..b.own_offset + b.layout.n_own()]);
        local.extend(b.reads.iter().map(|r| match *r {
            Read::Var(i) => x[i],
            Read::Input(j) => u[j],
        }));
    }

    /// Residuals `f(x, u)` at time `t` into `r` (length `n_eqs`).
    pub fn residual(&self, x: &[f64], u: &[f64], t: f64, r: &mut [f64]) {
        LOCAL.with_borrow_mut(|local| {
            for b in &self.blocks {
                self.gather(b, x, u, local);
                let io = UnitIo { local, layout: &b.layout, thermo: &self.thermo, time: t };
                b.unit.residual(&io, &mut r[b.eq_offset..b.eq_offset + b.n_eq]);
            }
        });
    }

    /// The second derivative of the residuals along two directions `a = (a_x, a_u)` and
    /// `b = (b_x, b_u)` of the variables and inputs, `f''[a, b] = Σ ∂²f/∂w_i∂w_j a_i b_j`
    /// (`w = (x, u)`), exact by hyper-dual numbers: one pass of every block ([`Unit::curvature`]),
    /// into `out` (length `n_eqs`). With the adjoint `λ` of a function of the steady state, the
    /// implicit-function theorem turns it into that function's exact second derivative along
    /// the inputs (`plantwide_studies::optimize`).
    pub fn curvature(&self, (x, u): (&[f64], &[f64]), a: (&[f64], &[f64]), b: (&[f64], &[f64]), out: &mut [f64]) {
        let (mut local, mut la, mut lb) = (Vec::new(), Vec::new(), Vec::new());
        for blk in &self.blocks {
            self.gather(blk, x, u, &mut local);
            self.gather(blk, a.0, a.1, &mut la);
            self.gather(blk, b.0, b.1, &mut lb);
            let io = UnitIo { local: &local, layout: &blk.layout, thermo: &self.thermo, time: 0.0 };
            blk.unit.curvature(&io, &la, &lb, &mut out[blk.eq_offset..blk.eq_offset + blk.n_eq]);
        }
    }

    /// Residuals and Jacobians: `∂f/∂x` as triplets `(row, col, value)` into `jx`, and `∂f/∂u`
    /// (free inputs only) into `ju`. Structural entries are kept even when their value is zero, so
    /// the pattern is the same at every point. Blocks are evaluated in parallel (rayon) when the
    /// plant is large enough for it to pay; the result is identical to the sequential one.
    pub fn jacobian(
        &self,
        x: &[f64],
        u: &[f64],
        t: f64,
        r: &mut [f64],
        jx: &mut Vec<(usize, usize, f64)>,
        ju: &mut Vec<(usize, usize, f64)>,
    ) {
        // Parallel when the blocks other than the largest carry enough work: a plant that is one
        // column and its small neighbours gains nothing from threads but their wake-up.
        let work: Vec<usize> = self.blocks.iter().map(|b| b.n_eq * (b.layout.len() + 1)).collect();
        let rest = work.iter().sum::<usize>() - work.iter().max().copied().unwrap_or(0);
        let par = if rest > PARALLEL_WORK { Parallelism::Rayon } else { Parallelism::Sequential };
        self.jacobian_with(par, x, u, t, r, jx, ju);
    }

    /// [`Plant::jacobian`] with the parallelism chosen by the caller.
    #[allow(clippy::too_many_arguments)]
    pub fn jacobian_with(
        &self,
        par: Parallelism,
        x: &[f64],
        u: &[f64],
        t: f64,
        r: &mut [f64],
        jx: &mut Vec<(usize, usize, f64)>,
        ju: &mut Vec<(usize, usize, f64)>,
    ) {
        jx.clear();
        ju.clear();
        let parts: Vec<BlockJacobian> = match par {
            Parallelism::Sequential => self.blocks.iter().map(|b| self.block_jacobian(b, &*b.unit, x, u, t)).collect(),
            Parallelism::Rayon => self.blocks.par_iter().map(|b| self.block_jacobian(b, &*b.unit, x, u, t)).collect(),
        };
        Self::merge(&self.blocks, parts, r, jx, ju);
    }

    /// [`Plant::jacobian`] with the controllers' output limits removed: the plant with its controllers
    /// in their linear range, where a well-posed plant's Jacobian is regular (a clamped output no
    /// longer depends on its measurement). For the degrees-of-freedom probe.
    pub fn jacobian_without_limits(
        &self,
        x: &[f64],
        u: &[f64],
        r: &mut [f64],
        jx: &mut Vec<(usize, usize, f64)>,
        ju: &mut Vec<(usize, usize, f64)>,
    ) {
        jx.clear();
        ju.clear();
        let parts = self
            .blocks
            .iter()
            .map(|b| {
                let relaxed = b.unit.without_limits();
                self.block_jacobian(b, relaxed.as_deref().unwrap_or(&*b.unit), x, u, 0.0)
            })
            .collect();
        Self::merge(&self.blocks, parts, r, jx, ju);
    }

    fn merge(
        blocks: &[Block],
        parts: Vec<BlockJacobian>,
        r: &mut [f64],
        jx: &mut Vec<(usize, usize, f64)>,
        ju: &mut Vec<(usize, usize, f64)>,
    ) {
        for (b, part) in blocks.iter().zip(parts) {
            r[b.eq_offset..b.eq_offset + b.n_eq].copy_from_slice(&part.r);
            jx.extend(part.jx);
            ju.extend(part.ju);
        }
    }

    /// Residuals and Jacobian entries of block `b` evaluated by `unit` (its own, or a variant of it).
    fn block_jacobian(&self, b: &Block, unit: &dyn Unit, x: &[f64], u: &[f64], t: f64) -> BlockJacobian {
        let mut local = Vec::new();
        self.gather(b, x, u, &mut local);
        with_dense_jacobian(b.n_eq * local.len(), |jac| self.block_entries(b, unit, &local, t, jac))
    }

    /// [`Plant::block_jacobian`] on the gathered `local` vector with `jac` (`n_eq × local.len()`,
    /// row-major) as the unit's dense Jacobian buffer.
    fn block_entries(&self, b: &Block, unit: &dyn Unit, local: &[f64], t: f64, jac: &mut [f64]) -> BlockJacobian {
        let n = local.len();
        let cap = b.pattern.as_ref().map_or(b.n_eq * n, Vec::len);
        let mut out = BlockJacobian { r: vec![0.0; b.n_eq], jx: Vec::with_capacity(cap), ju: Vec::new() };
        let io = UnitIo { local, layout: &b.layout, thermo: &self.thermo, time: t };
        unit.jacobian_colored(&io, &mut out.r, jac, b.coloring.as_ref());
        let n_own = b.layout.n_own();
        let mut push = |k: usize, j: usize| {
            let (row, v) = (b.eq_offset + k, jac[k * n + j]);
            if j < n_own {
                out.jx.push((row, b.own_offset + j, v));
            } else {
                match b.reads[j - n_own] {
                    Read::Var(i) => out.jx.push((row, i, v)),
                    Read::Input(i) => out.ju.push((row, i, v)),
                }
            }
        };
        match &b.pattern {
            Some(p) => p.iter().for_each(|&(k, j)| push(k, j)),
            None => (0..b.n_eq).for_each(|k| (0..n).for_each(|j| push(k, j))),
        }
        out
    }
}

thread_local! {
    /// The dense block Jacobian buffer of [`Plant::block_jacobian`], one per thread.
    static DENSE_JACOBIAN: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
    /// The local vector of [`Plant::residual`], one per thread: a residual is evaluated at every
    /// Newton iteration of every integrator step, and its allocation was a measurable share.
    static LOCAL: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Run `f` on this thread's dense block-Jacobian buffer (row-major, `need` entries), reused
/// between calls and never zeroed: [`Unit::jacobian_colored`] writes every entry it is read back
/// from — all of them without a colouring, the declared ones with one. A column's block is
/// 1.5 MB: allocated and zeroed at every evaluation it was a tenth of a dynamic run, and of a
/// sequential pass's group Newton (page faults included).
pub fn with_dense_jacobian<R>(need: usize, f: impl FnOnce(&mut [f64]) -> R) -> R {
    DENSE_JACOBIAN.with_borrow_mut(|jac| {
        if jac.len() < need {
            jac.resize(need, 0.0);
        }
        f(&mut jac[..need])
    })
}

/// Work (Σ equations × local length) above which block Jacobians are evaluated in parallel.
const PARALLEL_WORK: usize = 20_000;

/// How to evaluate independent blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parallelism {
    /// One block after another.
    Sequential,
    /// Blocks on the rayon pool; results merged in block order (bit-identical to sequential).
    Rayon,
}

/// One block's residuals and Jacobian entries.
struct BlockJacobian {
    r: Vec<f64>,
    jx: Vec<(usize, usize, f64)>,
    ju: Vec<(usize, usize, f64)>,
}
