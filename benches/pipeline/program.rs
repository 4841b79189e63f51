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

/// The process's CPU time so far (s): the time its threads ran, summed
/// (Linux `/proc/self/task/*/schedstat`, nanoseconds; a thread that ended
/// is left out, and a plan's threads are rayon's, which do not end);
/// `None` where that is not available.
fn cpu_s() -> Option<f64> {
    let ns: u64 = std::fs::read_dir("/proc/self/task")
        .ok()?
        .filter_map(|e| {
            let s = std::fs::read_to_string(e.ok()?.path().join("schedstat")).ok()?;
            s.split_whitespace().next()?.parse::<u64>().ok()
        })
        .sum();
    (ns > 0).then_some(ns as f64 * 1e-9)
}

/// The process's CPU time (s) at the plan's progress reports: when the
/// optimiser starts, when the program stage starts and when it ends.
#[derive(Default, Clone, Copy)]
struct StageCpu {
    optimise: Option<f64>,
    program: Option<f64>,
    end: Option<f64>,
}

impl StageCpu {
    /// The program stage's CPU time over the optimiser's (the optimiser's
    /// window also holds the split and slow-down passes, none on these
    /// parts), when all three were read.
    fn ratio(&self) -> Option<f64> {
        let (o, p, e) = (self.optimise?, self.program?, self.end?);
        Some((e - p) / (p - o))
    }
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
/// what carries across machines; the target is a sum of at most 1. Beside
/// the wall-clock ratios, the ratio of the whole program stage's CPU time
/// to the optimiser's (all threads, read at the plan's progress reports:
/// on a loaded machine the wall clock also counts the time a stage waited
/// for a core).
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
        let cpu_ratios = std::cell::RefCell::new(Vec::<f64>::new());
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
                        let cpu = std::sync::Arc::new(std::sync::Mutex::new(StageCpu::default()));
                        let seen = std::sync::Arc::clone(&cpu);
                        let control =
                            waam_slicer::Control::default().with_progress(move |name, done| {
                                let mut s = seen.lock().unwrap();
                                match name {
                                    "optimising" if s.optimise.is_none() => s.optimise = cpu_s(),
                                    "program" if s.program.is_none() => s.program = cpu_s(),
                                    "program" if done >= 1.0 => s.end = cpu_s(),
                                    _ => {}
                                }
                            });
                        let planned =
                            waam_slicer::plan_part_with(black_box(&p), &c, &opts, &control)
                                .unwrap();
                        assert!(planned.program.is_ok(), "{part} in {cell}: no program");
                        let t = planned.times;
                        ratios
                            .borrow_mut()
                            .push([stage(&t, 1) / t.optimise, stage(&t, 2) / t.optimise]);
                        if let Some(r) = cpu.lock().unwrap().ratio() {
                            cpu_ratios.borrow_mut().push(r);
                        }
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
        let cpu = cpu_ratios.borrow();
        let cpu_text = if cpu.is_empty() {
            "CPU time not available".to_string()
        } else {
            format!(
                "by CPU time {:.2} (mean of {})",
                cpu.iter().sum::<f64>() / cpu.len() as f64,
                cpu.len()
            )
        };
        // the machine's load during the runs (the ratios hold on a loaded
        // machine only while every stage gets the same share of it)
        let load = std::fs::read_to_string("/proc/loadavg")
            .ok()
            .and_then(|l| l.split_whitespace().next().map(str::to_string))
            .unwrap_or_else(|| "?".into());
        eprintln!(
            "late_stages {part} in {cell}: by wall time program {program:.2} x optimise, \
             cell_check {check:.2} x optimise, sum {:.2}; {cpu_text} ({} plans, load average \
             {load})",
            program + check,
            r.len()
        );
    }
    g.finish();
}
