//! **Leaf helpers below every stage**: atomic file writes and fast decimal
//! text. They import nothing from the crate but [`std`], so that every stage
//! (the file readers and writers in [`io`](crate::io), the program emitters,
//! the report) can use them without importing each other.
pub mod atomic;
pub mod decimal;
