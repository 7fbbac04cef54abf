//! Input waveforms: the value of every input as a function of time between two events.

use serde::{Deserialize, Serialize};

/// An input's value as a function of time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Waveform {
    /// Constant.
    Constant(f64),
    /// From `v0` at `t0` linearly to `v1` at `t1` [s], then `v1`.
    Ramp {
        /// Start [s].
        t0: f64,
        /// Value at start.
        v0: f64,
        /// End [s].
        t1: f64,
        /// Final value.
        v1: f64,
    },
    /// `base + amplitude·sin(2π(t − t0)/period)`.
    Sine {
        /// Start [s].
        t0: f64,
        /// Mean value.
        base: f64,
        /// Amplitude.
        amplitude: f64,
        /// Period [s].
        period: f64,
    },
}

impl Waveform {
    /// Value at `t`.
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            Waveform::Constant(v) => v,
            Waveform::Ramp { t0, v0, t1, v1 } => {
                if t >= t1 {
                    v1
                } else {
                    v0 + (v1 - v0) * (t - t0) / (t1 - t0)
                }
            }
            Waveform::Sine { t0, base, amplitude, period } => {
                base + amplitude * (std::f64::consts::TAU * (t - t0) / period).sin()
            }
        }
    }
}

/// The input vector `u(t)`: every waveform's value at `t`.
pub(super) fn values_at(waves: &[Waveform], t: f64) -> Vec<f64> {
    waves.iter().map(|w| w.at(t)).collect()
}
