//! The input of the fit: an indexed triangle mesh (mesh frame, mm) read from
//! an STL file.

use super::FitError;
use crate::math::Point3;
use std::path::Path;

/// Largest STL file accepted by the fit (bytes): 20 M triangles in binary.
pub const MAX_MESH_BYTES: u64 = 1024 * 1024 * 1024;

/// An indexed triangle mesh of a tube (mesh frame = part frame, mm), with
/// coincident vertices merged and degenerate triangles dropped.
#[derive(Debug, Clone)]
pub struct TubeMesh {
    /// The file it was read from (or the name given); errors name it.
    pub file: String,
    /// Vertex positions (mm).
    pub vertices: Vec<Point3>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

impl TubeMesh {
    /// Reads a binary or ASCII STL file.
    ///
    /// # Errors
    /// [`FitError::StlIo`] naming the file when it cannot be opened or
    /// read; [`FitError::Stl`] when it is over [`MAX_MESH_BYTES`],
    /// unreadable as STL, or without a usable triangle.
    pub fn read_stl(path: &Path) -> Result<Self, FitError> {
        let file = path.display().to_string();
        let bad = |reason: String| FitError::Stl {
            file: file.clone(),
            reason,
        };
        let io = |reason: String| FitError::StlIo {
            file: file.clone(),
            reason,
        };
        let meta = std::fs::metadata(path).map_err(|e| io(format!("cannot open: {e}")))?;
        if meta.len() > MAX_MESH_BYTES {
            return Err(bad(format!(
                "{} bytes; the limit for a mesh is {MAX_MESH_BYTES}",
                meta.len()
            )));
        }
        let bytes = std::fs::read(path).map_err(|e| io(format!("cannot read: {e}")))?;
        Self::from_stl_bytes(&bytes, &file)
    }

    /// Reads an STL file held in memory; `file` names it in errors.
    ///
    /// # Errors
    /// As [`TubeMesh::read_stl`].
    pub fn from_stl_bytes(bytes: &[u8], file: &str) -> Result<Self, FitError> {
        let bad = |reason: String| FitError::Stl {
            file: file.to_string(),
            reason,
        };
        if bytes.is_empty() {
            return Err(bad("the file is empty (0 bytes)".into()));
        }
        let looks_ascii = bytes.len() >= 5 && bytes[..5].eq_ignore_ascii_case(b"solid");
        let binary_consistent = bytes.len() >= 84 && {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
            84 + 50 * n == bytes.len() as u64
        };
        if !looks_ascii && !binary_consistent {
            return Err(bad(format!(
                "neither ASCII STL (no `solid` header) nor binary STL (the length, {} bytes, does not match the triangle count)",
                bytes.len()
            )));
        }
        let mut cursor = std::io::Cursor::new(bytes);
        let mesh =
            stl_io::read_stl(&mut cursor).map_err(|e| bad(format!("unreadable STL: {e}")))?;
        let vertices: Vec<Point3> = mesh
            .vertices
            .iter()
            .map(|v| Point3::new(v.0[0] as f64, v.0[1] as f64, v.0[2] as f64))
            .collect();
        let mut triangles = Vec::with_capacity(mesh.faces.len());
        for f in &mesh.faces {
            let [a, b, c] = f.vertices;
            let ok = |i: usize| {
                u32::try_from(i)
                    .ok()
                    .filter(|&i| (i as usize) < vertices.len())
            };
            match (ok(a), ok(b), ok(c)) {
                (Some(a), Some(b), Some(c)) => triangles.push([a, b, c]),
                _ => return Err(bad("a triangle refers to a missing vertex".into())),
            }
        }
        Self::new(vertices, triangles, file)
    }

    /// Builds a mesh from vertices and triangles; `file` names it in errors.
    /// Drops triangles with a repeated vertex or zero area.
    ///
    /// # Errors
    /// [`FitError::Stl`] if a vertex is not finite, an index is out of range,
    /// or no triangle is left.
    pub fn new(
        vertices: Vec<Point3>,
        triangles: Vec<[u32; 3]>,
        file: &str,
    ) -> Result<Self, FitError> {
        let bad = |reason: String| FitError::Stl {
            file: file.to_string(),
            reason,
        };
        if let Some(i) = vertices
            .iter()
            .position(|p| !p.coords.iter().all(|c| c.is_finite()))
        {
            return Err(bad(format!("vertex {i} is not finite")));
        }
        let n = vertices.len();
        let mut kept = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            if t.iter().any(|&v| v as usize >= n) {
                return Err(bad(format!("triangle {i} refers to a missing vertex")));
            }
            let [a, b, c] = t.map(|v| vertices[v as usize]);
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && (b - a).cross(&(c - a)).norm() > 0.0
            {
                kept.push(*t);
            }
        }
        if kept.is_empty() {
            return Err(bad("no triangle of non-zero area".into()));
        }
        Ok(Self {
            file: file.to_string(),
            vertices,
            triangles: kept,
        })
    }

    /// The mesh with every coordinate multiplied by `mm_per_unit` (its
    /// file's unit to mm; [`Units::mm_per_unit`](super::Units::mm_per_unit)).
    /// Same vertex and triangle order.
    pub fn scaled(&self, mm_per_unit: f64) -> TubeMesh {
        TubeMesh {
            file: self.file.clone(),
            vertices: self.vertices.iter().map(|p| p * mm_per_unit).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Largest side of the vertices' bounding box (the file's unit).
    pub fn bounding_box_size(&self) -> f64 {
        let (lo, hi) = self.vertices.iter().fold(
            (Point3::from([f64::MAX; 3]), Point3::from([f64::MIN; 3])),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        (hi - lo).max().max(0.0)
    }

    /// Number of triangles.
    pub fn num_triangles(&self) -> usize {
        self.triangles.len()
    }
}
