//! The declarations of an ABB module as read: its names and scope (one
//! global entry routine named after the program, every data `LOCAL`), the
//! `seamdata` gas times against the options, and every identifier a
//! motion or instruction uses declared with its type (or predefined).

use crate::program::abb::read::{RapidFrame, RapidModule, ToolArg};
use crate::program::abb::{AbbOptions, PREDEFINED_ZONES_MM};
use crate::program::validate::{push, ProblemKind, ValidationReport};

/// The module's names (pushed as [`ProblemKind::Declaration`] problems at
/// their line): `MODULE MOD_<program>`; one routine, the entry routine,
/// global and named `<program>` (never `main`, the task's own); every data
/// declaration `LOCAL`, so that nothing in the module clashes with a global
/// of the task it is loaded into (RAPID reference, "Basic Characteristics",
/// §3.1 and §5.1: a `LOCAL` name hides a global one). Names are compared
/// without case, as RAPID does.
pub(super) fn check_scope(module: &RapidModule, report: &mut ValidationReport) {
    use crate::program::abb::MODULE_PREFIX;
    let file = &module.file;
    let program = module
        .name
        .strip_prefix(MODULE_PREFIX)
        .filter(|p| !p.is_empty());
    if program.is_none() {
        push(
            report,
            ProblemKind::Declaration,
            file,
            module.line,
            format!(
                "MODULE {}: expected MODULE {MODULE_PREFIX}<program> (the entry routine takes the program's name, which its module cannot share)",
                module.name
            ),
        );
    }
    let entry = module.routines.iter().position(|r| !r.local);
    match entry.map(|k| &module.routines[k]) {
        None => push(
            report,
            ProblemKind::Declaration,
            file,
            module.line,
            format!(
                "no global routine: the entry routine {} must be global (the task's main calls it)",
                program.unwrap_or("<program>")
            ),
        ),
        Some(r) if r.name.eq_ignore_ascii_case("main") => push(
            report,
            ProblemKind::Declaration,
            file,
            r.line,
            format!(
                "PROC {}: clashes with the task's own main; the entry routine is named after the program ({})",
                r.name,
                program.unwrap_or("<program>")
            ),
        ),
        Some(r) => {
            if let Some(p) = program.filter(|p| !r.name.eq_ignore_ascii_case(p)) {
                push(
                    report,
                    ProblemKind::Declaration,
                    file,
                    r.line,
                    format!(
                        "entry routine {} is not named after the module's program {p} (MODULE {})",
                        r.name, module.name
                    ),
                );
            }
        }
    }
    // without a global routine the first one stands for the entry routine
    let first = entry.or((!module.routines.is_empty()).then_some(0));
    for (k, r) in module.routines.iter().enumerate() {
        if Some(k) == first {
            continue;
        }
        let scope = if r.local { "LOCAL PROC" } else { "global PROC" };
        push(
            report,
            ProblemKind::Declaration,
            file,
            r.line,
            format!(
                "{scope} {}: the module holds one routine, its entry routine{}",
                r.name,
                first.map_or(String::new(), |e| format!(
                    " {} (line {})",
                    module.routines[e].name, module.routines[e].line
                ))
            ),
        );
    }
    for d in &module.declarations {
        if d.scope.as_deref() != Some("LOCAL") {
            let scope = d
                .scope
                .as_deref()
                .map_or(String::new(), |s| format!("{s} "));
            push(
                report,
                ProblemKind::Declaration,
                file,
                d.line,
                format!(
                    "{scope}{} {} {} is not LOCAL: a global would clash with the task's own {} (only the entry routine is global)",
                    d.storage, d.ty, d.name, d.name
                ),
            );
        }
    }
}

/// The `seamdata` gas times against [`AbbOptions::purge_time_s`],
/// [`AbbOptions::preflow_time_s`] and [`AbbOptions::postflow_time_s`]
/// (written to the ms): an [`ProblemKind::Options`] problem at the
/// declaration for each that differs.
pub(super) fn check_gas_times(
    module: &RapidModule,
    opts: &AbbOptions,
    report: &mut ValidationReport,
) {
    for s in &module.seams {
        for (component, read, field, want) in [
            (
                "purge_time",
                s.purge_time_s,
                "purge_time_s",
                opts.purge_time_s,
            ),
            (
                "preflow_time",
                s.preflow_time_s,
                "preflow_time_s",
                opts.preflow_time_s,
            ),
            (
                "postflow_time",
                s.postflow_time_s,
                "postflow_time_s",
                opts.postflow_time_s,
            ),
        ] {
            // written with 3 decimals
            if !((read - want).abs() <= 5e-4 + 1e-9) {
                push(
                    report,
                    ProblemKind::Options,
                    &module.file,
                    s.line,
                    format!(
                        "{}: {component} {read} s, the options give {field} = {want} s",
                        s.name
                    ),
                );
            }
        }
    }
}

/// The module's declarations by name.
pub(super) type Decls<'a> =
    std::collections::HashMap<&'a str, &'a crate::program::abb::read::RapidDecl>;

/// Pushes a Declaration problem unless `name` is declared with type `ty`
/// (or `predefined`); `true` when it is.
pub(super) fn check_declared(
    module: &RapidModule,
    decls: &Decls,
    name: &str,
    ty: &str,
    predefined: bool,
    line: usize,
    report: &mut ValidationReport,
) -> bool {
    if predefined {
        return true;
    }
    match decls.get(name) {
        Some(d) if d.ty == ty => true,
        Some(d) => {
            push(
                report,
                ProblemKind::Declaration,
                &module.file,
                line,
                format!("{name} is a {} (line {}), not a {ty}", d.ty, d.line),
            );
            false
        }
        None => {
            push(
                report,
                ProblemKind::Declaration,
                &module.file,
                line,
                format!("{ty} {name} is not declared in the module"),
            );
            false
        }
    }
}

/// Checks a motion's zone, tool and work object identifiers.
pub(super) fn check_motion_args(
    module: &RapidModule,
    decls: &Decls,
    zone: &str,
    tool: &ToolArg,
    line: usize,
    report: &mut ValidationReport,
) {
    let predefined_zone = zone == "fine"
        || zone
            .strip_prefix('z')
            .and_then(|n| n.parse::<u32>().ok())
            .is_some_and(|n| PREDEFINED_ZONES_MM.contains(&n));
    check_declared(
        module,
        decls,
        zone,
        "zonedata",
        predefined_zone,
        line,
        report,
    );
    check_declared(module, decls, &tool.tool, "tooldata", false, line, report);
    let frame_of = |f: &Option<RapidFrame>| f.as_ref().map(|f| f.name.clone());
    if frame_of(&module.tool).as_deref() != Some(tool.tool.as_str())
        && decls.contains_key(tool.tool.as_str())
    {
        push(
            report,
            ProblemKind::Frame,
            &module.file,
            line,
            format!("tool {} is not the module's tool", tool.tool),
        );
    }
    match &tool.wobj {
        Some(w) => {
            check_declared(module, decls, w, "wobjdata", false, line, report);
        }
        None => push(
            report,
            ProblemKind::Frame,
            &module.file,
            line,
            "motion without \\WObj: the controller would use wobj0, not the module's work object"
                .into(),
        ),
    }
}
