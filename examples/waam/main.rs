//! The waam command-line tool (work in progress).
fn main() {}
