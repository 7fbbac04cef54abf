//! Sharding a job's independent tasks over processes (Slurm job arrays, Kubernetes indexed Jobs):
//! which tasks this process computes, and the results other processes computed.
//!
//! A sweeping study numbers its independent tasks `0 … N−1` in a fixed order (a sensitivity
//! sweep's walks, a screening's dynamically tested candidates). Task `t` belongs to shard
//! `t mod n` of `n`, so shards stay balanced whatever `N` is. Each task is a pure function of the
//! plant and the request, so a merged result equals the one-process result bit for bit.

use std::collections::BTreeMap;
use std::str::FromStr;

/// Shard `index` of `count` (`index` counts from 0, as `SLURM_ARRAY_TASK_ID` with
/// `--array=0-(n−1)` and Kubernetes' `JOB_COMPLETION_INDEX` do).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    /// This shard, `0 ≤ index < count`.
    pub index: usize,
    /// How many shards the job is split into.
    pub count: usize,
}

/// Why a `--shard` argument is refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "shard `{0}`: expected I/N with 0 ≤ I < N ≤ 100000, the index counting from 0 (e.g. `0/4` … `3/4`; \
     Slurm: `$SLURM_ARRAY_TASK_ID/4` in an array of tasks 0–3)"
)]
pub struct ShardError(pub String);

/// Most shards a job may be split into (a part file per shard).
pub const MAX_SHARDS: usize = 100_000;

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || ShardError(s.to_string());
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count || count > MAX_SHARDS {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// Whether task `task` is this shard's.
    pub fn owns(&self, task: usize) -> bool {
        task % self.count == self.index
    }
}

/// Which of a job's tasks this process computes.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Share<T> {
    /// Every task, here (the default: one process).
    #[default]
    All,
    /// Only this shard's tasks; the others are left out of the result.
    Shard(Shard),
    /// No task: every result was computed by the shards and is given here by task number.
    Merge(BTreeMap<usize, T>),
}

impl<T: Clone> Share<T> {
    /// Task `task`'s result: computed by `f` when this process owns it, taken from the merged
    /// parts when given, `None` when it is another shard's (or missing from the parts).
    pub fn run(&self, task: usize, f: impl FnOnce() -> T) -> Option<T> {
        match self {
            Share::All => Some(f()),
            Share::Shard(s) => s.owns(task).then(f),
            Share::Merge(_) => self.given(task),
        }
    }

    /// Task `task`'s result as the merged parts give it (`None` unless merging).
    pub fn given(&self, task: usize) -> Option<T> {
        match self {
            Share::Merge(given) => given.get(&task).cloned(),
            _ => None,
        }
    }

    /// Whether this process computes task `task` itself.
    pub fn computes(&self, task: usize) -> bool {
        match self {
            Share::All => true,
            Share::Shard(s) => s.owns(task),
            Share::Merge(_) => false,
        }
    }

    /// Whether this process computes only part of the tasks.
    pub fn is_shard(&self) -> bool {
        matches!(self, Share::Shard(_))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_from_zero_and_partition_the_tasks() {
        assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
        for bad in ["4/4", "1/0", "-1/3", "1", "a/b", "1/100001", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        // Every task belongs to exactly one of the n shards, and the shards differ by at most one.
        let n = 3;
        let counts: Vec<usize> =
            (0..n).map(|i| (0..10).filter(|&t| Shard { index: i, count: n }.owns(t)).count()).collect();
        assert_eq!(counts, vec![4, 3, 3]);
        assert!((0..10).all(|t| (0..n).filter(|&i| Shard { index: i, count: n }.owns(t)).count() == 1));
    }

    #[test]
    fn a_share_computes_its_own_tasks_and_takes_merged_ones() {
        let shard = Share::<usize>::Shard(Shard { index: 1, count: 2 });
        assert_eq!(shard.run(3, || 30), Some(30));
        assert_eq!(shard.run(2, || unreachable!("task 2 is shard 0's")), None);
        let merged = Share::Merge(BTreeMap::from([(0, 7usize)]));
        assert_eq!(merged.run(0, || unreachable!("given")), Some(7));
        assert_eq!(merged.run(1, || unreachable!("given")), None);
        assert_eq!(Share::<usize>::All.run(5, || 50), Some(50));
    }
}
