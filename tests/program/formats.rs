//! KUKA and ABB: our programs read back and validate in every cell; files
//! we corrupt (a joint pushed out of range, a dropped arc end, a truncated
//! file, a configuration flip) are rejected with a message naming the line.

use waam_slicer::program::abb::read::parse_mod;
use waam_slicer::program::abb::validate_abb;
use waam_slicer::program::abb::{abb_files, AbbOptions};
use waam_slicer::program::fanuc::parse_ls;
use waam_slicer::program::fanuc::validate_fanuc;
use waam_slicer::program::fanuc::{fanuc_files, FanucOptions};
use waam_slicer::program::kuka::read::parse_krl;
use waam_slicer::program::kuka::validate_kuka;
use waam_slicer::program::kuka::{kuka_files, KukaOptions};
use waam_slicer::program::validate::ValidationReport;
use waam_slicer::program::PositionMode;
use waam_slicer::program::{EmittedFile, Program, ProgramError};
use waam_slicer::robot::CellLayout;

use crate::fixture::{cell, part_carried, program, ABB_CELLS, KUKA_CELLS};

fn kuka_part_carried() -> CellLayout {
    cell("kuka_kr16_2_part_carried.toml")
}

fn abb_part_carried() -> CellLayout {
    cell("abb_irb2600_part_carried.toml")
}

fn hemi(cell: &CellLayout) -> (Program, Vec<waam_slicer::program::PlannedPoint>) {
    let (prog, _) = program(cell, 0..4, 24);
    let planned = prog.planned.clone();
    (prog, planned)
}

fn line_of(text: &str, needle: &str, after: usize) -> usize {
    text.lines()
        .enumerate()
        .skip(after)
        .find(|(_, l)| l.contains(needle))
        .map(|(i, _)| i + 1)
        .unwrap_or_else(|| panic!("`{needle}` not found"))
}

fn edit(text: &str, line: usize, f: impl Fn(&str) -> String) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { f(l) } else { l.to_string() })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

fn kuka_check(
    files: &[EmittedFile],
    src: &str,
    dat: &str,
    cell: &CellLayout,
    opts: &KukaOptions,
    planned: &[waam_slicer::program::PlannedPoint],
) -> ValidationReport {
    let p = parse_krl(src, &files[0].name, dat, &files[1].name).unwrap_or_else(|e| panic!("{e}"));
    validate_kuka(&p, cell, opts, Some(planned))
}

fn abb_check(
    text: &str,
    cell: &CellLayout,
    planned: &[waam_slicer::program::PlannedPoint],
) -> ValidationReport {
    let m = parse_mod(text, "HEMI.mod").unwrap_or_else(|e| panic!("{e}"));
    validate_abb(&m, cell, &AbbOptions::default(), Some(planned))
}

#[test]
fn kuka_and_abb_programs_read_back_and_validate_in_their_cells() {
    for file in KUKA_CELLS {
        let c = cell(file);
        let (prog, planned) = hemi(&c);
        for positions in [PositionMode::Joint, PositionMode::Cartesian] {
            let opts = KukaOptions {
                positions,
                ..Default::default()
            };
            let f = kuka_files(&prog, &opts).unwrap();
            let r = kuka_check(&f, &f[0].text, &f[1].text, &c, &opts, &planned);
            assert!(r.is_ok(), "{file} KUKA {positions:?}:\n{r}");
            assert_eq!((r.motions, r.beads), (96 + 8, 4));
        }
    }
    for file in ABB_CELLS {
        let c = cell(file);
        let (prog, planned) = hemi(&c);
        let f = abb_files(&prog, &AbbOptions::default()).unwrap();
        let r = abb_check(&f[0].text, &c, &planned);
        assert!(r.is_ok(), "{file} ABB:\n{r}");
        assert_eq!((r.motions, r.beads), (96 + 8, 4));
    }
}

/// A program's joints are in its robot's controller convention: written by
/// another vendor's emitter they would be meaningless (FANUC J2/J3 values as
/// KUKA A2/A3). Every emitter and validator refuses another vendor's robot,
/// naming both.
#[test]
fn emitters_and_validators_refuse_another_vendors_robot() {
    let (fanuc_prog, _) = program(&part_carried(), 0..1, 8);
    let (kuka_prog, _) = program(&kuka_part_carried(), 0..1, 8);
    let (abb_prog, _) = program(&abb_part_carried(), 0..1, 8);
    let mismatch = |e: ProgramError, emitter: &str, robot_vendor: &str| {
        let msg = e.to_string();
        assert!(
            matches!(e, ProgramError::VendorMismatch { .. })
                && msg.contains(emitter)
                && msg.contains(&format!("has vendor {robot_vendor} ")),
            "{msg}"
        );
    };
    for (result, emitter, robot_vendor) in [
        (
            kuka_files(&fanuc_prog, &KukaOptions::default()),
            "KUKA KRL",
            "FANUC",
        ),
        (
            abb_files(&fanuc_prog, &AbbOptions::default()),
            "ABB RAPID",
            "FANUC",
        ),
        (
            fanuc_files(&kuka_prog, &FanucOptions::default()),
            "FANUC TP",
            "KUKA",
        ),
        (
            abb_files(&kuka_prog, &AbbOptions::default()),
            "ABB RAPID",
            "KUKA",
        ),
        (
            kuka_files(&abb_prog, &KukaOptions::default()),
            "KUKA KRL",
            "ABB",
        ),
    ] {
        mismatch(result.unwrap_err(), emitter, robot_vendor);
    }
    // the writers themselves refuse too
    let mut sink = Vec::new();
    assert!(
        waam_slicer::program::kuka::write_dat(&mut sink, &fanuc_prog, &KukaOptions::default())
            .is_err()
    );
    assert!(
        waam_slicer::program::abb::write_mod(&mut sink, &kuka_prog, &AbbOptions::default())
            .is_err()
    );
    // validators: a right program checked against another vendor's cell
    let k = kuka_files(&kuka_prog, &KukaOptions::default()).unwrap();
    let krl = parse_krl(&k[0].text, &k[0].name, &k[1].text, &k[1].name).unwrap();
    let r = validate_kuka(&krl, &part_carried(), &KukaOptions::default(), None);
    assert_eq!(r.problems.len(), 1, "{r}");
    assert!(
        r.problems[0].line == 1 && r.problems[0].message.contains("has vendor FANUC "),
        "{r}"
    );
    let a = abb_files(&abb_prog, &AbbOptions::default()).unwrap();
    let m = parse_mod(&a[0].text, &a[0].name).unwrap();
    let r = validate_abb(&m, &kuka_part_carried(), &AbbOptions::default(), None);
    assert!(r.problems[0].message.contains("has vendor KUKA "), "{r}");
    let f = fanuc_files(&fanuc_prog, &FanucOptions::default()).unwrap();
    let tp = parse_ls(&f[0].text, &f[0].name).unwrap();
    let r = validate_fanuc(&[tp], &abb_part_carried(), &FanucOptions::default(), None);
    assert!(r.problems[0].message.contains("has vendor ABB "), "{r}");
}

/// With joint positions only PTP targets are E6AXIS: every LIN target is an
/// E6POS with S and T; a LIN to an E6AXIS is named by the validator.
#[test]
fn kuka_lin_targets_are_e6pos_even_with_joint_positions() {
    for file in KUKA_CELLS {
        let c = cell(file);
        let (prog, planned) = hemi(&c);
        let opts = KukaOptions::default();
        let f = kuka_files(&prog, &opts).unwrap();
        let (src, dat) = (&f[0].text, &f[1].text);
        let mut lin = 0;
        for l in src.lines().map(str::trim) {
            let (lin_move, target) = match l.split_whitespace().collect::<Vec<_>>()[..] {
                ["LIN", t, ..] => (true, t),
                ["PTP", t] => (false, t),
                _ => continue,
            };
            lin += lin_move as usize;
            let decl = dat
                .lines()
                .find(|d| d.contains(&format!(" {target}=")))
                .unwrap();
            let want = if lin_move {
                "DECL E6POS "
            } else {
                "DECL E6AXIS "
            };
            assert!(decl.trim_start().starts_with(want), "{file}: {l}: {decl}");
        }
        assert_eq!(
            lin,
            96 + 4,
            "{file}: 92 bead LINs, 4 into and 4 out of beads"
        );
        // P3 (a bead point, LIN) replaced by the E6AXIS of P2's joints
        let p2 = prog.points[1].joints.map(f64::to_degrees);
        let l = line_of(dat, "DECL E6POS P3=", 0);
        let bad = edit(dat, l, |_| {
            format!(
                "  DECL E6AXIS P3={{A1 {},A2 {},A3 {},A4 {},A5 {},A6 {},E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}}",
                p2[0], p2[1], p2[2], p2[3], p2[4], p2[5]
            )
        });
        let r = kuka_check(&f, src, &bad, &c, &opts, &planned);
        assert!(
            r.problems
                .iter()
                .any(|p| p.message.contains("LIN to P3, an E6AXIS")),
            "{file}: {r}"
        );
    }
}

/// KRL names have at most 24 characters: a 25-character name (which FANUC
/// and ABB accept) is refused by the KUKA emitter, naming the field.
#[test]
fn kuka_refuses_names_over_24_characters() {
    let (mut prog, _) = program(&kuka_part_carried(), 0..1, 8);
    prog.name = "A".repeat(24);
    assert!(kuka_files(&prog, &KukaOptions::default()).is_ok());
    prog.name = "A".repeat(25);
    let e = kuka_files(&prog, &KukaOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("`name`") && e.contains("24 characters"), "{e}");
}

/// KUKA: the INI fold declares the stop-message interrupt, and tool and base
/// are selected with BAS (which sets the load too); the validator reads BAS
/// and compares the numbers with the options.
#[test]
fn kuka_ini_fold_interrupt_and_bas_tool_base() {
    let c = kuka_part_carried();
    let (prog, planned) = hemi(&c);
    let opts = KukaOptions {
        tool: 3,
        base: 2,
        ..Default::default()
    };
    let f = kuka_files(&prog, &opts).unwrap();
    let src = &f[0].text;
    let ini: Vec<&str> = src
        .lines()
        .skip_while(|l| !l.contains(";FOLD INI"))
        .take_while(|l| !l.contains(";ENDFOLD"))
        .map(str::trim)
        .collect();
    assert_eq!(
        ini[1..],
        [
            "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
            "INTERRUPT ON 3",
            "BAS (#INITMOV,0 )"
        ]
    );
    assert!(
        src.contains("\n  BAS (#TOOL,3)\n  BAS (#BASE,2)\n"),
        "{src}"
    );
    // BAS selects the numbers (and the load); the frames the positions
    // assume are then stated
    assert!(src.contains("\n  $TOOL = {X ") && src.contains("\n  $BASE = {X "));
    let r = kuka_check(&f, src, &f[1].text, &c, &opts, &planned);
    assert!(r.is_ok(), "{r}");
    let other = KukaOptions {
        tool: 1,
        ..opts.clone()
    };
    let r = kuka_check(&f, src, &f[1].text, &c, &other, &planned);
    assert!(
        r.problems
            .iter()
            .any(|p| p.message.contains("TOOL_DATA[3], the options give 1")),
        "{r}"
    );
}

/// ABB: the positioner's external axes are configurable (`eax_c`, `eax_d`
/// here); the validator reads them from the same slots.
#[test]
fn abb_positioner_axes_are_configurable() {
    let c = cell("abb_irb2600_torch_carried.toml");
    let (prog, planned) = hemi(&c);
    let opts = AbbOptions {
        positioner_axes: ['c', 'd'],
        ..Default::default()
    };
    let text = &abb_files(&prog, &opts).unwrap()[0].text;
    let p13 = text
        .lines()
        .find(|l| l.contains("CONST robtarget p13 :="))
        .unwrap();
    let ext = &p13[p13.rfind(",[").unwrap() + 1..];
    assert!(
        ext.starts_with("[9E+09,9E+09,") && ext.matches("9E+09").count() == 4,
        "{p13}"
    );
    let m = parse_mod(text, "HEMI.mod").unwrap();
    let r = validate_abb(&m, &c, &opts, Some(&planned));
    assert!(r.is_ok(), "{r}");
    let bad = AbbOptions {
        positioner_axes: ['a', 'a'],
        ..Default::default()
    };
    let e = abb_files(&prog, &bad).unwrap_err().to_string();
    assert!(e.contains("`positioner_axes`"), "{e}");
}

#[test]
fn kuka_corruptions_are_named_by_their_line() {
    let c = kuka_part_carried();
    let (prog, planned) = hemi(&c);
    let opts = KukaOptions::default();
    let f = kuka_files(&prog, &opts).unwrap();
    let (src, dat) = (&f[0].text, &f[1].text);
    // a joint pushed out of range (J5 travel ±130°) in the approach point
    // (a PTP target: E6AXIS)
    let l = line_of(dat, "DECL E6AXIS P1=", 0);
    let bad = edit(dat, l, |s| {
        let a = s.find("A5 ").unwrap();
        let b = a + s[a..].find(',').unwrap();
        format!("{}A5 170.0{}", &s[..a], &s[b..])
    });
    let r = kuka_check(&f, src, &bad, &c, &opts, &planned);
    assert!(
        r.problems.iter().any(|p| p.file == "HEMI.dat"
            && p.line == l
            && p.message.contains("P1: J5 = 170.0000°")),
        "{r}"
    );
    // a dropped arc end: the next bead's start names it
    let exact = |needle: &str, after: usize| {
        src.lines()
            .enumerate()
            .skip(after)
            .find(|(_, l)| *l == needle)
            .map(|(i, _)| i + 1)
            .unwrap()
    };
    let end = exact("  $OUT[1]=FALSE", 0);
    // (the arc on is inside the ignition handshake's LOOP)
    let next_start = exact("    $OUT[1]=TRUE", end);
    let dropped: String = src
        .lines()
        .enumerate()
        .filter(|(i, _)| i + 1 != end)
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let r = kuka_check(&f, &dropped, dat, &c, &opts, &planned);
    assert!(
        r.problems
            .iter()
            .any(|p| p.line == next_start - 1 && p.message.contains("still on")),
        "{r}"
    );
    // truncated files
    for (text, name, word) in [(src, "HEMI.src", "END"), (dat, "HEMI.dat", "ENDDAT")] {
        let lines: Vec<&str> = text.lines().collect();
        let keep = lines.len() * 2 / 3;
        let cut = lines[..keep].join("\n") + "\n";
        let (s, d) = if name.ends_with("src") {
            (cut.as_str(), dat.as_str())
        } else {
            (src.as_str(), cut.as_str())
        };
        let e = parse_krl(s, "HEMI.src", d, "HEMI.dat")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("{name}:{keep}: ")) && e.contains(&format!("without {word}")),
            "{e}"
        );
    }
    // a configuration flip in an E6POS (Status bit 2: the sign of A5)
    let copts = KukaOptions {
        positions: PositionMode::Cartesian,
        ..Default::default()
    };
    let f = kuka_files(&prog, &copts).unwrap();
    let l = line_of(&f[1].text, "DECL E6POS P5=", 0);
    let flipped = edit(&f[1].text, l, |s| {
        let a = s.find(",S ").unwrap() + 3;
        let b = a + s[a..].find(',').unwrap();
        let v: u8 = s[a..b].parse().unwrap();
        format!("{}{}{}", &s[..a], v ^ 4, &s[b..])
    });
    let r = kuka_check(&f, &f[0].text, &flipped, &c, &copts, &planned);
    assert!(
        r.problems
            .iter()
            .any(|p| p.line == l && p.message.contains("configuration flip")),
        "{r}"
    );
}

#[test]
fn abb_corruptions_are_named_by_their_line() {
    let c = abb_part_carried();
    let (prog, planned) = hemi(&c);
    let text = &abb_files(&prog, &AbbOptions::default()).unwrap()[0].text;
    // a joint pushed out of range in the approach jointtarget
    let l = line_of(text, "CONST jointtarget j1 :=", 0);
    let bad = edit(text, l, |s| {
        let inner = s.find("[[").unwrap() + 2;
        let end = inner + s[inner..].find(']').unwrap();
        let mut v: Vec<String> = s[inner..end].split(',').map(String::from).collect();
        v[4] = "170.0".into();
        format!("{}{}{}", &s[..inner], v.join(","), &s[end..])
    });
    let r = abb_check(&bad, &c, &planned);
    assert!(
        r.problems
            .iter()
            .any(|p| p.line == l && p.message.contains("j1: J5 = 170.0000°")),
        "{r}"
    );
    // a dropped ArcLEnd (turned into ArcL): the next ArcLStart names it
    let end = line_of(text, "ArcLEnd ", 0);
    let next = line_of(text, "ArcLStart ", end);
    let dropped = edit(text, end, |s| {
        s.replace("ArcLEnd ", "ArcL ").replace(", fine,", ", z1,")
    });
    let r = abb_check(&dropped, &c, &planned);
    assert!(
        r.problems
            .iter()
            .any(|p| p.line == next && p.message.contains("still on")),
        "{r}"
    );
    // truncated
    let lines: Vec<&str> = text.lines().collect();
    let keep = lines.len() - 3;
    let cut = lines[..keep].join("\n") + "\n";
    let e = parse_mod(&cut, "HEMI.mod").unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("HEMI.mod:{keep}: ")) && e.contains("without ENDMODULE"),
        "{e}"
    );
    // a configuration flip: cfx with the other elbow
    let l = line_of(text, "CONST robtarget p5 :=", 0);
    let flipped = edit(text, l, |s| {
        let parts: Vec<&str> = s.split("],[").collect();
        // [..trans],[quat],[cf1,cf4,cf6,cfx],[ext]
        let conf: Vec<i32> = parts[2].split(',').map(|x| x.parse().unwrap()).collect();
        let new = format!("{},{},{},{}", conf[0], conf[1], conf[2], conf[3] ^ 2);
        s.replacen(parts[2], &new, 1)
    });
    let r = abb_check(&flipped, &c, &planned);
    assert!(
        r.problems
            .iter()
            .any(|p| p.line == l && p.message.contains("configuration flip")),
        "{r}"
    );
}

/// Without approach points a bead is reached by `MoveAbsJ` to its first
/// point; the `ArcLStart` that follows is a zero-length move and carries
/// no `\T` even where the positioner turned since the previous bead.
#[test]
fn abb_arc_start_after_moveabsj_is_not_timed() {
    use waam_slicer::program::{build_program_with, PointFeed, ProgramOptions};
    let c = cell("abb_irb2600_torch_carried.toml");
    let path = crate::fixture::hemisphere(0..3, 24, crate::fixture::law(&c));
    let tr = crate::fixture::trajectory(&c, &path);
    let prog = build_program_with(
        "HEMI",
        &c,
        &path,
        &tr,
        &PointFeed::constant(
            crate::fixture::TS_MM_S,
            crate::fixture::WFS_MM_S,
            path.len(),
        ),
        &ProgramOptions {
            clearance_mm: 0.0,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // the positioner tilts between the layers
    let e: Vec<f64> = prog
        .points
        .iter()
        .filter(|p| p.arc == waam_slicer::program::ArcFlag::Start)
        .map(|p| p.positioner.unwrap()[0])
        .collect();
    assert!((e[1] - e[0]).abs() > 1e-3, "{e:?}");
    let text = &abb_files(&prog, &AbbOptions::default()).unwrap()[0].text;
    let starts: Vec<&str> = text.lines().filter(|l| l.contains("ArcLStart")).collect();
    assert_eq!(starts.len(), 3, "{text}");
    for l in starts {
        assert!(!l.contains("\\T"), "{l}");
    }
    let planned = prog.planned.clone();
    let r = abb_check(text, &c, &planned);
    assert!(r.is_ok(), "{r}");
}
