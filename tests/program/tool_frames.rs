//! One tool convention in every program (issue 32 item 5): the torch's tool
//! frame has **+Z along the wire, out of the torch towards the part**, the
//! convention of welding-torch tool data (ABB "Application manual – Arc
//! and Arc Sensor": the tool's z axis points along the wire, "tool
//! direction" of the torch; KUKA ArcTech and FANUC ArcTool define the torch
//! TCP the same way, z out of the nozzle, so that tool-frame jogging,
//! offsets and weaving run the way the welder expects).
//!
//! The check does not trust our own frame code: the tool is parsed back from
//! the emitted text with each vendor's own orientation convention written
//! out here (ABB quaternion `[q1 q2 q3 q4]` = `w x y z`; KUKA `A B C` =
//! `Rz(A)·Ry(B)·Rx(C)`; FANUC `W P R` = `Rz(R)·Ry(P)·Rx(W)`), and at every
//! planned bead point the wire must point down into the part below the torch
//! (the build direction is within the cell's cone of the vertical, the
//! torch above the deposit) while the TCP stays where the planner put it.

use nalgebra::{Quaternion, Rotation3, UnitQuaternion, Vector3};
use waam_slicer::program::abb::{abb_files, AbbOptions};
use waam_slicer::program::fanuc::{fanuc_files, FanucOptions};
use waam_slicer::program::kuka::{kuka_files, KukaOptions};
use waam_slicer::program::Program;
use waam_slicer::robot::CellLayout;

use crate::fixture::{cell, program};

/// Numbers inside `line` (signed decimals), in order.
fn numbers(line: &str) -> Vec<f64> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for ch in line.chars().chain(std::iter::once(' ')) {
        if ch.is_ascii_digit() || ch == '.' || (ch == '-' && cur.is_empty()) {
            cur.push(ch);
        } else {
            if let Ok(v) = cur.parse::<f64>() {
                out.push(v);
            }
            cur.clear();
        }
    }
    out
}

fn line_with<'a>(text: &'a str, needle: &str) -> &'a str {
    text.lines()
        .find(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("no line with `{needle}` in\n{text}"))
}

fn rz_ry_rx(z_deg: f64, y_deg: f64, x_deg: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), z_deg.to_radians())
        * Rotation3::from_axis_angle(&Vector3::y_axis(), y_deg.to_radians())
        * Rotation3::from_axis_angle(&Vector3::x_axis(), x_deg.to_radians())
}

/// Asserts that the tool `(t, r)` (flange frame, mm) puts the wire down into
/// the part at every bead point of `prog`, with the TCP at the planner's.
fn wire_points_into_the_part(vendor: &str, prog: &Program, t: Vector3<f64>, r: Rotation3<f64>) {
    let CellLayout::TorchCarried(c) = &prog.cell else {
        panic!("a torch-carried cell")
    };
    // the planner's TCP (z into the torch) and the program's share the origin
    let planner = c.flange_from_tcp.translation.vector;
    assert!(
        (t - planner).norm() < 1e-3,
        "{vendor}: tool origin {t:?} is not the torch's TCP {planner:?}"
    );
    for p in &prog.points {
        let flange = c.robot.flange_pose(&p.joints);
        let wire = flange.rotation * (r * Vector3::z());
        assert!(
            wire.z < -0.5,
            "{vendor}: layer {} point {}: tool +Z {wire:?} does not point down into the part",
            p.layer,
            p.point
        );
        // the wire is the planner's tool axis reversed (T points into the torch)
        let t_axis = flange.rotation * (c.flange_from_tcp.rotation * Vector3::z());
        assert!((wire + t_axis).norm() < 1e-6, "{vendor}: tool +Z is not −T");
    }
}

fn torch_program(file: &str) -> Program {
    program(&cell(file), 0..2, 8).0
}

#[test]
fn abb_tool_z_is_the_wire_out_of_the_torch() {
    let prog = torch_program("abb_irb2600_torch_carried.toml");
    let text = &abb_files(&prog, &AbbOptions::default()).unwrap()[0].text;
    let v = numbers(line_with(text, "tooldata tWaam :="));
    // [robhold, [[x, y, z], [q1, q2, q3, q4]], ...]: robhold TRUE has no number
    let q = UnitQuaternion::from_quaternion(Quaternion::new(v[3], v[4], v[5], v[6]));
    wire_points_into_the_part(
        "ABB",
        &prog,
        Vector3::new(v[0], v[1], v[2]),
        q.to_rotation_matrix(),
    );
}

#[test]
fn kuka_tool_z_is_the_wire_out_of_the_torch() {
    let prog = torch_program("kuka_kr16_2_torch_carried.toml");
    let text = &kuka_files(&prog, &KukaOptions::default()).unwrap()[0].text;
    let v = numbers(line_with(text, "$TOOL = {"));
    wire_points_into_the_part(
        "KUKA",
        &prog,
        Vector3::new(v[0], v[1], v[2]),
        rz_ry_rx(v[3], v[4], v[5]),
    );
    assert!(
        text.contains("$TOOL_DIRECTION = #Z"),
        "the comment tells the cell how to jog"
    );
}

#[test]
fn fanuc_tool_z_is_the_wire_out_of_the_torch() {
    let prog = torch_program("robowam_torch_carried.toml");
    let text = &fanuc_files(&prog, &FanucOptions::default()).unwrap()[0].text;
    // `  7:  ! UT1 X,Y=-86.000,0.000 ;`: the values follow the `=`
    let after_eq = |needle: &str| {
        let line = line_with(text, needle);
        numbers(&line[line.find('=').expect("a remark with `=`")..])
    };
    let (xy, zw, pr) = (
        after_eq("! UT1 X,Y="),
        after_eq("! UT1 Z,W="),
        after_eq("! UT1 P,R="),
    );
    wire_points_into_the_part(
        "FANUC",
        &prog,
        Vector3::new(xy[0], xy[1], zw[0]),
        rz_ry_rx(pr[1], pr[0], zw[1]),
    );
}

/// The part-carried cells' fixed torch: +Z straight down at `D_R`.
#[test]
fn fixed_torch_z_points_down_into_the_part() {
    let c = cell("kuka_kr16_2_part_carried.toml");
    let prog = program(&c, 0..2, 8).0;
    let text = &kuka_files(&prog, &KukaOptions::default()).unwrap()[0].text;
    // external TCP: $BASE is the fixed torch
    let v = numbers(line_with(text, "$BASE = {"));
    let wire = rz_ry_rx(v[3], v[4], v[5]) * Vector3::z();
    assert!(
        (wire + Vector3::z()).norm() < 1e-9,
        "fixed torch +Z {wire:?}"
    );
}
