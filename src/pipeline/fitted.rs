//! `Part::from_mesh`: a part fitted to a tubular STL, and its files.

use std::path::{Path, PathBuf};

use crate::fit::{fit_tube, FitOptions, FitReport, TubeFit, TubeMesh};
use crate::io::part_file::{build_part, read_part_file, Part, PartSpec};
use crate::util::atomic::write_atomic;
use crate::Error;

/// A part fitted to a mesh: the validated part, the fit (guide points,
/// radius law, report) and the part file's text.
#[derive(Debug, Clone)]
pub struct FittedPart {
    /// The part, validated as if read from its file (part frame = mesh frame, mm).
    pub part: Part,
    /// The fit: guide points, laws, substrate, report.
    pub fit: TubeFit,
    /// The part file (TOML) that [`FittedPart::write`] writes as `part.toml`.
    pub toml: String,
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
}

impl Part {
    /// Fits a part to a tubular mesh (binary or ASCII STL; mesh frame =
    /// part frame, mm): a spline guide and a radius law from end to end,
    /// the wall thickness when the mesh holds the inner and outer skins, a
    /// flat substrate at the start end's plane ([`FitOptions::start`]), the
    /// slicing, tool-axis and process tables of [`FitOptions::template`].
    ///
    /// # Errors
    /// [`Error::Fit`] naming the mesh file and, where there is one, the
    /// station: unreadable, a branch, a closed blob, a section not near a
    /// circle, a residual over [`FitOptions::max_rms_mm`];
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
        let fit = fit_tube(mesh, opts)?;
        let name = opts.name.clone().unwrap_or_else(|| {
            Path::new(&mesh.file)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .filter(|s| !s.trim().is_empty())
                .unwrap_or_else(|| "fitted".into())
        });
        let spec = fit.part_spec(&name, template.as_ref());
        let toml = toml::to_string(&spec).map_err(|e| crate::fit::FitError::Degenerate {
            file: mesh.file.clone(),
            station: 0,
            reason: format!("the part file cannot be written: {e}"),
        })?;
        let origin = format!("{} (fitted part)", mesh.file);
        let part = build_part(spec, &origin, Path::new("."))?;
        Ok(FittedPart { part, fit, toml })
    }
}
