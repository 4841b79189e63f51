//! Integration tests of the robot stage (SPEC §6).
