//! The exchanger with holdup: `method: cells {n}` with `holdup_hot` and `holdup_cold` [mol] (and
//! optionally `wall_heat_capacity` [J/K]), for feed–effluent exchangers whose lag and positive
//! feedback matter to a reactor's stability (Tyreus & Luyben, *Chem. Eng. Sci.* 1976; Luyben,
//! *Plantwide Process Control*, 1998, ch. 4).
//!
//! `n` well-mixed cells per side in counter-current series, numbered from the hot-inlet end: hot
//! flows `1 → n`, cold `n → 1`; each cell holds `m_s = holdup_s / n` [mol] of side `s` (constant:
//! liquid full), and, with a wall, `c_w = wall_heat_capacity / n` [J/K] of metal at `T_wall[k]`.
//! Variables of cell `k`: `T_hot[k]`, `T_cold[k]` [K] (algebraic), `h_hot[k]`, `h_cold[k]` [J/mol]
//! (differential), `T_wall[k]` [K] (differential, with a wall). Equations, `F_s` the side's flow:
//! - `m_hot dh_hot[k]/dt = F_hot (h_hot[k−1] − h_hot[k]) − Q_hot,k`, `h_hot[0]` the hot inlet's;
//! - `m_cold dh_cold[k]/dt = F_cold (h_cold[k+1] − h_cold[k]) + Q_cold,k`, `h_cold[n+1]` the cold
//!   inlet's;
//! - with a wall: `c_w dT_wall[k]/dt = Q_hot,k − Q_cold,k`, `Q_hot,k = (2UA/n)(T_hot[k] − T_wall[k])`,
//!   `Q_cold,k = (2UA/n)(T_wall[k] − T_cold[k])` (two equal film conductances whose series is `UA`);
//!   without: `Q_hot,k = Q_cold,k = (UA/n)(T_hot[k] − T_cold[k])`;
//! - `h_s[k] = h_phase_s(T_s[k], z_s)`, the outlets `h_hot,out = h_hot[n]`, `h_cold,out = h_cold[1]`
//!   (their `T` from their `h`), and `Q = Σ_k Q_hot,k` [W].
//!
//! At steady state the wall carries what it receives, so each cell exchanges `(UA/n)(T_hot[k] −
//! T_cold[k])`: the steady state of the static `cells` model, whose boundary `k` is cell `k`'s
//! hot outlet and cell `k+1`'s cold outlet. Energy is conserved exactly at every state: the
//! holdups' accumulation `Σ m_s dh_s/dt + Σ c_w dT_wall/dt` telescopes to
//! `F_hot (h_hot,in − h_hot,out) + F_cold (h_cold,in − h_cold,out)`.

use crate::stream::H;
use crate::{Scalar, UnitIo, VarSpec};
use plantwide_units::Dimension;

use super::Q;

/// Holdups of the dynamic cells model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Holdups {
    /// Molar holdup [mol] of the hot and the cold side, whole exchanger.
    pub side: [f64; 2],
    /// Heat capacity [J/K] of the wall, whole exchanger (`None`: no wall).
    pub wall: Option<f64>,
}

impl Holdups {
    /// Variables per cell: `T_hot, h_hot, T_cold, h_cold[, T_wall]`.
    pub fn stride(&self) -> usize {
        if self.wall.is_some() { 5 } else { 4 }
    }

    /// The internal variables after `Q` for `n` cells.
    pub fn vars(&self, n: usize) -> Vec<VarSpec> {
        let mut v = Vec::with_capacity(self.stride() * n);
        for k in 1..=n {
            for side in ["hot", "cold"] {
                v.push(
                    VarSpec::algebraic(format!("T_{side}[{k}]"), Dimension::TEMPERATURE, 350.0).bounded(1.0, 5000.0),
                );
                v.push(VarSpec::differential(format!("h_{side}[{k}]"), Dimension::MOLAR_ENERGY, 3e4));
            }
            if self.wall.is_some() {
                v.push(
                    VarSpec::differential(format!("T_wall[{k}]"), Dimension::TEMPERATURE, 350.0).bounded(1.0, 5000.0),
                );
            }
        }
        v
    }

    /// Index in the local vector (and the own block's rows) of cell `k`'s variable `j`
    /// (0 `T_hot`, 1 `h_hot`, 2 `T_cold`, 3 `h_cold`, 4 `T_wall`).
    pub(super) fn at(&self, len: usize, k: usize, j: usize) -> usize {
        2 * len + 1 + self.stride() * (k - 1) + j
    }
}

/// The exchange of cell `k`: `(Q_hot,k, Q_cold,k)` [W].
fn exchange<S: Scalar>(h: &Holdups, io: &UnitIo<'_, S>, k: usize, uak: S) -> (S, S) {
    let len = io.layout.stream.len();
    let (th, tc) = (io.local[h.at(len, k, 0)], io.local[h.at(len, k, 2)]);
    match h.wall {
        Some(_) => {
            let tw = io.local[h.at(len, k, 4)];
            ((th - tw) * uak * 2.0, (tw - tc) * uak * 2.0)
        }
        None => {
            let q = (th - tc) * uak;
            (q, q)
        }
    }
}

/// Rows of the dynamic model beyond the stream relations both models share (`F`, `P`, `z` and the
/// outlets' `h(T)`): the outlets' enthalpies, `Q`, and every cell's rows.
pub(super) fn eval<S: Scalar>(x: &super::HeatExchanger, h: &Holdups, io: &UnitIo<'_, S>, r: &mut [S]) {
    let len = io.layout.stream.len();
    let n = x.n_cells();
    let (hi, ci, ho, co) = (io.inlet(0), io.inlet(1), io.outlet(0), io.outlet(1));
    let uak = io.input(0) / n as f64;
    let (m_hot, m_cold) = (h.side[0] / n as f64, h.side[1] / n as f64);
    let var = |k: usize, j: usize| io.local[h.at(len, k, j)];
    r[H] = ho.h() - var(n, 1);
    r[len + H] = co.h() - var(1, 3);
    let mut q_sum = S::from(0.0);
    for k in 1..=n {
        let (q_hot, q_cold) = exchange(h, io, k, uak);
        q_sum += q_hot;
        let hot_in = if k == 1 { hi.h() } else { var(k - 1, 1) };
        let cold_in = if k == n { ci.h() } else { var(k + 1, 3) };
        r[h.at(len, k, 0)] = var(k, 1) - x.phase[0].enthalpy(io.thermo, var(k, 0), ho.p(), hi.z());
        r[h.at(len, k, 1)] = ((hot_in - var(k, 1)) * hi.f() - q_hot) / m_hot;
        r[h.at(len, k, 2)] = var(k, 3) - x.phase[1].enthalpy(io.thermo, var(k, 2), co.p(), ci.z());
        r[h.at(len, k, 3)] = ((cold_in - var(k, 3)) * ci.f() + q_cold) / m_cold;
        if let Some(c) = h.wall {
            r[h.at(len, k, 4)] = (q_hot - q_cold) / (c / n as f64);
        }
    }
    r[2 * len + Q] = io.var(Q) - q_sum;
}

/// The cells' guess from the steady boundary states `(T, h)` of the static model: hot boundary `k`
/// is cell `k`'s hot state, cold boundary `k − 1` cell `k`'s cold state; the wall between them.
pub(super) fn guess(h: &Holdups, len: usize, k: usize, hot: (f64, f64), cold: (f64, f64), own: &mut [f64]) {
    let at = h.at(len, k, 0);
    own[at..at + 4].copy_from_slice(&[hot.0, hot.1, cold.0, cold.1]);
    if h.wall.is_some() {
        own[at + 4] = 0.5 * (hot.0 + cold.0);
    }
}
