//! Stage 7, the program stage's errors: [`ProgramError`] names the point,
//! field or file at fault; [`LayerRefusal`] says why a layer was refused.

/// Errors of the program stage; each names the point, field or file at fault.
/// `Clone` (an I/O error is shared), so that a plan can keep the program
/// stage's refusal as a value ([`PlannedPart::program`](crate::pipeline::PlannedPart::program)).
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum ProgramError {
    /// The plan has violations: no program is written for it.
    #[error(
        "refusing to write a program for an infeasible plan: {count} violation(s), first: {first}"
    )]
    Infeasible {
        /// Number of violations.
        count: usize,
        /// The first one, with its layer, point and joint.
        first: String,
        /// The layers the first one concerns (its own, and the next layer's
        /// for an arc-off move into it), so that a host (the placement
        /// search) reads them without parsing `first`.
        layers: Vec<usize>,
    },
    /// A layer of the plan is infeasible or has lost points: no program is
    /// written, so that no layer can silently vanish from it.
    #[error("refusing to write a program: layer {layer} cannot be built ({status}); {count} layer(s) in all")]
    InfeasibleLayer {
        /// The first such layer.
        layer: usize,
        /// How many layers are in that state.
        count: usize,
        /// Why it cannot be built.
        status: LayerRefusal,
    },
    /// The joint trajectory rebuilt from a plan fails (a point the plan
    /// solved no longer has a joint solution): the robot stage's error.
    #[error("joint trajectory: {source}")]
    Trajectory {
        /// The robot stage's error (names the point).
        #[source]
        source: crate::robot::RobotError,
    },
    /// Path points, trajectory and speeds do not describe the same path.
    #[error("input mismatch at index {index}: {reason}")]
    Mismatch {
        /// Index in the point list.
        index: usize,
        /// What differs.
        reason: String,
    },
    /// An option is out of its domain.
    #[error("program options: `{field}` = {value:?} is invalid ({reason})")]
    InvalidOptions {
        /// The field at fault.
        field: &'static str,
        /// The offending value.
        value: String,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// One layer's bead alone does not fit the controller's memory budget:
    /// a build is cut between beads only ([`split`](crate::program::split)), never inside one.
    #[error(
        "layer {layer} alone needs {size} {unit} in one program, more than `{field}` = {limit}: raise `{field}` if the controller holds more, or coarsen the layer (path_tolerance_mm, fewer points)"
    )]
    OverBudget {
        /// The cell-file key stating the budget, e.g. `[program.fanuc] max_positions`.
        field: &'static str,
        /// The budget, in `unit`.
        limit: usize,
        /// What is counted (`positions`, `bytes`).
        unit: &'static str,
        /// The layer whose bead does not fit.
        layer: usize,
        /// What its group alone needs, in `unit`.
        size: usize,
    },
    /// Two bodies of the cell come closer than `[program]
    /// collision_clearance_mm` along a motion ([`cell_check`](crate::program::cell_check)).
    #[error(
        "layer {layer}{}, {motion}: the {body_a} and the {body_b} come {} (clearance {clearance_mm} mm)",
        point.map_or(String::new(), |p| format!(", point {p}")),
        if *distance_mm < 0.0 { format!("{:.1} mm into each other", -distance_mm) } else { format!("within {distance_mm:.1} mm") }
    )]
    Collision {
        /// The layer the motion belongs to.
        layer: usize,
        /// The point (bead point, or the point a move goes to); `None` for
        /// a home move.
        point: Option<usize>,
        /// The motion: `bead`, `approach`, `retract`, `arc-off transit`,
        /// `home move`.
        motion: &'static str,
        /// One body (an arm link, `part`).
        body_a: String,
        /// The other (an arm link, the positioner's table or tilt body, a
        /// keep-out box by its name, `part`).
        body_b: String,
        /// Their distance (mm; negative: the penetration depth).
        distance_mm: f64,
        /// The clearance asked for (mm).
        clearance_mm: f64,
    },
    /// A file could not be written.
    #[error("{path}: cannot write: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error (shared: the error is `Clone`).
        source: std::sync::Arc<std::io::Error>,
    },
    /// The program's robot is another vendor's than the emitter's: its joints
    /// are in that vendor's controller convention and its Cartesian poses
    /// use that vendor's flange axes, meaningless on this controller.
    #[error(
        "the {emitter} emitter writes {emitter_vendor} programs, but the cell's robot `{robot}` has vendor {robot_vendor} (its joints are in the {robot_vendor} controller's convention): use the {robot_vendor} format"
    )]
    VendorMismatch {
        /// The emitter or validator, e.g. `KUKA KRL`.
        emitter: &'static str,
        /// The emitter's vendor.
        emitter_vendor: &'static str,
        /// The cell's robot (its name).
        robot: String,
        /// The robot's vendor.
        robot_vendor: &'static str,
    },
    /// A program file could not be read back.
    #[error("{file}:{line}: {reason}")]
    Read {
        /// The file (or program name).
        file: String,
        /// Line number, 1-based.
        line: usize,
        /// What is wrong.
        reason: String,
    },
}

/// Why a layer of a plan cannot be built ([`ProgramError::InfeasibleLayer`]).
#[derive(Debug, Clone, PartialEq)]
pub enum LayerRefusal {
    /// The optimiser left the layer infeasible: its status names the
    /// binding constraint (joint, point, amount).
    Infeasible(crate::optimise::LayerStatus),
    /// The plan has no entry for the layer (a host dropped it, or the
    /// optimiser returned none).
    NoPlan,
    /// The plan's entry for the layer has another number of points, or is
    /// another layer's.
    PointCount {
        /// Points in the plan's entry.
        planned: usize,
        /// Points of the path's layer.
        path: usize,
        /// The layer the plan's entry is for.
        plan_layer: usize,
    },
    /// A point of the layer has no joint solution in the plan.
    NoJointSolution {
        /// The point's index in the layer.
        point: usize,
    },
}

impl std::fmt::Display for LayerRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LayerRefusal::Infeasible(status) => write!(f, "{status}"),
            LayerRefusal::NoPlan => write!(f, "no plan for this layer"),
            LayerRefusal::PointCount {
                planned,
                path,
                plan_layer,
            } => write!(
                f,
                "the plan has {planned} point(s) for its {path} (layer {plan_layer})"
            ),
            LayerRefusal::NoJointSolution { point } => {
                write!(f, "point {point} has no joint solution")
            }
        }
    }
}

impl ProgramError {
    /// The layers (their [`LayerPoints::layer`](crate::optimise::LayerPoints::layer)
    /// numbers) the error names, from its typed fields: the first infeasible
    /// layer, or the layers of a program check's refusal (a violation's
    /// layer, an arc-off move's two layers); empty for errors about no
    /// layer. The placement search brings them into its subsample.
    pub fn layers(&self) -> Vec<usize> {
        match self {
            ProgramError::InfeasibleLayer { layer, .. } => vec![*layer],
            ProgramError::Infeasible { layers, .. } => layers.clone(),
            ProgramError::Collision { layer, .. } => vec![*layer],
            _ => Vec::new(),
        }
    }
}
