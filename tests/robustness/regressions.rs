//! Inputs that once crashed (panicked, hung or leaked a NaN), found by the
//! fuzz targets in `fuzz/` or by review; each is fed as it was and must now be
//! refused with an error naming the problem. Files too long to inline are in
//! `tests/robustness/regressions/`.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use waam_slicer::fit::{fit_tube, FitOptions, TubeMesh};
use waam_slicer::geometry::guide::{Expression, Line};
use waam_slicer::geometry::{FrameMethod, GeometryError, ProfileLaw, Tube, TubeRange};
use waam_slicer::math::{Point3, Vector3};

fn regression_file(name: &str) -> Vec<u8> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/robustness/regressions")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Review: a piecewise profile with no pieces panicked (index `0 - 1`) in
/// `ProfileLaw::radius`; part files refuse it earlier, the API did not.
#[test]
fn piecewise_profile_without_pieces_is_refused_by_the_tube() {
    let e = Tube::new(
        Arc::new(Line {
            origin: Point3::origin(),
            direction: Vector3::z_axis(),
        }),
        FrameMethod::default(),
        None,
        ProfileLaw::Piecewise(Vec::new()),
        TubeRange::new(0.0, 10.0),
    )
    .unwrap_err();
    assert!(
        matches!(e, GeometryError::NonFinite { t, .. } if t == 0.0),
        "{e:?}"
    );
    assert!(e.to_string().contains("profile radius"), "{e}");
}

fn expression_error(text: &str) -> String {
    match Expression::parse(text, "t", &BTreeMap::new()) {
        Ok(_) => panic!("accepted {} characters", text.len()),
        Err(e) => {
            assert!(matches!(e, GeometryError::Expression { .. }), "{e:?}");
            e.to_string()
        }
    }
}

/// Review (probing the expression target): 400 nested `sin(` overflowed the
/// stack while differentiating (SIGSEGV after 26 s).
#[test]
fn deeply_nested_expression_is_refused() {
    let text = format!("{}t{}", "sin(".repeat(400), ")".repeat(400));
    let msg = expression_error(&text);
    assert!(msg.contains("nest 400 deep; the limit is 32"), "{msg}");
}

/// Review: `t^t^...^t` (300 uses) overflowed the stack; a product of 60
/// factors `(1+t/k)` took 18 s and 3.3 GB before overflowing it.
#[test]
fn expression_with_too_many_uses_of_t_is_refused() {
    let tower = vec!["t"; 300].join("^");
    let msg = expression_error(&tower);
    assert!(msg.contains("tokens") || msg.contains("uses `t`"), "{msg}");
    let product: Vec<String> = (1..60).map(|k| format!("(1+t/{k})")).collect();
    let msg = expression_error(&product.join("*"));
    assert!(msg.contains("471 tokens"), "{msg}");
    let msg = expression_error(&vec!["t"; 59].join("*"));
    assert!(msg.contains("uses `t` 59 times; the limit is 24"), "{msg}");
}

/// Review: 3000 unary minus signs took 15 s to differentiate; 1000 `sin `
/// without parentheses timed out (100 s).
#[test]
fn long_unary_chains_are_refused() {
    let msg = expression_error(&format!("{}t", "-".repeat(3000)));
    assert!(
        msg.contains("3001 tokens") && msg.contains("limit is 256"),
        "{msg}"
    );
    let msg = expression_error(&format!("{}t", "sin ".repeat(1000)));
    assert!(msg.contains("tokens"), "{msg}");
}

/// Review: a chain of 24 divisions by `t` (within every text limit) took
/// 26 s and 5 GB; `t/(t*(t/(t*...)))` 76 s and 2 GB. The work bound per
/// differentiation refuses them at once.
#[test]
fn expression_whose_derivatives_explode_is_refused_quickly() {
    // the refusal is the work bound's ("too complex"): without it both
    // expressions are differentiated in full (tens of seconds, GBs)
    let chain = vec!["t"; 24].join("/");
    let msg = expression_error(&chain);
    assert!(msg.contains("too complex"), "{msg}");
    let nested = format!("{}t{}", "t/(t*(".repeat(7), "))".repeat(7));
    let msg = expression_error(&nested);
    assert!(msg.contains("too complex"), "{msg}");
}

/// What the limits must not refuse: the sample parts' kind of expressions.
#[test]
fn ordinary_expressions_pass_the_limits() {
    let c = BTreeMap::from([("R_s".to_string(), 45.0)]);
    for text in [
        "sqrt(R_s^2 - t^2)",
        "(0.005 * t^3 - 0.22 * t^2) / 6",
        "5 + cos(8 * PI * t / 40)",
        "1 + 2*t + 3*t^2 + 4*t^3 + 5*t^4 + 6*t^5 + 7*t^6 + 8*t^7 + 9*t^8 + 10*t^9",
        "exp(-t/20) * sin(t) / (1 + t^2) + atan(t) * cosh(t / 50)",
    ] {
        if let Err(e) = Expression::parse(text, "t", &c) {
            panic!("{text}: {e}");
        }
    }
}

/// Probing the ABB reader behind `waam check` (issue 22): a `robtarget`
/// whose brackets nest 20 000 deep overflowed the stack of the recursive
/// aggregate parser (a 2 MiB test thread; `waam check`'s 8 MiB main thread
/// at about 80 000). Nesting beyond 16 is refused at once.
#[test]
fn deeply_nested_abb_aggregate_is_refused() {
    for depth in [17usize, 20_000, 1_000_000] {
        let text = format!(
            "MODULE X\n  CONST robtarget p1 := {}1{};\nENDMODULE\n",
            "[".repeat(depth),
            "]".repeat(depth)
        );
        let e = waam_slicer::program::abb::read::parse_mod(&text, "deep.mod").unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with("deep.mod:2: ") && msg.contains("nest more than 16 deep"),
            "{}",
            &msg[..msg.len().min(200)]
        );
    }
}

/// Probes of the program readers behind `waam check` with large inputs: a
/// 1 MB line is refused naming its file, and programs with 20 000 repeated
/// motions answer (read, or refused naming their file). How fast they
/// answer is measured by the `program/readers` bench in `benches/`, not
/// here (a wall-clock bound fails on a loaded box).
#[test]
fn program_readers_answer_large_inputs() {
    use waam_slicer::program::{abb::parse_mod, fanuc::parse_ls, kuka::parse_krl};
    let golden = |name: &str| {
        std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/program/golden")
                .join(name),
        )
        .unwrap()
    };
    let names_file = |e: String, file: &str| assert!(e.contains(file), "{file}: {e}");
    let long_line = "x".repeat(1 << 20);
    names_file(
        parse_ls(&long_line, "long.ls").unwrap_err().to_string(),
        "long.ls",
    );
    names_file(
        parse_mod(&long_line, "long.mod").unwrap_err().to_string(),
        "long.mod",
    );
    names_file(
        parse_krl(&long_line, "long.src", &long_line, "long.dat")
            .unwrap_err()
            .to_string(),
        "long.",
    );
    // a golden with its motion lines repeated 20 000 times
    let ls = golden("fanuc_cartesian_HEMI.ls");
    let motion = ls
        .lines()
        .find(|l| l.contains(":L P["))
        .unwrap()
        .to_string()
        + "\n";
    if let Err(e) = parse_ls(&ls.replacen(&motion, &motion.repeat(20_000), 1), "many.ls") {
        names_file(e.to_string(), "many.ls");
    }
    let src = golden("kuka_cartesian_HEMI.src");
    let dat = golden("kuka_cartesian_HEMI.dat");
    if let Err(e) = parse_krl(
        &src.replacen("  LIN P2\n", &"  LIN P2\n".repeat(20_000), 1),
        "many.src",
        &dat,
        "many.dat",
    ) {
        names_file(e.to_string(), "many.");
    }
    let m = golden("abb_HEMI.mod");
    let target = m
        .lines()
        .find(|l| l.contains("CONST robtarget p2 "))
        .unwrap()
        .to_string()
        + "\n";
    if let Err(e) = parse_mod(&m.replacen(&target, &target.repeat(20_000), 1), "many.mod") {
        names_file(e.to_string(), "many.mod");
    }
}

/// Fuzz `fit_stl` (its artifact oom-1edf5395, less the units byte): with 4
/// refits, the guide of the last one had diverged and the final sections
/// were taken on it unchecked, 186 M station frames (a 7.4 GB allocation;
/// libFuzzer's 4 GB limit stopped it). The last refit's guide now gets the
/// length checks every refit's gets: refused naming the file, the process
/// peaking under 1 GB (read from /proc: the allocation itself is what
/// failed).
#[test]
fn a_fit_whose_last_refit_diverged_is_refused_not_sectioned() {
    let bytes = regression_file("fit-last-refit-diverged.stl");
    let mesh = TubeMesh::from_stl_bytes(&bytes, "fuzz.stl").expect("an STL");
    let opts = FitOptions {
        max_iterations: 4,
        check_surface: false,
        ..FitOptions::default()
    };
    let e = fit_tube(&mesh, &opts).unwrap_err();
    assert!(e.to_string().starts_with("fuzz.stl: "), "{e}");
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let peak_kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0);
    assert!(peak_kb < 1_000_000, "peak {peak_kb} kB");
}
