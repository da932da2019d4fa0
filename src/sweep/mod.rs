//! `tendril sweep`: many runs over a grid of scenario keys, in parallel, resumable, shardable.
//!
//! - [`spec`]: the sweep file and its expansion into runs.
//! - [`results`]: the incremental `results.csv`, its rows and shard merging.
//! - [`durable`]: checking, repairing and locking a results file before a resume appends.
//! - [`execute`]: checking and running the runs in parallel.
//! - [`contour`]: a summary field's threshold, for maps that follow a figure's contour.
//! - [`adaptive`]: a sweep refined over two of its keys ([`refine`] on each of its maps).
//! - [`refine`]: adaptive refinement of a two-key grid (only the cells whose runs disagree).

pub mod adaptive;
pub mod columns;
pub mod contour;
pub mod durable;
pub mod execute;
pub mod refine;
pub mod results;
pub mod spec;

pub use spec::{Sweep, SweepRun, load_sweep};

/// `--shard K/N`: this process runs the K-th of N interleaved slices (K from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which slice, 1..=count.
    pub index: usize,
    /// How many slices.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (k, n) = s.split_once('/').ok_or_else(|| format!("--shard {s}: expected K/N, e.g. 2/8"))?;
        let (index, count): (usize, usize) = match (k.trim().parse(), n.trim().parse()) {
            (Ok(k), Ok(n)) => (k, n),
            _ => return Err(format!("--shard {s}: K and N must be whole numbers")),
        };
        if count == 0 || index == 0 || index > count {
            return Err(format!("--shard {s}: need 1 <= K <= N"));
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// Whether run `id` belongs to this shard. Interleaved, so every shard gets a mix of
    /// objects and settings and the shards take similar time.
    pub fn owns(&self, id: usize) -> bool {
        id % self.count == self.index - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_runs() {
        let shards: Vec<Shard> = (1..=3).map(|k| format!("{k}/3").parse().unwrap()).collect();
        for id in 0..20 {
            assert_eq!(shards.iter().filter(|s| s.owns(id)).count(), 1);
        }
        assert!("0/3".parse::<Shard>().is_err());
        assert!("4/3".parse::<Shard>().is_err());
        assert!("x".parse::<Shard>().is_err());
    }
}
