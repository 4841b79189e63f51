//! Stage 7 — the program stage and the readers behind `waam check`: the
//! late stages of `plan` (program model, transits, whole-cell check) as
//! ratios to the optimiser's time in the same runs ([`late_stages`]), and
//! how fast the FANUC, KUKA and ABB readers answer large inputs (a 1 MB
//! line, refused; a golden program with one motion repeated 20 000 times).
//! The robustness test `program_readers_answer_large_inputs` checks the
//! readers' answers; this bench times them.

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::Criterion;
use waam_slicer::pipeline::PlanTimes;
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

/// The late stages of `plan` against the optimiser [issue 46]: the whole
/// `plan_part` of the nozzle and the helix in the ROBOWAM part-carried cell
/// and of the hemisphere in the ROBOWAM torch-carried cell, at the part
/// files' own grids. Each iteration is one `plan_part`; criterion times
/// three stages of it as reported by the plan ([`PlanTimes`]): the
/// optimiser, the program stage without the whole-cell check (joint
/// trajectory, program model, transits, interpolation checks) and the
/// whole-cell check. After each part the mean ratio of the two late stages
/// to the optimiser over the iterations is printed (same runs), which is
/// what carries across machines; the target is a sum of at most 1.
pub fn late_stages(c: &mut Criterion) {
    let parts = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("parts");
    let mut g = c.benchmark_group("late_stages");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10));
    for (part, cell) in [
        ("nozzle", "robowam_part_carried"),
        ("helix", "robowam_part_carried"),
        ("hemisphere", "robowam_torch_carried"),
    ] {
        let p = waam_slicer::Part::read(parts.join(format!("{part}.toml"))).unwrap();
        let c = waam_slicer::Cell::read(parts.join(format!("cells/{cell}.toml"))).unwrap();
        let opts = waam_slicer::PlanOptions::default();
        let ratios = std::cell::RefCell::new(Vec::<[f64; 2]>::new());
        let stage = |t: &PlanTimes, which: usize| match which {
            0 => t.optimise,
            1 => t.program - t.cell_check,
            _ => t.cell_check,
        };
        for (which, name) in ["optimise", "program", "cell_check"].iter().enumerate() {
            g.bench_function(format!("{part}_{cell}/{name}"), |b| {
                b.iter_custom(|iters| {
                    let mut total = Duration::ZERO;
                    for _ in 0..iters {
                        let planned = waam_slicer::plan_part(black_box(&p), &c, &opts).unwrap();
                        assert!(planned.program.is_ok(), "{part} in {cell}: no program");
                        let t = planned.times;
                        ratios
                            .borrow_mut()
                            .push([stage(&t, 1) / t.optimise, stage(&t, 2) / t.optimise]);
                        total += Duration::from_secs_f64(stage(&t, which));
                    }
                    total
                })
            });
        }
        let r = ratios.borrow();
        let n = r.len().max(1) as f64;
        let (program, check) = r
            .iter()
            .fold((0.0, 0.0), |(a, b), x| (a + x[0] / n, b + x[1] / n));
        // the machine's load during the runs (the ratios hold on a loaded
        // machine only while every stage gets the same share of it)
        let load = std::fs::read_to_string("/proc/loadavg")
            .ok()
            .and_then(|l| l.split_whitespace().next().map(str::to_string))
            .unwrap_or_else(|| "?".into());
        eprintln!(
            "late_stages {part} in {cell}: program {program:.2} x optimise, cell_check \
             {check:.2} x optimise, sum {:.2} ({} plans, load average {load})",
            program + check,
            r.len()
        );
    }
    g.finish();
}
