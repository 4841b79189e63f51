//! **The closed loop's errors** ([`ReplanError`], stage 9, re-exported by
//! [`crate::replan`]; they live with the crate's error so that [`crate::Error`]
//! wraps them without importing the room above it): a scan file
//! that cannot be read, a refused scan (another part, another layer, too
//! little coverage; the message names the distance), nothing left to
//! replan, a point that cannot be placed.

/// Errors of the closed loop; each names the file, row, layer or point. A
/// refused scan says which distance gave it away.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReplanError {
    /// The scan file cannot be read.
    #[error("scan {file}, line {line}: {reason}")]
    ScanFile {
        /// The file.
        file: String,
        /// 1-based line (0: the file as a whole).
        line: usize,
        /// What is wrong (names the column).
        reason: String,
    },
    /// An option is invalid.
    #[error("replan option `{field}`: {reason}")]
    InvalidOption {
        /// The option.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// No layer remains after the measured one.
    #[error("after layer {after_layer}: the plan has {layers} layers (0..{layers}), none remains to replan")]
    NothingToReplan {
        /// The measured layer.
        after_layer: usize,
        /// Layers in the plan.
        layers: usize,
    },
    /// The path cannot be replanned column by column.
    #[error("cannot replan this path: {reason}")]
    Unsupported {
        /// Why.
        reason: String,
    },
    /// Too few scan points lie near layer `K`: a scan of another part.
    #[error("the scan is not of layer {after_layer} of this part: {outside} of {total} rows lie more than {limit_mm:.3} mm from its planned top (median distance {median_distance_mm:.3} mm)")]
    WrongPart {
        /// The measured layer.
        after_layer: usize,
        /// Rows farther than the outlier distance.
        outside: usize,
        /// Rows in the scan.
        total: usize,
        /// The outlier distance (mm).
        limit_mm: f64,
        /// Median distance of all rows to the planned top (mm).
        median_distance_mm: f64,
    },
    /// The scan lies beside the wall: a scan of another part.
    #[error("the scan is not of layer {after_layer} of this part: it lies {median_mm:+.3} mm across the wall (along the surface normal) from the planned top on median, more than {limit_mm:.3} mm")]
    WallOffset {
        /// The measured layer.
        after_layer: usize,
        /// Median offset across the wall (mm).
        median_mm: f64,
        /// The limit (mm).
        limit_mm: f64,
    },
    /// The scan lies a layer or more above or below layer `K`.
    #[error("the scan is not of layer {after_layer}: its median height error is {median_error_mm:+.3} mm, more than {limit_mm:.3} mm{hint}")]
    WrongLayer {
        /// The measured layer.
        after_layer: usize,
        /// Median height error (mm).
        median_error_mm: f64,
        /// The limit (mm).
        limit_mm: f64,
        /// Which planned layer the scan fits, when found.
        hint: String,
    },
    /// A height-error row is for another layer.
    #[error("scan row {row} is for layer {scan_layer}, but the replan is after layer {after_layer}: a scan of another layer")]
    ScanOfAnotherLayer {
        /// Row (0-based).
        row: usize,
        /// Its layer.
        scan_layer: usize,
        /// The measured layer.
        after_layer: usize,
    },
    /// A height-error row names a point the layer does not have.
    #[error("scan row {row}: point {point}, but layer {after_layer} has {points} points")]
    ScanPoint {
        /// Row (0-based).
        row: usize,
        /// Its point.
        point: usize,
        /// Points of the layer.
        points: usize,
        /// The measured layer.
        after_layer: usize,
    },
    /// Too little of layer `K` was scanned.
    #[error("the scan covers {covered} of the {points} points of layer {after_layer}, fewer than {:.0} %", 100.0 * min_fraction)]
    TooLittleCoverage {
        /// The measured layer.
        after_layer: usize,
        /// Points with data.
        covered: usize,
        /// Points of the layer.
        points: usize,
        /// The fraction asked for.
        min_fraction: f64,
    },
    /// A rebuilt point cannot be placed.
    #[error("layer {layer}, point {point}: no point at {height_mm:.3} mm from the layer below ({reason})")]
    NoRoot {
        /// Layer.
        layer: usize,
        /// Point (column of the measured layer).
        point: usize,
        /// The bead height asked for (mm).
        height_mm: f64,
        /// Why.
        reason: &'static str,
    },
    /// The planned part given is not the part given.
    #[error("the plan is of part `{planned}`, not `{part}`")]
    PartMismatch {
        /// The plan's part.
        planned: String,
        /// The part given.
        part: String,
    },
}
