//! Unit tests of the tool-axis stage.
