//! The ranks of a `run` (cargo feature `mpi`: `mpiexec -n N meshless-impact
//! run ...`; one rank otherwise) and what they agree on: a failure at the
//! start on any rank stops every rank with its message and exit status,
//! and a signal received by any rank stops every rank at the same step.
//! Rank 0 alone writes the outputs and prints; the others are silent.

use super::stop::Stop;
use meshless_impact::ranks::{Handle, Ranks};

/// The ranks of this process's run: MPI's world with the feature `mpi`,
/// else one rank alone.
pub(crate) fn join() -> Result<Handle, Stop> {
    #[cfg(feature = "mpi")]
    {
        let world = super::mpi::init().map_err(|e| Stop::failed(format!("MPI: {e}")))?;
        Ok(Handle::new(std::sync::Arc::new(world)))
    }
    #[cfg(not(feature = "mpi"))]
    Ok(Handle::default())
}

/// `r` on every rank where it is `Ok` on all; else the failure of the
/// first failing rank, on every rank (printed by rank 0 alone: the others
/// give the same exit status with no lines).
pub(crate) fn agree<T>(team: &dyn Ranks, r: Result<T, Stop>) -> Result<T, Stop> {
    if team.size() == 1 {
        return r;
    }
    let mine = r.as_ref().err().map(encode);
    match first_failure(team, mine) {
        None => r,
        Some((rank, bytes)) => {
            let stop = decode(&bytes, rank);
            Err(if team.rank() == 0 { stop } else { silent(stop) })
        }
    }
}

/// The lowest rank whose `mine` is `Some`, with its bytes, on every rank;
/// `None` when no rank's is (one exchange, and a broadcast when some
/// rank's is).
fn first_failure(team: &dyn Ranks, mine: Option<Vec<u8>>) -> Option<(i64, Vec<u8>)> {
    let me = team.rank() as i64;
    let failed = team.all_min(if mine.is_some() { me } else { i64::MAX });
    if failed == i64::MAX {
        return None;
    }
    let mut bytes = if failed == me {
        mine.unwrap_or_default()
    } else {
        Vec::new()
    };
    team.broadcast(failed as usize, &mut bytes);
    Some((failed, bytes))
}

/// The lowest rank whose `mine` is `Some` (an error of a collective
/// output), with its message, on every rank; `None` when no rank's is.
pub(crate) fn first_error(team: &dyn Ranks, mine: Option<String>) -> Option<(usize, String)> {
    if team.size() == 1 {
        return mine.map(|m| (0, m));
    }
    let (rank, bytes) = first_failure(team, mine.map(String::into_bytes))?;
    Some((rank as usize, String::from_utf8_lossy(&bytes).into_owned()))
}

/// The signal that asked any rank to stop (its number; 0 for none): every
/// rank breaks off at the same step.
pub(crate) fn agree_signal(team: &dyn Ranks, signal: i32) -> i32 {
    if team.size() == 1 {
        return signal;
    }
    team.all_max(i64::from(signal.max(0))) as i32
}

/// Whether `mine` holds on some rank, on every rank (one exchange).
pub(crate) fn any(team: &dyn Ranks, mine: bool) -> bool {
    if team.size() == 1 {
        return mine;
    }
    team.all_max(i64::from(mine)) > 0
}

/// After a step that failed on some ranks and not on this one (`mine` is
/// `None`): the first failing rank's message, as this rank's stop. The
/// ranks compute the same steps from the same state, so this happens only
/// if they diverged, a fault; the run stops rather than hangs. `None`
/// when no rank failed, or when this rank failed too (its own error
/// stands).
pub(crate) fn diverged(team: &dyn Ranks, mine: Option<String>) -> Option<Stop> {
    if team.size() == 1 {
        return None;
    }
    let failed_here = mine.is_some();
    let (rank, bytes) = first_failure(team, mine.map(String::into_bytes))?;
    if failed_here {
        return None;
    }
    Some(Stop::Failed(vec![format!(
        "rank {rank} stopped with \"{}\" at a step that this rank (rank {}) passed: the ranks diverged",
        String::from_utf8_lossy(&bytes),
        team.rank()
    )]))
}

/// The end of a run on rank `team.rank()`: rank 0's as it is, the others'
/// with the same exit status and nothing printed.
pub(crate) fn quiet_unless_root(team: &dyn Ranks, r: Result<(), Stop>) -> Result<(), Stop> {
    if team.rank() == 0 {
        r
    } else {
        r.map_err(silent)
    }
}

fn silent(stop: Stop) -> Stop {
    match stop {
        Stop::Failed(_) => Stop::Failed(Vec::new()),
        Stop::Interrupted(_) => Stop::Interrupted(Vec::new()),
        Stop::BrokenPipe => Stop::BrokenPipe,
    }
}

/// A stop as bytes: its kind, then its lines as JSON.
fn encode(stop: &Stop) -> Vec<u8> {
    let (kind, lines): (u8, &[String]) = match stop {
        Stop::Failed(l) => (b'F', l),
        Stop::Interrupted(l) => (b'I', l),
        Stop::BrokenPipe => (b'B', &[]),
    };
    let mut out = vec![kind];
    out.extend(serde_json::to_vec(lines).unwrap_or_default());
    out
}

/// The stop of [`encode`], its lines marked with the rank that failed.
fn decode(bytes: &[u8], rank: i64) -> Stop {
    let lines: Vec<String> = bytes
        .get(1..)
        .and_then(|b| serde_json::from_slice(b).ok())
        .unwrap_or_default();
    let mark = |lines: Vec<String>| -> Vec<String> {
        lines
            .into_iter()
            .map(|l| format!("{l} (rank {rank})"))
            .collect()
    };
    match bytes.first() {
        Some(b'I') => Stop::Interrupted(mark(lines)),
        Some(b'B') => Stop::BrokenPipe,
        _ => Stop::Failed(mark(lines)),
    }
}
