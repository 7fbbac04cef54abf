//! A plant run step by step, its inputs set between steps: a plant test (a relay, a step on a
//! loop in manual), and the interactive simulator's clock.
//!
//! The inputs are constant between [`Session::set_input`] calls; a change takes effect at the
//! current time, where the algebraic variables are made consistent with it and the integrator
//! restarts at order 1 (the same discipline as a scenario's events). The session works on its own
//! copy of the plant.

use plantwide_flowsheet::Plant;

use super::adapter::{DaeShape, PlantDae};
use super::waveform::Waveform;
use crate::dae::{Bdf, BdfSettings, DaeError, DaeIntegrator};

/// Why a session could not advance.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: integration failed at t = {t:.6e} s: {source}{}", super::failure_hint(.source))]
pub struct SessionError {
    /// Flowsheet file.
    pub file: String,
    /// Time reached \[s\].
    pub t: f64,
    /// The integrator's reason.
    pub source: DaeError,
}

/// A plant integrated on demand.
#[derive(Debug)]
pub struct Session {
    plant: Plant,
    waves: Vec<Waveform>,
    shape: DaeShape,
    bdf: Bdf,
    restart: bool,
}

impl Session {
    /// A session of `plant` (at its input values) from state `x0` at `t = 0`, default tolerances.
    ///
    /// # Errors
    /// [`SessionError`] when no consistent initial state is found.
    pub fn new(plant: &Plant, x0: &[f64]) -> Result<Session, SessionError> {
        Session::with_settings(plant, x0, BdfSettings::default())
    }

    /// [`Session::new`] with integrator settings.
    ///
    /// # Errors
    /// [`SessionError`] when no consistent initial state is found.
    pub fn with_settings(plant: &Plant, x0: &[f64], settings: BdfSettings) -> Result<Session, SessionError> {
        let plant = plant.clone();
        let waves: Vec<Waveform> = plant.inputs().iter().map(|i| Waveform::Constant(i.value)).collect();
        let shape = DaeShape::new(&plant, &[], None);
        let mut s = Session { plant, waves, shape, bdf: Bdf::new(settings), restart: false };
        let sys = PlantDae::new(&s.plant, &s.waves, &s.shape);
        s.bdf.restart(&sys, 0.0, x0).map_err(|source| SessionError {
            file: s.plant.file().to_string(),
            t: 0.0,
            source,
        })?;
        Ok(s)
    }

    /// The current time \[s\].
    pub fn time(&self) -> f64 {
        self.bdf.t()
    }

    /// The current state (plant variables, SI).
    pub fn state(&self) -> &[f64] {
        self.bdf.x()
    }

    /// The plant being run.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// Hold input `i` at `value` (SI) from now on.
    pub fn set_input(&mut self, i: usize, value: f64) {
        if self.waves[i] != Waveform::Constant(value) {
            self.waves[i] = Waveform::Constant(value);
            self.restart = true;
        }
    }

    /// Drive input `i` by `wave` (times on the session's clock) from now on: a ramp or a sinusoid
    /// that the integrator follows between steps, where [`Session::set_input`] holds a value.
    pub fn set_waveform(&mut self, i: usize, wave: Waveform) {
        if self.waves[i] != wave {
            self.waves[i] = wave;
            self.restart = true;
        }
    }

    /// Integrate to time `t` \[s\] (ending exactly on it).
    ///
    /// # Errors
    /// [`SessionError`] when the integrator fails (the state stays where it failed).
    pub fn advance_to(&mut self, t: f64) -> Result<(), SessionError> {
        let sys = PlantDae::new(&self.plant, &self.waves, &self.shape);
        let fail = |source, t| SessionError { file: self.plant.file().to_string(), t, source };
        if self.restart {
            let (now, x) = (self.bdf.t(), self.bdf.x().to_vec());
            self.bdf.restart_after_discontinuity(&sys, now, &x).map_err(|e| fail(e, now))?;
            self.restart = false;
        }
        while self.bdf.t() < t {
            self.bdf.step(&sys, t).map_err(|e| fail(e, self.bdf.t()))?;
        }
        Ok(())
    }
}
