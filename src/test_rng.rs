//! The tests' random numbers: Knuth's MMIX linear congruential generator,
//! seeded, so that every test draws the same numbers on every machine.

/// Uniform numbers in `[0, 1)` from `seed`: the top 53 bits of each state.
pub(crate) fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}
