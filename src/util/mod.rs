//! **Leaf helpers below every stage**: atomic file writes, fast decimal
//! text and, for unit tests, seeded numbers. They import nothing from the
//! crate but [`std`], so that every stage (the file readers and writers in
//! [`io`](crate::io), the program emitters, the report) can use them
//! without importing each other.
pub mod atomic;
pub mod decimal;

/// Seeded uniform numbers in `[lo, hi)` for unit tests (xorshift64): the
/// same sequence on every machine, no dependency.
#[cfg(test)]
pub(crate) fn uniform(mut seed: u64, lo: f64, hi: f64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        lo + (seed >> 11) as f64 / (1u64 << 53) as f64 * (hi - lo)
    }
}
