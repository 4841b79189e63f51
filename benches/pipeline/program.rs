//! Stage 7 — the program readers behind `waam check`: how fast the FANUC,
//! KUKA and ABB readers answer large inputs (a 1 MB line, refused; a golden
//! program with one motion repeated 20 000 times). The robustness test
//! `program_readers_answer_large_inputs` checks their answers; this bench
//! times them.

use std::hint::black_box;
use std::path::Path;

use criterion::Criterion;
use waam_slicer::program::{abb::parse_mod, fanuc::parse_ls, kuka::parse_krl};

fn golden(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/program/golden")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// `text` with its first line containing `marker` repeated `n` times.
fn repeated(text: &str, marker: &str, n: usize) -> String {
    let line = text
        .lines()
        .find(|l| l.contains(marker))
        .unwrap_or_else(|| panic!("no line with {marker}"))
        .to_string()
        + "\n";
    text.replacen(&line, &line.repeat(n), 1)
}

/// The three readers on a 1 MB line and on 20 000 repeated motions.
pub fn readers(c: &mut Criterion) {
    let long_line = "x".repeat(1 << 20);
    let ls = repeated(&golden("fanuc_cartesian_HEMI.ls"), ":L P[", 20_000);
    let src = repeated(&golden("kuka_cartesian_HEMI.src"), "  LIN P2", 20_000);
    let dat = golden("kuka_cartesian_HEMI.dat");
    let m = repeated(&golden("abb_HEMI.mod"), "CONST robtarget p2 ", 20_000);
    let mut g = c.benchmark_group("program/readers");
    g.sample_size(10);
    g.bench_function("long_line_1mb_three_readers", |b| {
        b.iter(|| {
            let _ = black_box(parse_ls(black_box(&long_line), "long.ls"));
            let _ = black_box(parse_mod(black_box(&long_line), "long.mod"));
            let _ = black_box(parse_krl(&long_line, "long.src", &long_line, "long.dat"));
        })
    });
    g.bench_function("fanuc_20k_motions", |b| {
        b.iter(|| black_box(parse_ls(black_box(&ls), "many.ls")).is_ok())
    });
    g.bench_function("kuka_20k_motions", |b| {
        b.iter(|| black_box(parse_krl(black_box(&src), "many.src", &dat, "many.dat")).is_ok())
    });
    g.bench_function("abb_20k_targets", |b| {
        b.iter(|| black_box(parse_mod(black_box(&m), "many.mod")).is_ok())
    });
    g.finish();
}
