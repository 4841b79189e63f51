//! Substrates the tube is built on — plane, cylinder, or a triangle mesh read
//! from STL — and the first layer: the closed curve where the tube surface
//! meets the substrate, as `(t, v)` pairs (part frame, mm) [SPEC §2.3;
//! thesis eq. 2.17–2.19].

use super::tube::Tube;
use super::GeometryError;
use crate::math::{self, tol, Point3, UnitVector3, Vector3};
use parry3d_f64::query::{Ray, RayCast};
use parry3d_f64::shape::TriMesh;
use std::f64::consts::TAU;

/// Signed distance (mm) at which a point scanned along an iso-v line is on
/// an analytic substrate: the scan stops there, and Brent's method stops at a
/// residual this small.
const ON_SUBSTRATE_MM: f64 = 1e-12;

/// Largest STL file accepted (bytes): 256 MiB, about 5 million triangles.
pub const MAX_STL_BYTES: u64 = 256 * 1024 * 1024;

/// Steps of the scan along an iso-`v` line from the lowest evaluable `t` to
/// `t_max`: about 0.5 mm of guide length each, 64..=4096 of them.
fn scan_steps(tube: &Tube) -> usize {
    let range = tube.range();
    let length = tube.arc_length(range.t_max) - tube.arc_length(range.eval_min());
    ((length / 0.5).ceil() as usize).clamp(64, 4096)
}

/// A triangle-mesh substrate (part frame, mm).
#[derive(Clone)]
pub struct MeshSubstrate {
    mesh: TriMesh,
    source: String,
}

impl std::fmt::Debug for MeshSubstrate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshSubstrate")
            .field("source", &self.source)
            .field("triangles", &self.mesh.num_triangles())
            .finish()
    }
}

impl MeshSubstrate {
    /// Builds a mesh substrate from triangles given by their corners (mm).
    ///
    /// # Errors
    /// [`GeometryError::Stl`] (naming `source`) if there are no triangles, a
    /// coordinate is not finite, or the mesh cannot be indexed.
    pub fn from_triangles(triangles: &[[Point3; 3]], source: &str) -> Result<Self, GeometryError> {
        let bad = |reason: String| GeometryError::Stl {
            file: source.to_string(),
            reason,
        };
        if triangles.is_empty() {
            return Err(bad("the mesh has no triangles".into()));
        }
        let mut vertices = Vec::with_capacity(triangles.len() * 3);
        let mut indices = Vec::with_capacity(triangles.len());
        for (i, tri) in triangles.iter().enumerate() {
            if !tri.iter().all(|p| p.coords.iter().all(|c| c.is_finite())) {
                return Err(bad(format!("triangle {i} has a non-finite coordinate")));
            }
            let base =
                u32::try_from(vertices.len()).map_err(|_| bad("too many vertices".into()))?;
            vertices.extend_from_slice(tri);
            indices.push([base, base + 1, base + 2]);
        }
        let mesh = TriMesh::new(vertices, indices).map_err(|e| bad(format!("{e:?}")))?;
        Ok(Self {
            mesh,
            source: source.to_string(),
        })
    }

    /// Reads an STL file (binary or ASCII) held in memory. `source` names it
    /// in errors.
    ///
    /// # Errors
    /// [`GeometryError::Stl`] for an empty or oversized file, a binary file
    /// whose length does not match its triangle count, or unreadable content.
    pub fn from_stl_bytes(bytes: &[u8], source: &str) -> Result<Self, GeometryError> {
        let bad = |reason: String| GeometryError::Stl {
            file: source.to_string(),
            reason,
        };
        if bytes.is_empty() {
            return Err(bad("the file is empty (0 bytes)".into()));
        }
        if bytes.len() as u64 > MAX_STL_BYTES {
            return Err(bad(format!(
                "the file is {} bytes; the limit is {MAX_STL_BYTES} bytes",
                bytes.len()
            )));
        }
        let looks_ascii = bytes.len() >= 5 && bytes[..5].eq_ignore_ascii_case(b"solid");
        let binary_consistent = bytes.len() >= 84 && {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
            84 + 50 * n == bytes.len() as u64
        };
        if !looks_ascii && !binary_consistent {
            if bytes.len() < 84 {
                return Err(bad(format!(
                    "binary STL shorter than its 84-byte header ({} bytes)",
                    bytes.len()
                )));
            }
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
            return Err(bad(format!(
                "binary STL header announces {n} triangles ({} bytes expected) but the file has {} bytes",
                84 + 50 * n,
                bytes.len()
            )));
        }
        let mut cursor = std::io::Cursor::new(bytes);
        let mesh =
            stl_io::read_stl(&mut cursor).map_err(|e| bad(format!("unreadable STL: {e}")))?;
        let mut triangles = Vec::with_capacity(mesh.faces.len());
        for (i, f) in mesh.faces.iter().enumerate() {
            let mut tri = [Point3::origin(); 3];
            for (k, &vi) in f.vertices.iter().enumerate() {
                let v = mesh
                    .vertices
                    .get(vi)
                    .ok_or_else(|| bad(format!("triangle {i} refers to a missing vertex")))?;
                tri[k] = Point3::new(v.0[0] as f64, v.0[1] as f64, v.0[2] as f64);
            }
            triangles.push(tri);
        }
        Self::from_triangles(&triangles, source)
    }

    /// Reads an STL file from disk.
    ///
    /// # Errors
    /// [`GeometryError::Stl`] naming the path, as [`MeshSubstrate::from_stl_bytes`],
    /// or if the file cannot be opened; the size limit is checked before reading.
    pub fn from_stl_file(path: &std::path::Path) -> Result<Self, GeometryError> {
        let source = path.display().to_string();
        let bad = |reason: String| GeometryError::Stl {
            file: source.clone(),
            reason,
        };
        let meta = std::fs::metadata(path).map_err(|e| bad(format!("cannot open: {e}")))?;
        if meta.len() > MAX_STL_BYTES {
            return Err(bad(format!(
                "the file is {} bytes; the limit is {MAX_STL_BYTES} bytes",
                meta.len()
            )));
        }
        // Read at most one byte past the limit: a device or pipe reports a
        // length of 0 and would otherwise be read for ever.
        use std::io::Read as _;
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .map_err(|e| bad(format!("cannot open: {e}")))?
            .take(MAX_STL_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| bad(format!("cannot read: {e}")))?;
        if bytes.len() as u64 > MAX_STL_BYTES {
            return Err(bad(format!(
                "more than {MAX_STL_BYTES} bytes, the limit for an STL file"
            )));
        }
        Self::from_stl_bytes(&bytes, &source)
    }

    /// Number of triangles.
    pub fn num_triangles(&self) -> usize {
        self.mesh.num_triangles()
    }

    /// The triangles by their corners (part frame, mm).
    pub fn triangles(&self) -> Vec<[Point3; 3]> {
        self.mesh.triangles().map(|t| [t.a, t.b, t.c]).collect()
    }

    /// Distance (mm) of `p` (part frame) to the mesh's surface.
    pub fn distance_mm(&self, p: &Point3) -> f64 {
        use parry3d_f64::query::PointQuery;
        self.mesh.distance_to_local_point(p, true)
    }
}

/// The surface the first layer is deposited on (part frame, mm).
#[derive(Debug, Clone)]
pub enum Substrate {
    /// A plane through `point` with unit `normal` (pointing to the part side).
    Plane {
        /// A point of the plane (mm).
        point: Point3,
        /// Unit normal, toward the side the part grows on.
        normal: UnitVector3,
    },
    /// An infinite circular cylinder.
    Cylinder {
        /// A point of the axis (mm).
        axis_point: Point3,
        /// Unit axis direction.
        axis: UnitVector3,
        /// Radius `R_c` (mm).
        radius: f64,
    },
    /// A triangle mesh.
    Mesh(Box<MeshSubstrate>),
}

/// One point of a curve drawn on the tube, with its surface coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// Guide parameter `t`.
    pub t: f64,
    /// Profile angle `v` (rad).
    pub v: f64,
    /// `M(t, v)` (part frame, mm).
    pub position: Point3,
}

impl Substrate {
    /// Signed distance-like function of a point: zero on the substrate,
    /// positive on the side of the plane normal / outside the cylinder (mm).
    /// `None` for meshes (which are intersected by ray casting).
    pub fn signed_distance(&self, p: &Point3) -> Option<f64> {
        match self {
            Substrate::Plane { point, normal } => Some((p - point).dot(normal)),
            Substrate::Cylinder {
                axis_point,
                axis,
                radius,
            } => {
                let d = p - axis_point;
                Some((d - axis.into_inner() * d.dot(axis)).norm() - radius)
            }
            Substrate::Mesh(_) => None,
        }
    }

    /// Unit direction pointing away from the substrate at a point on (or
    /// near) it: the plane normal, the radial direction of the cylinder, or
    /// `None` for meshes.
    pub fn outward(&self, p: &Point3) -> Option<Vector3> {
        match self {
            Substrate::Plane { normal, .. } => Some(normal.into_inner()),
            Substrate::Cylinder {
                axis_point, axis, ..
            } => {
                let d = p - axis_point;
                let r = d - axis.into_inner() * d.dot(axis);
                (r.norm() > 0.0).then(|| r.normalize())
            }
            Substrate::Mesh(_) => None,
        }
    }

    /// Validates the substrate's own numbers.
    ///
    /// # Errors
    /// [`GeometryError::InvalidField`] naming the field.
    pub fn validate(&self) -> Result<(), GeometryError> {
        let finite = |p: &Point3| p.coords.iter().all(|c| c.is_finite());
        match self {
            Substrate::Plane { point, .. } if !finite(point) => Err(GeometryError::InvalidField {
                field: "substrate.point".into(),
                reason: "must be finite".into(),
            }),
            Substrate::Cylinder { radius, .. } if !(radius.is_finite() && *radius > 0.0) => {
                Err(GeometryError::InvalidField {
                    field: "substrate.radius".into(),
                    reason: format!("must be positive and finite, got {radius}"),
                })
            }
            Substrate::Cylinder { axis_point, .. } if !finite(axis_point) => {
                Err(GeometryError::InvalidField {
                    field: "substrate.axis_point".into(),
                    reason: "must be finite".into(),
                })
            }
            _ => Ok(()),
        }
    }

    /// Guide parameter `t` where the iso-`v` line of the tube first meets the
    /// substrate, searching from the tube's lowest evaluable parameter up to
    /// `t_max` (1-D root find on the signed distance, or ray casting on a mesh).
    ///
    /// # Errors
    /// [`GeometryError::SubstrateMiss`] naming `v` when the line never meets it.
    pub fn first_layer_t(&self, tube: &Tube, v: f64) -> Result<f64, GeometryError> {
        self.first_layer_t_in(tube, v, scan_steps(tube))
    }

    fn first_layer_t_in(&self, tube: &Tube, v: f64, steps: usize) -> Result<f64, GeometryError> {
        let range = tube.range();
        let (lo, hi) = (range.eval_min(), range.t_max);
        let dt = (hi - lo) / steps as f64;
        let miss = |reason: &str| GeometryError::SubstrateMiss {
            v,
            reason: reason.to_string(),
        };
        match self {
            Substrate::Mesh(m) => {
                let mut a = tube.point(lo, v);
                for k in 0..steps {
                    let ta = lo + k as f64 * dt;
                    let tb = ta + dt;
                    let b = tube.point(tb, v);
                    let ray = Ray::new(a, b - a);
                    if let Some(hit) = m.mesh.cast_local_ray_and_get_normal(&ray, 1.0, false) {
                        let hp = ray.point_at(hit.time_of_impact);
                        let n = hit.normal;
                        let g = |t: f64| (tube.point(t, v) - hp).dot(&n);
                        return Ok(match math::brent(g, ta, tb, tol::PARAM_FINE, 0.0) {
                            Ok(r) => r.x,
                            Err(_) => ta + hit.time_of_impact * dt,
                        });
                    }
                    a = b;
                }
                Err(miss(
                    "the iso-v line does not cross the mesh between t_min and t_max",
                ))
            }
            _ => {
                let f = |t: f64| self.signed_distance(&tube.point(t, v)).unwrap_or(f64::NAN);
                let f0 = f(lo);
                if !f0.is_finite() {
                    return Err(miss("signed distance is not finite"));
                }
                if f0.abs() <= tol::LENGTH_MM {
                    return Ok(lo);
                }
                let mut ta = lo;
                let mut fa = f0;
                for k in 1..=steps {
                    let tb = lo + k as f64 * dt;
                    let fb = f(tb);
                    if fb.abs() <= ON_SUBSTRATE_MM {
                        return Ok(tb);
                    }
                    if fa * fb < 0.0 {
                        return math::brent(f, ta, tb, tol::PARAM_FINE, ON_SUBSTRATE_MM)
                            .map(|r| r.x)
                            .map_err(|_| miss("root finding failed"));
                    }
                    ta = tb;
                    fa = fb;
                }
                Err(miss(
                    "the iso-v line does not cross the substrate between t_min and t_max",
                ))
            }
        }
    }

    /// The first layer: `n` points, `v = 2πk/n`, where the tube meets the
    /// substrate, as a closed curve (the last point joins the first).
    ///
    /// # Errors
    /// [`GeometryError::SubstrateMiss`] naming the first `v` that misses;
    /// [`GeometryError::InvalidField`] for `n < 3`.
    pub fn first_layer(&self, tube: &Tube, n: usize) -> Result<Vec<CurvePoint>, GeometryError> {
        if n < 3 {
            return Err(GeometryError::InvalidField {
                field: "points".into(),
                reason: format!("a layer needs at least 3 points, got {n}"),
            });
        }
        let steps = scan_steps(tube);
        (0..n)
            .map(|k| {
                let v = TAU * k as f64 / n as f64;
                let t = self.first_layer_t_in(tube, v, steps)?;
                Ok(CurvePoint {
                    t,
                    v,
                    position: tube.point(t, v),
                })
            })
            .collect()
    }
}
