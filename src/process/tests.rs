//! Unit tests of the process stage.
