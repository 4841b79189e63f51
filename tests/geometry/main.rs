//! Integration tests of the geometry stage (SPEC §2).
