//! `Part::from_mesh`: a part fitted to a tubular STL, and its files.

use std::path::{Path, PathBuf};

use crate::fit::section::plane_basis;
use crate::fit::{fit_tube, FitError, FitOptions, FitReport, TubeFit, TubeMesh};
use crate::geometry::MeshSubstrate;
use crate::io::part_file::{build_part, read_part_file, Part, PartSpec, Scalar, SubstrateSpec};
use crate::math::{Point3, UnitVector3};
use crate::report::{write_fit_report, FitReportInput};
use crate::util::atomic::write_atomic;
use crate::Error;

/// A part fitted to a mesh: the validated part, the fit (guide points,
/// radius law, per-vertex distances, report), the part file's text and the
/// mesh it was fitted to.
#[derive(Debug, Clone)]
pub struct FittedPart {
    /// The part, validated as if read from its file (part frame = mesh frame, mm).
    pub part: Part,
    /// The fit: guide points, laws, substrate, report.
    pub fit: TubeFit,
    /// The part file (TOML) that [`FittedPart::write`] writes as `part.toml`.
    pub toml: String,
    /// The mesh the tube was fitted to, converted to mm from
    /// [`FitOptions::units`] (mesh frame = part frame), for
    /// [`FittedPart::write_report`].
    pub mesh: TubeMesh,
}

impl FittedPart {
    /// The fit report (distances in mm).
    pub fn report(&self) -> &FitReport {
        &self.fit.report
    }

    /// Writes `part.toml` and `fit.json` into `dir` (created if missing),
    /// each through a temporary file renamed into place; returns their paths.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn write(&self, dir: impl AsRef<Path>) -> Result<Vec<PathBuf>, Error> {
        let dir = dir.as_ref();
        let io = |path: &Path, e: std::io::Error| Error::Io {
            path: path.display().to_string(),
            source: std::sync::Arc::new(e),
        };
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        let part = dir.join("part.toml");
        write_atomic(&part, |w| w.write_all(self.toml.as_bytes())).map_err(|e| io(&part, e))?;
        let json = dir.join("fit.json");
        let text =
            serde_json::to_string_pretty(&self.fit.report).map_err(|e| io(&json, e.into()))?;
        write_atomic(&json, |w| w.write_all(text.as_bytes())).map_err(|e| io(&json, e))?;
        Ok(vec![part, json])
    }

    /// Writes `report.html` into `dir` (created if missing), through a
    /// temporary file renamed into place: the mesh with its vertices
    /// coloured by their distance to the fitted tube, the fitted tube, the
    /// part's substrate and the fit's figures
    /// ([`write_fit_report`](crate::report::write_fit_report)); returns its path.
    ///
    /// # Errors
    /// [`Error::Io`] naming the folder; [`Error::Report`] naming the file.
    pub fn write_report(&self, dir: impl AsRef<Path>) -> Result<PathBuf, Error> {
        let dir = dir.as_ref();
        std::fs::create_dir_all(dir).map_err(|e| Error::Io {
            path: dir.display().to_string(),
            source: std::sync::Arc::new(e),
        })?;
        let html = dir.join("report.html");
        let input = FitReportInput {
            substrate: Some(&self.part.substrate),
            ..FitReportInput::new(&self.part.name, &self.mesh, &self.fit)
        };
        write_fit_report(&html, &input)?;
        Ok(html)
    }
}

/// The substrate mesh of [`FitOptions::substrate`]: its absolute path (as
/// the part file names it) and the mesh.
fn read_substrate(mesh: &TubeMesh, path: &Path) -> Result<(String, MeshSubstrate), FitError> {
    let bad = |reason: String| FitError::Stl {
        file: path.display().to_string(),
        reason: format!("substrate of {}: {reason}", mesh.file),
    };
    let abs = std::fs::canonicalize(path).map_err(|e| bad(format!("cannot open: {e}")))?;
    let text = abs
        .to_str()
        .ok_or_else(|| bad("the path is not valid UTF-8, a part file cannot name it".into()))?
        .to_string();
    let sub = MeshSubstrate::from_stl_file(&abs).map_err(|e| bad(e.to_string()))?;
    Ok((text, sub))
}

/// Largest distance (mm) to `sub` of 72 points of the start end's rim (its
/// fitted circle, mesh frame).
fn rim_distance(report: &FitReport, sub: &MeshSubstrate) -> f64 {
    let s = &report.start;
    let c = Point3::from(s.centre_mm);
    let n = UnitVector3::new_normalize(s.normal.into());
    let (e1, e2) = plane_basis(&n);
    (0..72)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 72.0;
            sub.distance_mm(&(c + (e1 * a.cos() + e2 * a.sin()) * s.radius_mm))
        })
        .fold(0.0, f64::max)
}

impl Part {
    /// Fits a part to a tubular mesh (binary or ASCII STL; mesh frame =
    /// part frame, mm): a spline guide and a radius law from end to end,
    /// the wall thickness when the mesh holds the inner and outer skins, a
    /// flat substrate at the start end's plane ([`FitOptions::start`]) or
    /// the substrate mesh of [`FitOptions::substrate`] (named by its
    /// absolute path, so that the written part reads from any working
    /// directory), the slicing, tool-axis and process tables of
    /// [`FitOptions::template`].
    ///
    /// # Errors
    /// [`Error::Fit`] naming the mesh file and, where there is one, the
    /// station: unreadable, a branch, a closed blob, a section not near a
    /// circle, a residual over [`FitOptions::max_rms_mm`], an unreadable
    /// substrate mesh, a start end further than
    /// [`FitOptions::substrate_tolerance_mm`] from it;
    /// [`Error::PartFile`] for an unreadable template, or a fitted tube that
    /// is not valid (naming the mesh).
    ///
    /// # Example
    /// ```no_run
    /// use waam_slicer::{FitOptions, Part};
    /// # fn main() -> Result<(), waam_slicer::Error> {
    /// let fitted = Part::from_mesh("scan/elbow.stl", &FitOptions::default())?;
    /// assert!(fitted.report().rms_mm < 0.1);
    /// let sliced = waam_slicer::slice_part(&fitted.part)?;
    /// fitted.write("out/elbow")?;
    /// # let _ = sliced; Ok(()) }
    /// ```
    pub fn from_mesh(path: impl AsRef<Path>, opts: &FitOptions) -> Result<FittedPart, Error> {
        let path = path.as_ref();
        let mesh = TubeMesh::read_stl(path)?;
        Self::from_tube_mesh(&mesh, opts)
    }

    /// As [`Part::from_mesh`], for a mesh already in memory.
    ///
    /// # Errors
    /// As [`Part::from_mesh`].
    pub fn from_tube_mesh(mesh: &TubeMesh, opts: &FitOptions) -> Result<FittedPart, Error> {
        let template: Option<PartSpec> = match &opts.template {
            Some(p) => Some(read_part_file(p)?.spec),
            None => None,
        };
        let substrate = match &opts.substrate {
            Some(p) => Some(read_substrate(mesh, p)?),
            None => None,
        };
        let mut fit = fit_tube(mesh, opts)?;
        let name = opts.name.clone().unwrap_or_else(|| {
            Path::new(&mesh.file)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .filter(|s| !s.trim().is_empty())
                .unwrap_or_else(|| "fitted".into())
        });
        let mut spec = fit.part_spec(&name, template.as_ref());
        if let Some((file, sub)) = &substrate {
            let d = rim_distance(&fit.report, sub);
            fit.report.substrate_distance_mm = Some(d);
            if !(d <= opts.substrate_tolerance_mm) {
                return Err(FitError::SubstrateFar {
                    file: mesh.file.clone(),
                    substrate: file.clone(),
                    distance_mm: d,
                    tolerance_mm: opts.substrate_tolerance_mm,
                }
                .into());
            }
            // Below the start end far enough for every iso-v line to reach
            // the substrate, wherever the rim is off it.
            let before = fit.extend_before_mm.max(2.0 * d + 1.0);
            spec.range.extend_before = Some(Scalar::Number(before));
            spec.substrate = SubstrateSpec::Mesh { file: file.clone() };
            spec.description.push_str(&format!(
                "; stands on the substrate mesh {file} (start end within {d:.3} mm)"
            ));
        }
        let toml = toml::to_string(&spec).map_err(|e| crate::fit::FitError::Degenerate {
            file: mesh.file.clone(),
            station: 0,
            reason: format!("the part file cannot be written: {e}"),
        })?;
        let origin = format!("{} (fitted part)", mesh.file);
        let part = build_part(spec, &origin, Path::new("."))?;
        Ok(FittedPart {
            part,
            fit,
            toml,
            mesh: mesh.scaled(opts.units.mm_per_unit()),
        })
    }
}
