//! The memory budget: before a run allocates, its peak memory is estimated
//! from its node count and the peak bytes a node of its solver (and, in
//! 3-D, of its forces) measured over whole runs, and a run over the budget
//! is refused with [`Error::MemoryBudget`]. The 3-D solver's bytes a node
//! are held by a test between its heap's peak and twice it
//! (`tests/mlpg_alloc.rs`; BENCHMARKS.md; docs/notes/2026-11-29-memory-bounds.md).
//!
//! The budget is [`DEFAULT_MEMORY_BUDGET`] (8 GiB, below the memory of the
//! machines the project is measured on) unless the environment variable
//! [`MEMORY_BUDGET_VAR`] (`MI_MEMORY_BUDGET`) sets it: a number of bytes,
//! with an optional binary suffix `K`, `M`, `G` or `T` (`32G`, `512M`).

use crate::error::{Error, Result, number};

/// The budget when `MI_MEMORY_BUDGET` is not set: 8 GiB.
pub const DEFAULT_MEMORY_BUDGET: f64 = 8.0 * GIB;

/// The environment variable that sets the budget.
pub const MEMORY_BUDGET_VAR: &str = "MI_MEMORY_BUDGET";

/// The smallest budget the variable may set (64 MiB: less would refuse the
/// smallest runs of every scene).
const LEAST: f64 = 64.0 * 1024.0 * 1024.0;

/// The largest budget the variable may set (1 PiB).
const MOST: f64 = 1024.0 * 1024.0 * GIB;

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Bytes of a run before its nodes: the program, the thread pool, the
/// tables (measured: the smallest runs peak at 6-14 MB resident). What the
/// allocator keeps resident beyond the heap's peak (4-22 MB in the 3-D
/// runs of docs/notes/2026-11-29-memory-bounds.md) is in the margin of
/// the bytes a node.
const BASE: f64 = 16.0 * 1024.0 * 1024.0;

/// How a kind of scene's memory grows with its nodes: the peak bytes per
/// node of its solver, measured over whole runs, with a margin (the 3-D
/// solver's: the heap's peak counted by the allocator, `tests/mlpg_alloc.rs`;
/// the others': the peak resident memory, BENCHMARKS.md, "Memory per node").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemoryPerNode {
    /// Peak bytes per node (particle) of the solver.
    pub bytes: f64,
}

/// The budget now: [`MEMORY_BUDGET_VAR`] if it is set, else
/// [`DEFAULT_MEMORY_BUDGET`]. A value that is not a size in
/// [64 MiB, 1 PiB] is an error naming the variable.
pub fn memory_budget() -> Result<f64> {
    match std::env::var(MEMORY_BUDGET_VAR) {
        Ok(text) => parse_budget(&text),
        Err(std::env::VarError::NotPresent) => Ok(DEFAULT_MEMORY_BUDGET),
        Err(std::env::VarError::NotUnicode(t)) => Err(Error::ParseValue {
            name: MEMORY_BUDGET_VAR.into(),
            text: t.to_string_lossy().into_owned(),
        }),
    }
}

/// A budget written as bytes with an optional binary suffix (`K`, `M`, `G`,
/// `T`, upper or lower case, optionally followed by `B` or `iB`).
pub fn parse_budget(text: &str) -> Result<f64> {
    let bad = || Error::ParseValue {
        name: MEMORY_BUDGET_VAR.into(),
        text: text.into(),
    };
    let t = text.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (digits, scale) = match t.chars().last().map(|c| c.to_ascii_uppercase()) {
        Some('K') => (&t[..t.len() - 1], 1024.0),
        Some('M') => (&t[..t.len() - 1], 1024.0 * 1024.0),
        Some('G') => (&t[..t.len() - 1], GIB),
        Some('T') => (&t[..t.len() - 1], 1024.0 * GIB),
        _ => (t, 1.0),
    };
    let value = digits.trim().parse::<f64>().map_err(|_| bad())? * scale;
    if !(LEAST..=MOST).contains(&value) {
        return Err(Error::OutOfRange {
            name: MEMORY_BUDGET_VAR.into(),
            value,
            range: format!("[{}, {}] bytes", number(LEAST), number(MOST)),
        });
    }
    Ok(value)
}

/// The estimated peak memory (bytes) of a run of `nodes` nodes at
/// `per_node`: the base and the nodes at their bytes.
pub fn estimate(nodes: f64, per_node: MemoryPerNode) -> f64 {
    BASE + nodes * per_node.bytes
}

/// Refuses a run of `nodes` nodes at `per_node` whose estimate exceeds
/// `budget` (bytes).
pub fn check_memory_with(nodes: f64, per_node: MemoryPerNode, budget: f64) -> Result<()> {
    let estimate = estimate(nodes, per_node);
    if estimate <= budget {
        Ok(())
    } else {
        Err(Error::MemoryBudget {
            nodes,
            estimate,
            budget,
            per_node: per_node.bytes,
        })
    }
}

/// [`check_memory_with`] the budget of [`memory_budget`].
pub fn check_memory(nodes: f64, per_node: MemoryPerNode) -> Result<()> {
    check_memory_with(nodes, per_node, memory_budget()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_parse_with_binary_suffixes() {
        assert_eq!(parse_budget("8G").unwrap(), 8.0 * GIB);
        assert_eq!(parse_budget(" 512 MiB").unwrap(), 512.0 * 1024.0 * 1024.0);
        assert_eq!(parse_budget("1t").unwrap(), 1024.0 * GIB);
        assert_eq!(parse_budget("100000000").unwrap(), 1e8);
        for bad in ["", "G", "x1G", "8 GB GB"] {
            assert_eq!(parse_budget(bad).unwrap_err().name(), "ParseValue", "{bad}");
        }
        for out in ["1K", "-8G", "inf", "nan", "2048T"] {
            let e = parse_budget(out).unwrap_err();
            assert_eq!(e.name(), "OutOfRange", "{out}");
            assert!(e.to_string().contains(MEMORY_BUDGET_VAR), "{e}");
        }
    }

    /// The estimate is the base plus the nodes at their measured bytes, and
    /// the error gives the estimate and the budget.
    #[test]
    fn a_run_over_the_budget_is_refused_with_both_figures() {
        let per = MemoryPerNode { bytes: 16_000.0 };
        check_memory_with(1e5, per, 8.0 * GIB).unwrap();
        let e = check_memory_with(6.3e6, per, 8.0 * GIB).unwrap_err();
        assert_eq!(e.name(), "MemoryBudget");
        let m = e.to_string();
        assert!(m.contains("6300000 nodes") && m.contains("8.0 GiB"), "{m}");
        assert!(m.contains(MEMORY_BUDGET_VAR), "{m}");
    }
}
