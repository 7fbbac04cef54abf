//! The best subsets of the candidate measurements, by bidirectional branch and bound (Cao &
//! Kariwala, "Bidirectional branch and bound for controlled variable selection: Part I", Comput.
//! Chem. Eng. 32 (2008) 2306–2319; Kariwala & Cao, "… Part II: exact local method for
//! self-optimizing control", Comput. Chem. Eng. 33 (2009) 1402–1412; "… Part III: local average
//! loss minimization", IEEE Trans. Ind. Inform. 6 (2010) 54–61).
//!
//! A node is a set `F` of measurements fixed in the subset and a set `C` of candidates still
//! free; its subsets are the `F ∪ X`, `X ⊆ C`, of the size asked for. With the exact local
//! method's best `H`, both losses are functions of `Λ_s = G̃_sᵀ (Y_s Y_sᵀ)⁻¹ G̃_s` (see
//! [`crate::loss`]): worst case `1 / (2 λ_min)`, average `½ tr Λ⁻¹`. A measurement added to a set
//! adds a positive semidefinite term of rank one to `Λ`, so (with `B` the loss of the K-th best
//! subset found so far):
//!
//! * **downward** (superset) pruning: no subset of `S = F ∪ C` loses less than `S` itself; if
//!   `S` loses at least `B` the node is dropped. A candidate `i` whose removal makes `S \ i` lose
//!   at least `B` is in every subset that can beat `B` and is fixed. Removing `i` is a rank-one
//!   downdate `Λ_S − g gᵀ / q`, with `q = (Y_SS⁻¹)_ii` and `g = G̃_Sᵀ Y_SS⁻¹ e_i`: for the worst
//!   case the test is the sign of `1 − gᵀ (Λ_S − b I)⁻¹ g / q`, `b = 1/(2B)` (Part II, eq. 20);
//!   for the average it is the Sherman–Morrison trace `tr Λ_S⁻¹ + ‖Λ_S⁻¹ g‖² / (q − gᵀ Λ_S⁻¹ g)`.
//! * **upward** pruning, partial (the subsets still need `r < nu` measurements): `r` rank-one
//!   terms raise `λ_k` at most to `λ_{k+r}(Λ_F)` (Weyl), so every subset of the node loses at
//!   least `1 / (2 λ_{r+1}(Λ_F))` (worst case) or `½ Σ_{k>r} 1/λ_k(Λ_F)` (average); if that is at
//!   least `B` the node is dropped. For the worst case, when exactly `r` eigenvalues of `Λ_F` lie
//!   below `b`, each added measurement must lift one of them past `b`; a candidate with Schur
//!   complements `x_i`, `r_i` on `F` that cannot (`x_iᵀ (b I − Λ_F)⁻¹ x_i / r_i ≤ 1`, the inertia of
//!   a rank-one update) is dropped from `C` (Part II, eq. 24).
//!
//! Pruning only removes subsets that cannot beat the K-th best, so the K best are exact whatever
//! the order of the branches; the order only changes how many nodes are evaluated. A node branches
//! on the candidate its downward test rates most needed: fixed first while the subsets still
//! need no more than half the candidates, otherwise the least needed is dropped first.

use faer::{Mat, Side};
use serde::{Deserialize, Serialize};

use crate::dense::{cholesky, lower_solve, principal, rank_deficient, rows, thin_svd};
use crate::error::SocError;
use crate::loss::{Combination, Losses, exact_local, from_sigma};
use crate::model::LocalModel;

/// Default node budget: about half a minute on 40 candidates with 15 inputs (Yi Cao's case needs
/// 65 167 nodes for the 100 best of size 15).
pub const DEFAULT_MAX_NODES: u64 = 200_000;

/// Most subsets a search may return.
pub const MAX_BEST: usize = 10_000;

/// Which loss ranks the subsets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// `½ σ̄(M)²`.
    Worst,
    /// `½ ‖M‖²_F`.
    Average,
}

impl Criterion {
    /// The ranked loss.
    pub fn of(self, losses: &Losses) -> f64 {
        match self {
            Criterion::Worst => losses.worst_case,
            Criterion::Average => losses.average,
        }
    }
}

/// What to search for.
#[derive(Debug, Clone, Copy)]
pub struct Search {
    /// Measurements in a subset (nu ≤ size ≤ ny).
    pub size: usize,
    /// How many of the best subsets to return.
    pub best: usize,
    /// The loss that ranks them.
    pub criterion: Criterion,
    /// Nodes the search may evaluate before it gives up.
    pub max_nodes: u64,
}

/// The best subsets, best first, with the nodes evaluated to prove it.
#[derive(Debug, Clone)]
pub struct Ranking {
    /// At most `best` subsets (fewer when fewer subsets can hold the inputs), best first.
    pub subsets: Vec<Combination>,
    /// Nodes evaluated (terminal evaluations included).
    pub nodes: u64,
    /// Complete subsets evaluated and found rank-deficient (they cannot hold the inputs).
    pub rank_deficient: u64,
}

/// The `search.best` subsets of `search.size` measurements with the least loss, by bidirectional
/// branch and bound.
///
/// # Errors
/// [`SocError::Request`] for a size outside `nu..=ny` or a count of subsets outside
/// `1..=MAX_BEST`; [`SocError::NodeBudget`] when the budget runs out before the ranking is proved.
pub fn branch_and_bound(model: &LocalModel, search: &Search) -> Result<Ranking, SocError> {
    check(model, search)?;
    let mut bnb = Bnb::new(model, search);
    bnb.node(Vec::new(), (0..model.ny()).collect())?;
    bnb.finish()
}

/// The same ranking by evaluating every subset: the reference the branch and bound is tested
/// against, and the cheaper search when the subsets are few.
///
/// # Errors
/// As [`branch_and_bound`]; the budget counts subsets.
pub fn enumerate(model: &LocalModel, search: &Search) -> Result<Ranking, SocError> {
    check(model, search)?;
    let mut bnb = Bnb::new(model, search);
    let mut subset: Vec<usize> = (0..search.size).collect();
    loop {
        bnb.offer(subset.clone())?;
        // The next subset in lexicographic order.
        let Some(k) = (0..search.size).rev().find(|&k| subset[k] < model.ny() - search.size + k) else { break };
        subset[k] += 1;
        for j in k + 1..search.size {
            subset[j] = subset[j - 1] + 1;
        }
    }
    bnb.finish()
}

fn check(model: &LocalModel, search: &Search) -> Result<(), SocError> {
    let (nu, ny) = (model.nu(), model.ny());
    if search.size < nu || search.size > ny {
        return Err(SocError::Request(format!(
            "size {}: a subset needs at least as many measurements as inputs ({nu}) and at most the candidates ({ny})",
            search.size
        )));
    }
    if search.best == 0 || search.best > MAX_BEST {
        return Err(SocError::Request(format!("best {}: ask for 1 to {MAX_BEST} subsets", search.best)));
    }
    if search.max_nodes == 0 {
        return Err(SocError::Request("max_nodes 0: the search needs at least one node".to_string()));
    }
    Ok(())
}

/// The outcome of a node's pruning.
enum Prune {
    /// No subset of the node can beat the K-th best.
    Node,
    /// Candidates to move: fixed (downward) or dropped (upward).
    Move(Vec<usize>),
    /// Nothing to prune; the downward need of each candidate, for branching.
    Keep(Vec<f64>),
}

struct Bnb<'a> {
    model: &'a LocalModel,
    search: Search,
    /// The best subsets found so far with their ranked loss, ascending.
    best: Vec<(f64, Combination)>,
    nodes: u64,
    rank_deficient: u64,
}

impl<'a> Bnb<'a> {
    fn new(model: &'a LocalModel, search: &Search) -> Bnb<'a> {
        Bnb { model, search: *search, best: Vec::new(), nodes: 0, rank_deficient: 0 }
    }

    /// The ranking, refused when no subset of the size can hold the inputs.
    fn finish(self) -> Result<Ranking, SocError> {
        if self.best.is_empty() {
            return Err(SocError::Request(format!(
                "size {}: every subset of {} measurements is rank-deficient (no combination of them can hold the {} inputs); ask for a larger size",
                self.search.size,
                self.search.size,
                self.model.nu()
            )));
        }
        let (nodes, rank_deficient) = (self.nodes, self.rank_deficient);
        Ok(Ranking { subsets: self.best.into_iter().map(|(_, c)| c).collect(), nodes, rank_deficient })
    }

    /// The loss of the K-th best subset, once K are known.
    fn bound(&self) -> Option<f64> {
        (self.best.len() == self.search.best).then(|| self.best[self.search.best - 1].0)
    }

    fn count(&mut self) -> Result<(), SocError> {
        self.nodes += 1;
        if self.nodes <= self.search.max_nodes {
            return Ok(());
        }
        let names = &self.model.parts().measurements;
        let so_far = match self.best.first() {
            Some((_, c)) => {
                let m: Vec<&str> = c.measurements.iter().map(|&i| names[i].as_str()).collect();
                format!("{} with loss {:.6e}", m.join(", "), self.search.criterion.of(&c.losses))
            }
            None => "none".to_string(),
        };
        Err(SocError::NodeBudget {
            nodes: self.search.max_nodes,
            best: self.search.best,
            size: self.search.size,
            so_far,
        })
    }

    /// Evaluate a complete subset and keep it if it is among the K best.
    fn offer(&mut self, mut subset: Vec<usize>) -> Result<(), SocError> {
        self.count()?;
        subset.sort_unstable();
        let Some(c) = exact_local(self.model, &subset)? else {
            self.rank_deficient += 1;
            return Ok(());
        };
        // Bounds are kept in the scaled data's units, as the nodes compute them.
        let loss = self.model.scaled_loss(self.search.criterion.of(&c.losses));
        if !loss.is_finite() || self.bound().is_some_and(|b| loss >= b) {
            return Ok(());
        }
        let at = self.best.partition_point(|(l, _)| *l <= loss);
        self.best.insert(at, (loss, c));
        self.best.truncate(self.search.best);
        Ok(())
    }

    fn node(&mut self, mut fixed: Vec<usize>, mut cand: Vec<usize>) -> Result<(), SocError> {
        self.count()?;
        let need = loop {
            let left = self.search.size - fixed.len();
            if cand.len() < left {
                return Ok(());
            }
            if left == 0 {
                return self.offer(fixed);
            }
            if cand.len() == left {
                fixed.extend(cand);
                return self.offer(fixed);
            }
            match self.downward(&fixed, &cand)? {
                Prune::Node => return Ok(()),
                // More measurements needed than the subsets have room for.
                Prune::Move(fix) if fix.len() > left => return Ok(()),
                Prune::Move(fix) => {
                    cand.retain(|c| !fix.contains(c));
                    fixed.extend(fix);
                    continue;
                }
                Prune::Keep(need) => match self.upward(&fixed, &cand)? {
                    Prune::Node => return Ok(()),
                    Prune::Move(drop) => cand.retain(|c| !drop.contains(c)),
                    Prune::Keep(_) => break need,
                },
            }
        };
        let left = self.search.size - fixed.len();
        let fix_first = 2 * left <= cand.len();
        let pick = match fix_first {
            true => argmax(&need),
            false => argmax(&need.iter().map(|v| -v).collect::<Vec<_>>()),
        };
        let i = cand.remove(pick);
        let mut with = fixed.clone();
        with.push(i);
        if fix_first {
            self.node(with, cand.clone())?;
            self.node(fixed, cand)
        } else {
            self.node(fixed, cand.clone())?;
            self.node(with, cand)
        }
    }

    /// Downward pruning on the superset `S = F ∪ C`.
    fn downward(&self, fixed: &[usize], cand: &[usize]) -> Result<Prune, SocError> {
        let s: Vec<usize> = fixed.iter().chain(cand).copied().collect();
        let l = cholesky(principal(self.model.y2(), &s).as_ref(), "Y Yᵀ of the candidates")?;
        let z = lower_solve(l.as_ref(), Mat::<f64>::identity(s.len(), s.len()).as_ref());
        let w = &z * rows(self.model.g_tilde(), &s);
        let svd = thin_svd(w.as_ref())?;
        if rank_deficient(&svd.sigma, w.nrows(), w.ncols()) {
            return Ok(Prune::Node);
        }
        let loss = self.search.criterion.of(&from_sigma(&svd.sigma));
        let bound = self.bound();
        if bound.is_some_and(|b| loss >= b) {
            return Ok(Prune::Node);
        }
        let lambda: Vec<f64> = svd.sigma.iter().map(|s| s * s).collect();
        // Columns of L⁻¹ for the candidates: g = Wᵀ z_i, q = ‖z_i‖², t = Vᵀ g.
        let zc = z.as_ref().get(.., fixed.len()..);
        let t = svd.v.transpose() * w.transpose() * zc;
        let q: Vec<f64> = (0..cand.len()).map(|j| zc.col(j).iter().map(|v| v * v).sum()).collect();
        let need: Vec<f64> = (0..cand.len())
            .map(|j| {
                let t = t.col(j);
                match self.search.criterion {
                    Criterion::Worst => {
                        let b = bound.map_or(0.0, |b| 0.5 / b);
                        (0..lambda.len()).map(|k| t[k] * t[k] / (lambda[k] - b)).sum::<f64>() / q[j] - 1.0
                    }
                    Criterion::Average => {
                        let kept = q[j] - (0..lambda.len()).map(|k| t[k] * t[k] / lambda[k]).sum::<f64>();
                        let extra = (0..lambda.len()).map(|k| t[k] * t[k] / (lambda[k] * lambda[k])).sum::<f64>();
                        match kept > q[j] * 1e-12 {
                            true => 0.5 * (lambda.iter().map(|l| 1.0 / l).sum::<f64>() + extra / kept),
                            false => f64::INFINITY,
                        }
                    }
                }
            })
            .collect();
        let Some(b) = bound else { return Ok(Prune::Keep(need)) };
        let fix: Vec<usize> = (0..cand.len())
            .filter(|&j| match self.search.criterion {
                Criterion::Worst => need[j] > 0.0,
                Criterion::Average => need[j] >= b,
            })
            .map(|j| cand[j])
            .collect();
        Ok(if fix.is_empty() { Prune::Keep(need) } else { Prune::Move(fix) })
    }

    /// Partial upward pruning on the fixed set `F`.
    fn upward(&self, fixed: &[usize], cand: &[usize]) -> Result<Prune, SocError> {
        let (nu, left) = (self.model.nu(), self.search.size - fixed.len());
        let Some(bound) = self.bound() else { return Ok(Prune::Keep(Vec::new())) };
        if fixed.is_empty() || left >= nu {
            return Ok(Prune::Keep(Vec::new()));
        }
        let lf = cholesky(principal(self.model.y2(), fixed).as_ref(), "Y Yᵀ of the fixed measurements")?;
        let wf = lower_solve(lf.as_ref(), rows(self.model.g_tilde(), fixed).as_ref());
        let eig = (wf.transpose() * &wf)
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| SocError::Numerical(format!("the eigenvalues of Λ did not converge: {e:?}")))?;
        let lambda: Vec<f64> = eig.S().column_vector().iter().copied().collect();
        let least = match self.search.criterion {
            Criterion::Worst => 0.5 / lambda[left],
            Criterion::Average => 0.5 * lambda[left..].iter().map(|l| 1.0 / l).sum::<f64>(),
        };
        if lambda[left] <= 0.0 || least >= bound {
            return Ok(Prune::Node);
        }
        let b = 0.5 / bound;
        if self.search.criterion == Criterion::Average || lambda[left - 1] >= b {
            return Ok(Prune::Keep(Vec::new()));
        }
        // Exactly `left` eigenvalues below b: each added measurement must lift one past it.
        let y2 = self.model.y2();
        let y2_fc = Mat::from_fn(fixed.len(), cand.len(), |i, j| y2[(fixed[i], cand[j])]);
        let a = lower_solve(lf.as_ref(), y2_fc.as_ref());
        let x = rows(self.model.g_tilde(), cand).transpose() - wf.transpose() * &a;
        let t = eig.U().transpose() * &x;
        let drop: Vec<usize> = (0..cand.len())
            .filter(|&j| {
                let r = y2[(cand[j], cand[j])] - a.col(j).iter().map(|v| v * v).sum::<f64>();
                let lift: f64 = (0..nu).map(|k| t[(k, j)] * t[(k, j)] / (b - lambda[k])).sum();
                lift <= r
            })
            .map(|j| cand[j])
            .collect();
        Ok(if drop.is_empty() { Prune::Keep(Vec::new()) } else { Prune::Move(drop) })
    }
}

/// Index of the largest value, the first on ties.
fn argmax(v: &[f64]) -> usize {
    let mut at = 0;
    for (k, x) in v.iter().enumerate() {
        if *x > v[at] {
            at = k;
        }
    }
    at
}
