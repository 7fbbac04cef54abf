//! Errors of the studies: [`TuneError`] of tuning, [`crate::screen::ScreenError`] of screening,
//! [`crate::size::SizeError`] of surge sizing, [`crate::compare::CompareError`] of comparison,
//! [`crate::identify::IdentifyError`] of identification, joined in the crate-level [`enum@Error`].

use thiserror::Error;

/// Any failure of a study (the crate-level error): each variant one study's typed error.
#[derive(Debug, Clone, Error)]
pub enum Error {
    /// Tuning.
    #[error(transparent)]
    Tune(#[from] TuneError),
    /// Screening.
    #[error(transparent)]
    Screen(#[from] crate::screen::ScreenError),
    /// Surge sizing.
    #[error(transparent)]
    Size(#[from] crate::size::SizeError),
    /// Comparison of schemes.
    #[error(transparent)]
    Compare(#[from] crate::compare::CompareError),
    /// Identification.
    #[error(transparent)]
    Identify(#[from] crate::identify::IdentifyError),
}

impl Error {
    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        match self {
            Error::Tune(e) => e.is_user_error(),
            Error::Screen(e) => e.is_user_error(),
            Error::Size(e) => e.is_user_error(),
            Error::Compare(e) => e.is_user_error(),
            Error::Identify(e) => e.is_user_error(),
        }
    }
}

/// Why a tuning request was refused.
#[derive(Debug, Clone, Error)]
pub enum TuneError {
    /// A list of the request names one item twice.
    #[error(transparent)]
    Duplicate(#[from] crate::request::Duplicate),
    /// BLT needs as many inputs as outputs (one loop per output).
    #[error(
        "model `{model}` is not square ({n_outputs} outputs × {n_inputs} inputs): BLT pairs output i with input i; \
         give a model with as many inputs as outputs"
    )]
    NotSquare {
        /// Model name.
        model: String,
        /// Number of outputs.
        n_outputs: usize,
        /// Number of inputs.
        n_inputs: usize,
    },
    /// `G(0)` is singular: the outputs cannot be controlled independently by these inputs.
    #[error(
        "model `{model}` is singular at steady state (σ_min/σ_max of G(0) = {ratio:.3e}): the loops cannot all \
         be closed with integral action; remove a dependent output or input"
    )]
    SingularGain {
        /// Model name.
        model: String,
        /// Smallest over largest singular value of `G(0)`.
        ratio: f64,
    },
    /// A paired (diagonal) element has no phase crossover, so it has no ultimate gain.
    #[error(
        "element {output} ← {input} has no phase crossover (its phase never reaches −180°{detail}): it has no \
         ultimate gain; add the element's dead time or its measurement and valve lags, or tune this loop another way"
    )]
    NoPhaseCrossover {
        /// Output of the element.
        output: String,
        /// Input of the element.
        input: String,
        /// What the element is (e.g. ", a first-order lag without dead time").
        detail: String,
    },
    /// An element whose ultimate gain is not a representable number (its gain is too small or
    /// too large for `K_u = 1/|g(jω_u)|` to be finite and nonzero in double precision).
    #[error(
        "element {output} ← {input}: its ultimate gain {ku:e} is not a usable number (the element's gain is {gain:e}): \
         give the gain in other units, so that it lies within about 1e-300 … 1e300"
    )]
    UltimateOutOfRange {
        /// Output of the element.
        output: String,
        /// Input of the element.
        input: String,
        /// The element's gain.
        gain: f64,
        /// The ultimate gain computed.
        ku: f64,
    },
    /// A relay test did not settle into a cycle.
    #[error("relay test: no limit cycle: {why}")]
    NoCycle {
        /// Why, and what to change.
        why: String,
    },
    /// The name is no PID controller of the plant.
    #[error("no PID controller `{name}` in the flowsheet (its PID loops: {loops})")]
    NotALoop {
        /// The name asked for.
        name: String,
        /// The PID controllers it has.
        loops: String,
    },
    /// Averaging-level tuning of a measurement that does not integrate.
    #[error(
        "`{controller}` measures {measurement}, which settles at a finite gain when its output moves: averaging \
         tuning is for levels (integrating measurements); use `method` simc or blt"
    )]
    NotIntegrating {
        /// Controller.
        controller: String,
        /// Its measurement.
        measurement: String,
    },
    /// Averaging-level tuning of a level that integrates, but that other loops move as well at
    /// the averaging loop's own time scale, so that no single integrating gain describes it there.
    #[error(
        "`{controller}` measures {measurement}, which integrates (s·g → {slow:.4e} per output unit per second over \
         the slowest modes) but, at the time scale this `level_band` and `flow_change` give the loop (1/ω = {time:.4e} s), \
         other loops move it as well: s·g(jω) = {re:.4e} {im:+.4e}j, {:.0}% off the single integrator averaging tuning \
         assumes. {suggestion}", 100.0 * (.im / .re).abs()
    )]
    Interacting {
        /// Controller.
        controller: String,
        /// Its measurement.
        measurement: String,
        /// `s g(s)` at the lowest frequency probed.
        slow: f64,
        /// `1/ω` at the band's frequency \[s\].
        time: f64,
        /// Real part of `s g(jω)`.
        re: f64,
        /// Imaginary part of `s g(jω)`.
        im: f64,
        /// The level bands at which the loop would see one integrator, and the other methods.
        suggestion: String,
        /// The band of a faster loop that sees one integrator, if there is one (measurement units).
        faster_band: Option<f64>,
    },
    /// The file's action is the opposite of what the process gain needs.
    #[error(
        "`{controller}` has action \"{file}\" in the file, but its process gain needs \"{needed}\" (the loop would \
         run away); set its action to \"{needed}\""
    )]
    WrongAction {
        /// Controller.
        controller: String,
        /// The file's action.
        file: &'static str,
        /// The action needed.
        needed: &'static str,
    },
    /// Averaging-level settings cannot be computed.
    #[error(transparent)]
    Averaging(#[from] crate::tune::averaging::AveragingError),
    /// A relay test on an element with more leads than lags (an improper transfer function).
    #[error("relay test: no limit cycle: the element has {leads} leads and {lags} lags (improper)")]
    ImproperElement {
        /// Number of leads.
        leads: usize,
        /// Number of lags.
        lags: usize,
    },
    /// BLT: no detuning factor up to the largest allowed brings the biggest log modulus down to
    /// its target.
    #[error(
        "BLT: the biggest log modulus stays above {target_db} dB up to F = {detuning}: the loops interact too \
         strongly for one detuning factor (check the pairing)"
    )]
    DetuningLimit {
        /// The target of the biggest log modulus \[dB\].
        target_db: f64,
        /// The largest detuning factor tried (at least `max_detuning`).
        detuning: f64,
    },
    /// No detuning factor up to the limit closes the loops stably.
    #[error(
        "BLT: the loops close unstably at every detuning factor up to F = {detuning} (generalized Nyquist \
         criterion on det(I + G K)): the pairing cannot be closed by detuned PI loops (check the pairing and \
         the signs of the gains)"
    )]
    NeverStable {
        /// The largest detuning factor tried.
        detuning: f64,
    },
    /// The singular values of `G(0)` could not be computed.
    #[error("SVD of G(0): {detail}")]
    Svd {
        /// What the linear-algebra library reported.
        detail: String,
    },
    /// The plant's linear model could not be formed or analysed (eigenvalues, steady gain).
    #[error("linear model of the loops: {0}")]
    Linear(#[from] Box<plantwide_analysis::AnalysisError>),
    /// The loop's element has no time constant to size a test by (a pure integrator).
    #[error(
        "`{controller}`: its element has no lag or dead time of its own (a pure integrator?) to size the test by; \
         give `scan` (the test then runs 500 scans)"
    )]
    ResidenceTime {
        /// Controller.
        controller: String,
    },
    /// The loop's linear model has no state.
    #[error("`{controller}`: no dynamics between its output and its measurement (the linear model has no state)")]
    NoDynamics {
        /// Controller.
        controller: String,
    },
    /// The plant could not be integrated during a test.
    #[error(transparent)]
    Simulation(Box<plantwide_solve::dynamic::SessionError>),
    /// A relay test found no usable cycle.
    #[error("relay test of `{controller}`: {source}")]
    Relay {
        /// Controller.
        controller: String,
        /// Why.
        source: Box<crate::tune::bench::RelayError<plantwide_solve::dynamic::SessionError>>,
    },
    /// A test amplitude of zero (the output's steady value is zero).
    #[error(
        "`{controller}`: the test amplitude is {} (5 % of an output at zero); give `relay_amplitude` or `step`",
        plantwide_model::limits::number(*.amplitude)
    )]
    RelayAmplitude {
        /// Controller.
        controller: String,
        /// The amplitude.
        amplitude: f64,
    },
    /// A plant test's scan that is not a positive time, or so short against the loop's own time
    /// that the test would take without bound.
    #[error("`{controller}`: a scan of {scan:e} s {why}")]
    Scan {
        /// Controller.
        controller: String,
        /// The scan asked for \[s\].
        scan: f64,
        /// What is wrong and what would fix it.
        why: String,
    },
    /// A test would drive its input out of range (a valve past fully open).
    #[error(
        "`{controller}`: the test moves {input} to {}: {why}; give a smaller `relay_amplitude` or `step`",
        plantwide_model::limits::number(*.value)
    )]
    Saturates {
        /// Controller.
        controller: String,
        /// The input it drives.
        input: String,
        /// The value the test would give it.
        value: f64,
        /// Why that value is out of range.
        why: String,
    },
    /// A test's move asked for would take a flow past its bound at the new steady state.
    #[error(
        "`{controller}`: a move of {} {unit} either way takes `{path}` past its bound at the new steady state (the \
         exact steady gains allow at most {} {unit}); give a smaller `relay_amplitude` or `step`",
        plantwide_model::limits::number(*.amplitude),
        plantwide_model::limits::number(*.limit)
    )]
    BeyondRoom {
        /// Controller.
        controller: String,
        /// The output's SI unit.
        unit: String,
        /// The move asked for (output units, SI).
        amplitude: f64,
        /// The variable it would take past its bound.
        path: String,
        /// The largest move that keeps it within (output units, SI).
        limit: f64,
    },
    /// The loop's output has no lasting effect on its measurement (a washout: the response returns
    /// to where it started), so no model with a steady-state gain or an integrator describes it.
    #[error(
        "`{controller}`: its output has no steady-state effect on its measurement (the response returns to where it \
         started: something else — another loop, an inventory left free — cancels it); tune the loops that hold \
         the plant around it first, or tune this one on a faster test (`method` relay)"
    )]
    NoSteadyGain {
        /// Controller.
        controller: String,
    },
    /// The fitted model does not describe the step response: settings from it would be arbitrary.
    #[error(
        "`{controller}`: the {model} model explains R² = {r2:.3} of the step response (at least {min_r2} needed); {}",
        shape.as_ref().map_or_else(
            || "choose another `model`, a smaller `step`, or a relay test".to_string(),
            |s| format!(
                "the response {s}, which no first- or second-order lag describes: tune the loop by a relay test, or by \
                 `blt` on the exact linear model"
            )
        )
    )]
    PoorFit {
        /// Controller.
        controller: String,
        /// The model fitted.
        model: &'static str,
        /// Its coefficient of determination.
        r2: f64,
        /// The least accepted.
        min_r2: f64,
        /// What the response does that a lag cannot ([`crate::tune::fit::lagless_shape`]).
        shape: Option<String>,
    },
    /// No step tried gives a fitted gain within [`crate::tune::plant_tests::MAX_GAIN_ERROR`] of the
    /// element's linearized gain: the settings would rest on the secant of a curved response, or on
    /// a model that does not describe it.
    #[error(
        "`{controller}`: the {model} model's gain disagrees with the linearized gain {} at every step tried ({}); {}",
        crate::identify::number(*.linear_gain),
        step_tries(tests),
        if *stalled {
            if *settled {
                "a smaller step did not bring it closer, so the difference is not the plant's curvature: the model \
                 does not describe the response; choose another `model`, or a relay test (`method` relay)"
            } else {
                "a smaller step did not bring it closer, and the response had not settled within the test: the fit \
                 extrapolates; give a longer `scan`, or a relay test (`method` relay)"
            }
        } else {
            "the response stays outside the linear range down to the last step; tune by a relay test (`method` \
             relay) or on the linear model (`method` blt)"
        }
    )]
    OutsideLinearRange {
        /// Controller.
        controller: String,
        /// The model fitted.
        model: &'static str,
        /// The element's gain from the exact linearization (SI).
        linear_gain: f64,
        /// The tests run.
        tests: Vec<crate::tune::plant_tests::StepTry>,
        /// Whether the last test's response settled.
        settled: bool,
        /// Whether the last smaller step failed to bring the gain closer.
        stalled: bool,
    },
    /// The step record determines no model.
    #[error(transparent)]
    Fit(#[from] crate::tune::fit::FitError),
    /// A field of the request that does not parse or does not fit.
    #[error("{field} {why}")]
    Field {
        /// The [`crate::tune::request::TuneRequest`] field.
        field: &'static str,
        /// What is wrong, after the field's name (`must not be negative`, `3 kg: …`).
        why: String,
    },
    /// No steady state of the plant with the loops tuned before this one.
    #[error("the steady state with the loops before `{controller}` tuned: {source}")]
    Steady {
        /// The loop to be tested next.
        controller: String,
        /// The solver's reason.
        source: Box<plantwide_solve::SolveError>,
    },
    /// The tuned settings could not be written into the plant.
    #[error("writing the tuned settings into the flowsheet: {0}")]
    Structure(Box<plantwide_flowsheet::OverrideError>),
    /// The flowsheet's text could not be edited.
    #[error(transparent)]
    Edit(Box<plantwide_flowsheet::edit::EditError>),
    /// A model-based rule cannot be applied.
    #[error(transparent)]
    Rule(#[from] crate::tune::rules::RuleError),
}

impl TuneError {
    /// The request field a refusal is about, which its message starts with.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            TuneError::Field { field, .. } => Some(field),
            TuneError::Duplicate(_) => Some("loops"),
            _ => None,
        }
    }

    /// True for problems of the request (exit code 1), false for numerical failures (exit code 2).
    pub fn is_user_error(&self) -> bool {
        if let TuneError::Steady { source, .. } = self {
            return source.is_user_error();
        }
        !matches!(
            self,
            TuneError::DetuningLimit { .. }
                | TuneError::NeverStable { .. }
                | TuneError::Svd { .. }
                | TuneError::Linear(_)
                | TuneError::Simulation(_)
                | TuneError::ResidenceTime { .. }
                | TuneError::OutsideLinearRange { .. }
        )
    }
}

/// The steps of `tests` with their fitted gains and errors, for a message.
fn step_tries(tests: &[crate::tune::plant_tests::StepTry]) -> String {
    use crate::identify::number;
    let one = |t: &crate::tune::plant_tests::StepTry| {
        format!("step {}: gain {}, {} % off", number(t.step), number(t.gain), number(100.0 * t.gain_error))
    };
    tests.iter().map(one).collect::<Vec<_>>().join("; ")
}
