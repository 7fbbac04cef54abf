//! # plantwide-mpc: dynamic matrix control (DMC / QDMC) solved by clarabel
//!
//! A step-response model `S_k` (`ny × nu`, response at `(k+1)·ts` to unit input steps, held
//! constant beyond the last of `N` coefficients) predicts the outputs over `P` samples from `M`
//! future moves `ΔU = [Δu(k); …; Δu(k+M−1)]`:
//!
//! ```text
//! Ŷ = f + A ΔU,      A = ⎡ S_0                 ⎤   (P·ny × M·nu, the dynamic matrix)
//!                        ⎢ S_1   S_0           ⎥
//!                        ⎢  ⋮           ⋱      ⎥
//!                        ⎣ S_{P−1} …  S_{P−M}  ⎦
//! f_l = ŷ(k+l | k−1) + d,   d = y_meas(k) − ŷ(k | k−1)   (output disturbance held constant)
//! ```
//!
//! `ŷ(·|k−1)` is the stored open-loop prediction from all past moves, advanced every sample by
//! the DMC shift `ŷ(k+1+l | k) = ŷ(k+1+l | k−1) + S_l Δu(k)`. The constant-`d` feedback makes the
//! controller offset-free for step-like disturbances and gain mismatch.
//!
//! The moves minimise (QDMC)
//!
//! ```text
//! J = ½‖r − f − AΔU‖²_Q + ½‖ΔU‖²_R + Σ_s (ρ ε_s + ½ ρ ε_s²)
//! s.t. u_min ≤ u(k−1) + LΔU ≤ u_max,  |ΔU| ≤ du_max           (hard)
//!      y_min − ε ≤ f + AΔU ≤ y_max + ε,  ε ≥ 0                  (soft)
//! ```
//!
//! i.e. clarabel's `½zᵀPz + qᵀz` with `z = [ΔU; ε]`, `P = blockdiag(AᵀQA + R, ρI)`,
//! `q = [−AᵀQ(r − f); ρ·1]` (see [`qp`]). `Q`, `R` are diagonal, repeated over the horizon;
//! `r` is the setpoint held over the horizon; `L` sums moves. There is one slack per finite
//! output-limit side (per output, per side), shared by all `P` samples: `ε` is the worst
//! violation of that limit over the horizon. Only the first move is applied (receding horizon).
//! With no active constraint the minimiser is `ΔU = H⁻¹AᵀQ(r − f)`
//! ([`Dmc::unconstrained_move`]).
//!
//! ## Solver
//! Clarabel (interior point) with tolerances 1e-12. The sparse constraint matrix, `P` and the
//! cones are built once in [`Dmc::new`]; every sample only `q` and `b` change and are written
//! in place (`update_q`, `update_b`; presolve disabled so updates are allowed). Clarabel has
//! no warm start: the structure (and its symbolic KKT factorisation) is reused, the iterate is
//! not — each sample starts from clarabel's default initial point.
//!
//! ## Sources
//! - C. R. Cutler, B. L. Ramaker, *Dynamic Matrix Control — a computer control algorithm*,
//!   Joint Automatic Control Conference, 1980.
//! - C. E. Garcia, A. M. Morshedi, *Quadratic programming solution of dynamic matrix control
//!   (QDMC)*, Chem. Eng. Commun. 46 (1986) 73–87.
//! - D. E. Seborg, T. F. Edgar, D. A. Mellichamp, F. J. Doyle, *Process Dynamics and Control*,
//!   ch. 20 (Model predictive control).
//! - P. J. Goulart, Y. Chen, *Clarabel: an interior-point solver for conic programs with
//!   quadratic objectives*, 2024.

#![forbid(unsafe_code)]

mod dmc;
mod error;
mod model;
pub mod qp;
mod settings;

pub use dmc::{Dmc, Move};
pub use error::MpcError;
pub use model::StepModel;
pub use settings::Settings;
