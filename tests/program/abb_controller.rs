//! ABB RAPID modules a controller loads (issue 18): every identifier
//! declared (or named in the options as controller data), ArcWare data,
//! coordinated positioner, home, per-bead payload / dwell / interpass wait,
//! read back and validated; every emitted module passes two RAPID grammar
//! checkers: our independent recogniser ([`crate::rapid_grammar`]) and, when
//! installed, the third-party `rapidchecker` (PyPI, pyparsing grammar of
//! ABB RAPID, "tested with RobotWare 5 code").
//!
//! Reviewed against (public, third-party sources; none is ABB's current
//! manual itself):
//! * RAPID reference (the "Basic Characteristics RAPID"/RAPID reference
//!   manual pages as published on yumpu): `tooldata` `[robhold, tframe,
//!   tload]`, `tload` for a stationary tool = the load the robot holds
//!   besides the payload, `GripLoad` for the payload; `loaddata` `[mass kg,
//!   cog mm, aom, ix, iy, iz kg·m²]` with a payload's `cog` in the tool
//!   frame, or in the object frame with a stationary tool (also the ROS
//!   `abb_rapid_msgs/LoadData` message doc); `wobjdata` `[robhold, ufprog,
//!   ufmec, uframe, oframe]`, with coordinated external axes `ufprog` FALSE,
//!   `ufmec` the mechanical unit and the user frame taken from the system
//!   parameters; speeds relative to the work object with a stationary tool
//!   or coordinated external axes.
//! * ABB MultiMove application manual (3HAC021272-001 rev. H, "Coordinated
//!   work objects"): `PERS wobjdata wobj_stn1 := [FALSE, FALSE, "STN_1",
//!   [[0,0,0],[1,0,0,0]], [[0,0,250],[1,0,0,0]]]`, the form of `wWaam` here.
//! * ArcWare data layouts, RobotWare 6 Arc: published controller modules on
//!   GitHub (`TASK PERS seamdata seam1:=[0.5,0.5,[5,0,24,120,0,0,0,0,0],0.5,
//!   1,10,0,5,[...],0,1,[...],0,0,[...],0]` = 16 components with `arcdata`
//!   at 3, 9, 12, 15; `welddata weld1:=[6,0,[5,0,24,120,0,0,0,0,0],[0,...]]`
//!   = `[weld_speed, org_weld_speed, main_arc, org_arc]`, `arcdata` of 9),
//!   and a data-type page giving `weld_speed` in mm/s. The component names
//!   (purge_time, preflow_time, ign_arc, ..., postflow_time) agree with the
//!   vendor notes' sources (§3, below), not with the Arc application manual
//!   itself.
//! * `WaitTime`, `WaitDI signal, 1`, `MoveAbsJ`, `ConfL \On`, `\T`,
//!   `\WObj`: RAPID reference from memory, and published modules.
//! * Names (issue 32): RAPID reference, "Basic Characteristics RAPID" §3.1
//!   routine scope and §5.1 data scope (yumpu 5679047 pp. 87, 96): `LOCAL
//!   PROC`/`LOCAL PERS|VAR|CONST` are visible in their module only, hide a
//!   global of the same name, and are allowed at module level only; routine
//!   and module names share one name space (vendor notes §3: RoboDK's ABB
//!   post writes `MODULE MOD_<prog>` holding `PROC <prog>()`). So the module
//!   is `MOD_<name>`, its one global routine `<name>`, all else `LOCAL`.
//! * `ActUnit STN1;` / `DeactUnit STN1;` (a `mecunit` argument): published
//!   controller modules (vendor notes §3, "Mechanical units").
//! * `seamdata` gas times: components 1 (`purge_time`), 2 (`preflow_time`)
//!   and 16 (`postflow_time`) of the 16 (vendor notes §3: ABB's SeamData.js
//!   field order, zwj12/ZhongXunRapid modules, RW 6.15 `seamdata.xml`).
//!
//! Not verified: that a controller (or RobotStudio) loads these modules;
//! that ArcWare accepts `sched` with every other `arcdata` component 0 for
//! the power sources in use; the RobotWare 5 layouts (different); that the
//! positioner unit's coordinated user frame, as calibrated, is our table
//! frame; whether ArcWare honours `\T` on `ArcL` (v_reax bounds the move
//! either way); the default 3 kg torch load (identify the real one).

use std::process::Command;

use waam_slicer::math::{Point3, Vector3};
use waam_slicer::program::abb::read::{parse_mod, RapidOp};
use waam_slicer::program::abb::validate_abb;
use waam_slicer::program::abb::{abb_files, AbbLoad, AbbOptions};
use waam_slicer::program::validate::{ProblemKind, ValidationReport};
use waam_slicer::program::{
    build_program, BeadSetup, EmittedFile, HomePosition, Payload, PlannedPoint, PointFeed,
    ProcessControl, Program, ProgramError,
};
use waam_slicer::robot::CellLayout;

use crate::fixture::{cell, program, ABB_CELLS};
use crate::golden::check_golden;
use crate::rapid_grammar::{check_module, check_task};

const PART: &str = "abb_irb2600_part_carried.toml";
const TORCH: &str = "abb_irb2600_torch_carried.toml";

fn planned(prog: &Program) -> Vec<PlannedPoint> {
    prog.planned.clone()
}

fn check(text: &str, c: &CellLayout, opts: &AbbOptions, plan: &[PlannedPoint]) -> ValidationReport {
    let m = parse_mod(text, "HEMI.mod").unwrap_or_else(|e| panic!("{e}\n{text}"));
    validate_abb(&m, c, opts, Some(plan))
}

fn has(r: &ValidationReport, kind: ProblemKind, line: usize, words: &str) -> bool {
    r.problems
        .iter()
        .any(|p| p.kind == kind && p.line == line && p.message.contains(words))
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("`{needle}` not found in\n{text}"))
}

/// Two layers in the part-carried cell with home, a payload before each
/// bead, a 30 s dwell and an interpass wait on input 3 before the second:
/// set by hand, as `build_program_with` will (issue 18 interface).
fn setup_program() -> (Program, AbbOptions) {
    let c = cell(PART);
    let (mut prog, _) = program(&c, 0..2, 8);
    let mut home = prog.points[0].joints;
    home[0] += 20f64.to_radians();
    home[1] -= 10f64.to_radians();
    assert_eq!(c.robot().configuration_of(&home), c.configuration());
    prog.home = Some(HomePosition {
        joints: home,
        positioner: None,
    });
    prog.bead_setup = vec![
        BeadSetup {
            layer: 0,
            payload: Some(Payload {
                mass_kg: 2.0,
                cog_mm: Point3::new(-40.0, 0.0, 10.0),
            }),
            dwell_s: 0.0,
            wait_input: None,
        },
        BeadSetup {
            layer: 1,
            payload: Some(Payload {
                mass_kg: 2.0123,
                cog_mm: Point3::new(-41.5, 0.5, 10.25),
            }),
            dwell_s: 30.0,
            wait_input: Some(3),
        },
    ];
    let mut opts = AbbOptions::default();
    opts.common.home_deg = Some(home.map(f64::to_degrees));
    opts.common.dwell_s = 30.0;
    opts.common.interpass_input = Some(3);
    opts.common.payload_every_layers = 1;
    opts.common.payload_base_kg = 2.0;
    opts.common.payload_base_cog_mm = [-40.0, 0.0, 10.0];
    (prog, opts)
}

#[test]
fn abb_setup_golden_reads_back_home_payload_dwell_and_wait() {
    let (prog, opts) = setup_program();
    let files = abb_files(&prog, &opts).unwrap();
    let text = &files[0].text;
    check_module(text).unwrap_or_else(|e| panic!("{e}"));
    // the set-up before bead 1's approach, in order payload, dwell, wait
    let l = line_of(text, "MoveAbsJ j11,");
    let lines: Vec<&str> = text.lines().collect();
    let before: Vec<&str> = lines[l - 8..l - 2].iter().map(|s| s.trim()).collect();
    assert_eq!(
        before,
        [
            "! bead 1 (layer 1): payload",
            "GripLoad loadWaam2;",
            "! bead 1 (layer 1): dwell (s)",
            "WaitTime 30.000;",
            "! bead 1 (layer 1): interpass wait, [program] interpass_input 3 = signal diInterpass",
            "WaitDI diInterpass, 1;",
        ],
        "{text}"
    );
    // home first and last
    let m = parse_mod(text, &files[0].name).unwrap();
    let motions: Vec<&RapidOp> = m
        .instructions
        .iter()
        .map(|i| &i.op)
        .filter(|op| matches!(op, RapidOp::MoveAbsJ { .. } | RapidOp::Linear { .. }))
        .collect();
    for op in [motions[0], motions[motions.len() - 1]] {
        assert!(
            matches!(op, RapidOp::MoveAbsJ { target, .. } if target == "jHome"),
            "{op:?}"
        );
    }
    // the payload's centre of gravity is written in the part (object) frame
    // of the robot-held work object: flange_from_part⁻¹ · cog
    let CellLayout::PartCarried(pc) = cell(PART) else {
        unreachable!()
    };
    let want = pc.flange_from_part.inverse() * Point3::new(-41.5, 0.5, 10.25);
    let (_, _, l2) = &m.loads[1];
    assert!(
        (l2.cog_mm - want).norm() < 1e-4,
        "{:?} vs {want:?}",
        l2.cog_mm
    );
    assert!((l2.mass_kg - 2.0123).abs() < 1e-9);
    // all of it validates (2 home moves on top of the 20 points)
    let r = check(text, &cell(PART), &opts, &planned(&prog));
    assert!(r.is_ok(), "{r}");
    assert_eq!((r.motions, r.beads), (22, 2));
    check_golden("abb_setup_HEMI.mod", text);
}

/// A WaitDI on another signal than the options' controller signal, or with
/// no interpass input in the options, a GripLoad of an undeclared load, an
/// undeclared welddata or seamdata, a zone RobotWare does not predefine and
/// an undeclared tool: each is named by its line.
#[test]
fn undeclared_identifiers_are_declaration_problems() {
    let (prog, opts) = setup_program();
    let text = &abb_files(&prog, &opts).unwrap()[0].text;
    let c = cell(PART);
    let plan = planned(&prog);
    let edit = |from: &str, to: &str| text.replacen(from, to, 1);
    let drop = |needle: &str| -> String {
        text.lines()
            .filter(|l| !l.contains(needle))
            .map(|l| format!("{l}\n"))
            .collect()
    };
    let wait = line_of(text, "WaitDI ");
    let r = check(
        &edit("WaitDI diInterpass", "WaitDI diOther"),
        &c,
        &opts,
        &plan,
    );
    assert!(has(&r, ProblemKind::Declaration, wait, "diOther"), "{r}");
    let mut no_input = opts.clone();
    no_input.common.interpass_input = None;
    let r = check(text, &c, &no_input, &plan);
    assert!(
        has(&r, ProblemKind::Options, wait, "interpass_input"),
        "{r}"
    );
    let grip = line_of(text, "GripLoad loadWaam2");
    let r = check(
        &edit("GripLoad loadWaam2", "GripLoad loadX"),
        &c,
        &opts,
        &plan,
    );
    assert!(
        has(&r, ProblemKind::Declaration, grip, "loaddata loadX"),
        "{r}"
    );
    // without the welddata and seamdata declarations (lines shift by 1)
    let arc = line_of(text, "ArcLStart p2,") - 1;
    let r = check(&drop("welddata weldWaam1"), &c, &opts, &plan);
    assert!(
        has(&r, ProblemKind::Declaration, arc, "welddata weldWaam1"),
        "{r}"
    );
    let r = check(&drop("seamdata seamWaam"), &c, &opts, &plan);
    assert!(
        has(&r, ProblemKind::Declaration, arc, "seamdata seamWaam"),
        "{r}"
    );
    let on = line_of(text, "ArcL p3,");
    let r = check(&edit("z1, tWaam", "z7, tWaam"), &c, &opts, &plan);
    assert!(has(&r, ProblemKind::Declaration, on, "zonedata z7"), "{r}");
    let first = line_of(text, "MoveAbsJ jHome");
    let r = check(&edit("fine, tWaam\\", "fine, tOther\\"), &c, &opts, &plan);
    assert!(
        has(&r, ProblemKind::Declaration, first, "tooldata tOther"),
        "{r}"
    );
}

/// One welddata per planned speed: a modulated travel speed (6 and 8 mm/s
/// alternating) gives two, each `ArcL` names the one of its speed, with the
/// same `v_tcp`; a `weld_speed` that differs from it is a timing problem.
#[test]
fn one_welddata_per_planned_speed_and_weld_speed_is_checked() {
    let c = cell(PART);
    let path = crate::fixture::hemisphere(0..2, 8, crate::fixture::law(&c));
    let tr = crate::fixture::trajectory(&c, &path);
    let speeds: Vec<f64> = (0..path.len())
        .map(|i| if i % 2 == 0 { 6.0 } else { 8.0 })
        .collect();
    let prog = build_program(
        "HEMI",
        &c,
        &path,
        &tr,
        &speeds
            .iter()
            .map(|&v| PointFeed {
                travel_speed_mm_s: v,
                wire_feed_mm_s: crate::fixture::WFS_MM_S,
            })
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let opts = AbbOptions::default();
    let text = &abb_files(&prog, &opts).unwrap()[0].text;
    let welds: Vec<&str> = text
        .lines()
        .filter(|l| l.contains("PERS welddata"))
        .collect();
    assert_eq!(welds.len(), 2, "{text}");
    for (k, v) in prog
        .points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.arc.is_bead() && p.arc != waam_slicer::program::ArcFlag::Start)
    {
        let l = text
            .lines()
            .find(|l| l.contains(&format!(" p{}, ", k + 1)) && l.contains("Arc"))
            .unwrap();
        assert!(
            l.contains(&format!("[{:.4},500,5000,1000]", v.speed_mm_s)),
            "{l}"
        );
        let w = l.split(", ").find(|s| s.starts_with("weldWaam")).unwrap();
        let decl = welds
            .iter()
            .find(|d| d.contains(&format!(" {w} := ")))
            .unwrap();
        assert!(
            decl.contains(&format!(":= [{:.4},", v.speed_mm_s)),
            "{decl} / {l}"
        );
    }
    let r = check(text, &c, &opts, &planned(&prog));
    assert!(r.is_ok(), "{r}");
    check_module(text).unwrap();
    // weld_speed 6 -> 7: every ArcL/ArcLEnd at 6 mm/s is flagged
    let bad = text.replacen(":= [6.0000,0,", ":= [7.0000,0,", 1);
    let r = check(&bad, &c, &opts, &planned(&prog));
    let l = line_of(text, "ArcL p4,");
    assert!(has(&r, ProblemKind::Timing, l, "weld_speed 7"), "{r}");
}

/// Coordinated (default): `wWaam` moves with STN1, the robtargets are the
/// torch in the part frame (a bead point's robtarget is its planned
/// position), no `\T`; a coordinated file checked with coordination off, or
/// another unit, is an options problem; a robtarget moved by 0.1 mm is a
/// deviation (the coordinated decoding is live). Not coordinated: a timed
/// move whose `v_reax` lets the positioner outrun its `\T` is a timing
/// problem.
#[test]
fn coordinated_work_object_and_v_reax() {
    let c = cell(TORCH);
    let (prog, _) = program(&c, 0..2, 8);
    let plan = planned(&prog);
    let opts = AbbOptions::default();
    let text = &abb_files(&prog, &opts).unwrap()[0].text;
    assert!(!text.contains("\\T:="), "{text}");
    let m = parse_mod(text, "HEMI.mod").unwrap();
    for (i, p) in prog.points.iter().enumerate() {
        let t = m
            .targets
            .iter()
            .find(|t| t.name == format!("p{}", i + 1))
            .unwrap();
        let waam_slicer::program::abb::read::RapidTargetValue::Rob { pose, .. } = &t.value else {
            panic!()
        };
        // the torch's TCP over the part frame (oframe = table_from_part = identity here)
        let d: Vector3 = pose.translation.vector - p.position_mm.coords;
        assert!(d.norm() < 1e-3, "p{}: {d:?}", i + 1);
    }
    assert!(check(text, &c, &opts, &plan).is_ok());
    let w = line_of(text, "PERS wobjdata wWaam");
    let mut off = opts.clone();
    off.common.coordinated = false;
    let r = check(text, &c, &off, &plan);
    assert!(has(&r, ProblemKind::Options, w, "coordinated"), "{r}");
    let other = AbbOptions {
        ufmec: "STN2".into(),
        ..opts.clone()
    };
    let r = check(text, &c, &other, &plan);
    assert!(has(&r, ProblemKind::Options, w, "\"STN2\""), "{r}");
    let l = line_of(text, "CONST robtarget p13 :=");
    let moved = text.replacen("[[31.6236,31.6236,4.9897]", "[[31.6236,31.6236,5.0897]", 1);
    assert_ne!(&moved, text);
    let r = check(&moved, &c, &opts, &plan);
    assert!(has(&r, ProblemKind::Deviation, l, "p13"), "{r}");
    // the same file in the part-carried cell: no positioner to move wWaam
    let r = check(text, &cell(PART), &opts, &plan);
    assert!(has(&r, ProblemKind::Frame, w, "no positioner"), "{r}");
    // not coordinated
    let free_text = &abb_files(&prog, &off).unwrap()[0].text;
    assert!(check(free_text, &c, &off, &plan).is_ok());
    let l = line_of(free_text, "ArcL p13,");
    let fast = free_text.replacen(",7.6857]\\T:=5.855", ",1000]\\T:=5.855", 1);
    let r = check(&fast, &c, &off, &plan);
    assert!(has(&r, ProblemKind::Timing, l, "v_reax 1000"), "{r}");
}

#[test]
fn bad_options_and_set_ups_are_refused_naming_the_field() {
    let (prog, opts) = setup_program();
    for (o, field) in [
        (
            AbbOptions {
                zone_mm: 7,
                ..opts.clone()
            },
            "`zone_mm`",
        ),
        (
            AbbOptions {
                interpass_signal: "1di".into(),
                ..opts.clone()
            },
            "`interpass_signal`",
        ),
        (
            AbbOptions {
                ufmec: "".into(),
                ..opts.clone()
            },
            "`ufmec`",
        ),
        (
            AbbOptions {
                purge_time_s: -0.1,
                ..opts.clone()
            },
            "`purge_time_s`",
        ),
        (
            AbbOptions {
                preflow_time_s: f64::NAN,
                ..opts.clone()
            },
            "`preflow_time_s`",
        ),
        (
            AbbOptions {
                postflow_time_s: f64::INFINITY,
                ..opts.clone()
            },
            "`postflow_time_s`",
        ),
        (
            AbbOptions {
                tool_load: Some(AbbLoad {
                    mass_kg: 0.0,
                    cog_mm: [0.0; 3],
                    inertia_kg_m2: [0.0; 3],
                }),
                ..opts.clone()
            },
            "`tool_load`",
        ),
    ] {
        let e = abb_files(&prog, &o).unwrap_err();
        assert!(
            matches!(e, ProgramError::InvalidOptions { .. }) && e.to_string().contains(field),
            "{e}"
        );
    }
    let mut short = prog.clone();
    short.bead_setup.pop();
    let e = abb_files(&short, &opts).unwrap_err().to_string();
    assert!(e.contains("1 bead set-ups for 2 beads"), "{e}");
    let mut nan = prog.clone();
    nan.bead_setup[1].dwell_s = f64::NAN;
    let e = abb_files(&nan, &opts).unwrap_err().to_string();
    assert!(e.contains("dwell_s"), "{e}");
    // a given tool load is written as given
    let o = AbbOptions {
        tool_load: Some(AbbLoad {
            mass_kg: 4.25,
            cog_mm: [10.0, 0.0, 120.0],
            inertia_kg_m2: [0.01, 0.02, 0.005],
        }),
        ..opts
    };
    let text = &abb_files(&prog, &o).unwrap()[0].text;
    assert!(
        text.contains(",[4.2500,[10.0000,0.0000,120.0000],[1,0,0,0],0.010000,0.020000,0.005000]];")
    );
}

/// Every module the emitter writes in the tests' settings: both example
/// cells, coordinated or not, arc or custom process, with and without
/// approach points, with the full set-up, and the golden files.
fn every_module() -> Vec<EmittedFile> {
    let mut out = Vec::new();
    let mut off = AbbOptions::default();
    off.common.coordinated = false;
    let custom = AbbOptions {
        process: ProcessControl::Custom {
            start: "SetDO doExtruder, 1".into(),
            end: "SetDO doExtruder, 0".into(),
        },
        ..Default::default()
    };
    for file in ABB_CELLS {
        let (prog, _) = program(&cell(file), 0..3, 12);
        for opts in [&AbbOptions::default(), &off, &custom] {
            out.extend(abb_files(&prog, opts).unwrap());
        }
    }
    let (prog, opts) = setup_program();
    out.extend(abb_files(&prog, &opts).unwrap());
    let golden = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/program/golden");
    for e in std::fs::read_dir(golden).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "mod") {
            out.push(EmittedFile {
                name: p.file_name().unwrap().to_string_lossy().into(),
                text: std::fs::read_to_string(&p).unwrap(),
            });
        }
    }
    assert!(out.len() >= 11);
    out
}

#[test]
fn every_emitted_module_passes_the_rapid_grammar() {
    for f in every_module() {
        check_module(&f.text).unwrap_or_else(|e| panic!("{}: {e}\n{}", f.name, f.text));
    }
}

/// The third-party checker: `python -m rapidchecker` (PyPI `rapidchecker`
/// 0.1.5) through the Python given by `WAAM_RAPIDCHECKER`, which `.ci/run`
/// installs; without it the test is skipped outside CI and fails in CI.
/// A module with a missing `;` must be refused (the harness is live).
#[test]
fn every_emitted_module_passes_rapidchecker() {
    let Some(python) = std::env::var_os("WAAM_RAPIDCHECKER") else {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must install rapidchecker and set WAAM_RAPIDCHECKER (see .ci/run)"
        );
        eprintln!("rapidchecker not installed (WAAM_RAPIDCHECKER unset): skipped");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let run = |files: &[std::path::PathBuf]| {
        Command::new(&python)
            .args(["-m", "rapidchecker"])
            .args(files)
            .current_dir(dir.path())
            .output()
            .expect("run rapidchecker")
    };
    let mut paths = Vec::new();
    for (i, f) in every_module().iter().enumerate() {
        let p = dir.path().join(format!("m{i}_{}", f.name));
        std::fs::write(&p, &f.text).unwrap();
        paths.push(p);
    }
    let out = run(&paths);
    assert!(
        out.status.success(),
        "rapidchecker refused:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let broken = dir.path().join("broken.mod");
    let text = std::fs::read_to_string(&paths[0]).unwrap();
    std::fs::write(&broken, text.replacen("ConfL \\On;", "ConfL \\On", 1)).unwrap();
    assert!(!run(&[broken]).status.success(), "a missing `;` passed");
}

/// Issue 32: the module's names. Every module the emitter writes is
/// `MODULE MOD_HEMI` with one global routine, `PROC HEMI()` (no `PROC
/// main`), and every other declaration at module level `LOCAL` (RAPID
/// reference §3.1, §5.1; module doc), read here from the text, not by our
/// reader.
#[test]
fn every_name_but_the_entry_routine_is_local() {
    let (prog, opts) = setup_program();
    let mut files = abb_files(&prog, &opts).unwrap();
    for file in ABB_CELLS {
        files.extend(abb_files(&program(&cell(file), 0..2, 8).0, &AbbOptions::default()).unwrap());
    }
    for f in &files {
        let text = &f.text;
        assert_eq!(f.name, "HEMI.mod");
        assert_eq!(text.lines().next(), Some("MODULE MOD_HEMI"), "{text}");
        assert!(!text.to_ascii_lowercase().contains("proc main"), "{text}");
        let mut in_routine = false;
        let mut globals = Vec::new();
        for l in text.lines().skip(1).map(str::trim) {
            if l.is_empty() || l.starts_with('!') || l == "ENDMODULE" {
                continue;
            }
            if l == "ENDPROC" {
                in_routine = false;
                continue;
            }
            if in_routine {
                continue;
            }
            if l.contains("PROC ") {
                in_routine = true;
            }
            if !l.starts_with("LOCAL ") {
                globals.push(l.to_string());
            }
        }
        assert_eq!(globals, ["PROC HEMI()"], "{text}");
    }
}

/// A task's own main module, the usual one: a global `main` that calls the
/// part's entry routine, and a global `tWaam`, `wWaam` and `p1` of its own.
const TASK_MAIN: &str = "MODULE MainModule
  PERS tooldata tWaam := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];
  PERS wobjdata wWaam := [FALSE,TRUE,\"\",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  CONST robtarget p1 := [[500,0,500],[1,0,0,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  PROC main()
    HEMI;
    NOZZLE;
  ENDPROC
ENDMODULE
";

/// Issue 32: the module loads into a task that already has a global
/// `main`, `tWaam`, `wWaam` and `p1`, next to another part's module (same
/// local names, other entry routine), in the independent scope model of
/// [`crate::rapid_grammar::check_task`]. The live checks: the same module
/// with its `LOCAL`s removed, or with the old `PROC main`, clashes.
#[test]
fn the_module_loads_into_a_task_with_its_own_main() {
    for file in ABB_CELLS {
        let c = cell(file);
        let (hemi, _) = program(&c, 0..2, 8);
        let mut nozzle = hemi.clone();
        nozzle.name = "NOZZLE".into();
        let a = &abb_files(&hemi, &AbbOptions::default()).unwrap()[0].text;
        let b = &abb_files(&nozzle, &AbbOptions::default()).unwrap()[0].text;
        assert!(b.starts_with("MODULE MOD_NOZZLE\n") && b.contains("  PROC NOZZLE()\n"));
        check_task(&[TASK_MAIN, a, b]).unwrap_or_else(|e| panic!("{file}: {e}"));
        let global = a.replace("  LOCAL ", "  ");
        let e = check_task(&[TASK_MAIN, &global]).unwrap_err();
        assert!(e.contains("tWaam"), "{e}");
        let old = a.replace("PROC HEMI()", "PROC main()");
        let e = check_task(&[TASK_MAIN, &old]).unwrap_err();
        assert!(e.contains("main"), "{e}");
        // a module named like its routine
        let same = a.replace("MODULE MOD_HEMI", "MODULE HEMI");
        assert!(check_task(&[TASK_MAIN, &same]).is_err());
    }
}

/// Names the entry routine cannot take are refused naming `name`: `main`
/// (the task's), one of the module's own (`p1` as `P1`, `jHome`), an
/// instruction it uses, the mechanical unit, a reserved word, and more
/// than 28 characters (`MOD_` + 28 = RAPID's 32).
#[test]
fn entry_names_that_would_clash_are_refused() {
    let (prog, _) = program(&cell(TORCH), 0..1, 8);
    for name in [
        "main",
        "MAIN",
        "P1",
        "j12",
        "JHOME",
        "tWaam",
        "weldWaam3",
        "MoveL",
        "ActUnit",
        "STN1",
        "MODULE",
        "A234567890123456789012345678X",
    ] {
        let mut p = prog.clone();
        p.name = name.into();
        let e = abb_files(&p, &AbbOptions::default()).unwrap_err();
        assert!(
            matches!(e, ProgramError::InvalidOptions { field: "name", .. }),
            "{name}: {e}"
        );
    }
    let mut p = prog.clone();
    p.name = "PART_2".into();
    assert!(abb_files(&p, &AbbOptions::default()).is_ok());
}

/// Issue 32: in the torch-carried cell `ActUnit STN1` comes before the
/// first motion (`MoveAbsJ`, `MoveL`, `Arc*`) and `DeactUnit STN1` after
/// the last; none in the part-carried cell. The decoder reports a missing
/// `ActUnit` at the first motion, a missing `DeactUnit` at the last, a
/// motion after `DeactUnit`, another unit (options) and a unit in a cell
/// without a positioner.
#[test]
fn positioner_unit_is_active_for_every_motion() {
    let is_motion = |l: &str| {
        let l = l.trim_start();
        l.starts_with("Move") || l.starts_with("Arc")
    };
    let c = cell(TORCH);
    let (prog, _) = program(&c, 0..2, 8);
    let plan = planned(&prog);
    let mut opts = AbbOptions::default();
    let mut with_home = prog.clone();
    with_home.home = Some(HomePosition {
        joints: prog.points[0].joints,
        positioner: prog.points[0].positioner,
    });
    opts.common.home_deg = Some(prog.points[0].joints.map(f64::to_degrees));
    opts.common.home_positioner_deg = prog.points[0].positioner.map(|q| q.map(f64::to_degrees));
    let text = &abb_files(&with_home, &opts).unwrap()[0].text;
    let lines: Vec<&str> = text.lines().collect();
    let act = line_of(text, "    ActUnit STN1;");
    let deact = line_of(text, "    DeactUnit STN1;");
    let first = lines.iter().position(|l| is_motion(l)).unwrap() + 1;
    let last = lines.iter().rposition(|l| is_motion(l)).unwrap() + 1;
    assert!(lines[first - 1].contains("MoveAbsJ jHome"), "{text}");
    assert!(line_of(text, "PROC HEMI()") < act && act < first, "{text}");
    assert!(last < deact && lines[deact].trim() == "ENDPROC", "{text}");
    let r = check(text, &c, &opts, &plan);
    assert!(r.is_ok(), "{r}");
    let drop = |n: usize| -> String {
        lines
            .iter()
            .enumerate()
            .filter(|(k, _)| k + 1 != n)
            .map(|(_, l)| format!("{l}\n"))
            .collect()
    };
    // without ActUnit: the first motion (one line up)
    let r = check(&drop(act), &c, &opts, &plan);
    assert!(
        has(&r, ProblemKind::Setup, first - 1, "before ActUnit STN1"),
        "{r}"
    );
    // without DeactUnit: the last motion
    let r = check(&drop(deact), &c, &opts, &plan);
    assert!(
        has(&r, ProblemKind::Setup, last, "no DeactUnit STN1"),
        "{r}"
    );
    // DeactUnit before the last (home) move
    let mut early: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    early.swap(last - 1, deact - 1);
    let r = check(&(early.join("\n") + "\n"), &c, &opts, &plan);
    assert!(
        has(&r, ProblemKind::Setup, deact, "after DeactUnit STN1"),
        "{r}"
    );
    let other = text.replace("ActUnit STN1;", "ActUnit STN2;");
    let r = check(&other, &c, &opts, &plan);
    assert!(has(&r, ProblemKind::Options, act, "ActUnit STN2"), "{r}");
    // the part-carried cell: no unit to activate
    let (part_prog, _) = program(&cell(PART), 0..2, 8);
    let part = &abb_files(&part_prog, &AbbOptions::default()).unwrap()[0].text;
    assert!(
        !part.contains("ActUnit") && !part.contains("DeactUnit"),
        "{part}"
    );
    let conf = line_of(part, "ConfL \\On;");
    let with_unit = part.replacen(
        "    ConfL \\On;\n",
        "    ActUnit STN1;\n    ConfL \\On;\n",
        1,
    );
    let r = check(
        &with_unit,
        &cell(PART),
        &AbbOptions::default(),
        &planned(&part_prog),
    );
    assert!(
        has(&r, ProblemKind::Instruction, conf, "no positioner"),
        "{r}"
    );
}

/// Issue 32: the gas times are written into `seamdata` from the options
/// (components 1, 2 and 16, to the ms), read back, and checked against the
/// options by the decoder, naming the option; a negative time is refused
/// naming its field.
#[test]
fn gas_times_are_written_from_the_options() {
    let (prog, _) = program(&cell(PART), 0..2, 8);
    let plan = planned(&prog);
    let d = &abb_files(&prog, &AbbOptions::default()).unwrap()[0].text;
    assert!(
        d.contains("  LOCAL PERS seamdata seamWaam := [0.500,0.300,[1,0,0,0,0,0,0,0,0],0,0,0,0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],1.500];\n"),
        "{d}"
    );
    let opts = AbbOptions {
        purge_time_s: 0.0,
        preflow_time_s: 0.45,
        postflow_time_s: 2.0,
        ..Default::default()
    };
    let text = &abb_files(&prog, &opts).unwrap()[0].text;
    let m = parse_mod(text, "HEMI.mod").unwrap();
    assert_eq!(m.seams.len(), 1);
    let s = &m.seams[0];
    assert_eq!(
        (s.purge_time_s, s.preflow_time_s, s.postflow_time_s),
        (0.0, 0.45, 2.0)
    );
    assert!(check(text, &cell(PART), &opts, &plan).is_ok());
    // read with the default options: all three differ, named
    let r = check(text, &cell(PART), &AbbOptions::default(), &plan);
    let l = line_of(text, "seamdata seamWaam");
    for field in [
        "purge_time_s = 0.5",
        "preflow_time_s = 0.3",
        "postflow_time_s = 1.5",
    ] {
        assert!(has(&r, ProblemKind::Options, l, field), "{field}: {r}");
    }
    for (o, field) in [
        (
            AbbOptions {
                purge_time_s: -0.5,
                ..Default::default()
            },
            "`purge_time_s`",
        ),
        (
            AbbOptions {
                preflow_time_s: -1e-9,
                ..Default::default()
            },
            "`preflow_time_s`",
        ),
        (
            AbbOptions {
                postflow_time_s: -2.0,
                ..Default::default()
            },
            "`postflow_time_s`",
        ),
    ] {
        let e = abb_files(&prog, &o).unwrap_err();
        assert!(
            matches!(e, ProgramError::InvalidOptions { .. }) && e.to_string().contains(field),
            "{e}"
        );
    }
}

/// Issue 32: the decoder reports, at its line, a declaration whose `LOCAL`
/// was removed (tool, target, seamdata), a global routine that is not the
/// entry routine, an entry routine named `main` or not after the program,
/// a module not named `MOD_<program>`, and a module without a global
/// routine.
#[test]
fn a_removed_local_is_reported_by_the_decoder() {
    let (prog, opts) = setup_program();
    let text = &abb_files(&prog, &opts).unwrap()[0].text;
    let c = cell(PART);
    let plan = planned(&prog);
    assert!(check(text, &c, &opts, &plan).is_ok());
    for needle in [
        "LOCAL PERS tooldata tWaam",
        "LOCAL CONST robtarget p5 ",
        "LOCAL PERS seamdata seamWaam",
        "LOCAL CONST jointtarget jHome",
    ] {
        let l = line_of(text, needle);
        let bad = text.replacen(needle, &needle["LOCAL ".len()..], 1);
        let r = check(&bad, &c, &opts, &plan);
        let name = needle.split_whitespace().nth(3).unwrap();
        assert!(
            has(
                &r,
                ProblemKind::Declaration,
                l,
                &format!("{name} is not LOCAL")
            ),
            "{needle}: {r}"
        );
        assert_eq!(r.problems.len(), 1, "{r}");
    }
    let proc_line = line_of(text, "  PROC HEMI()");
    let r = check(
        &text.replace("PROC HEMI()", "PROC main()"),
        &c,
        &opts,
        &plan,
    );
    assert!(has(&r, ProblemKind::Declaration, proc_line, "main"), "{r}");
    let r = check(
        &text.replace("PROC HEMI()", "PROC PART2()"),
        &c,
        &opts,
        &plan,
    );
    assert!(
        has(
            &r,
            ProblemKind::Declaration,
            proc_line,
            "not named after the module's program HEMI"
        ),
        "{r}"
    );
    let r = check(
        &text.replace("MODULE MOD_HEMI", "MODULE HEMI"),
        &c,
        &opts,
        &plan,
    );
    assert!(has(&r, ProblemKind::Declaration, 1, "MOD_<program>"), "{r}");
    let r = check(
        &text.replace("PROC HEMI()", "LOCAL PROC HEMI()"),
        &c,
        &opts,
        &plan,
    );
    assert!(
        has(&r, ProblemKind::Declaration, 1, "no global routine"),
        "{r}"
    );
    let extra = text.replace(
        "ENDMODULE",
        "  PROC helper()\n    WaitTime 1.000;\n  ENDPROC\nENDMODULE",
    );
    let l = line_of(&extra, "PROC helper()");
    let r = check(&extra, &c, &opts, &plan);
    assert!(
        has(
            &r,
            ProblemKind::Declaration,
            l,
            "global PROC helper: the module holds one routine"
        ),
        "{r}"
    );
    // LOCAL is refused inside a routine (module level only)
    let e = parse_mod(
        &text.replace(
            "    ConfL \\On;",
            "    LOCAL VAR num k := 1;\n    ConfL \\On;",
        ),
        "HEMI.mod",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("module level only"), "{e}");
}
