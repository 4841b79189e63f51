//! The mesh's surfaces: connected pieces, their open ends (boundary loops),
//! faces split at creases, flat end faces (caps), and the level sets of the
//! geodesic distance from an open end (a first guide, and where a tube
//! branches). Mesh frame, mm.

use super::outcome::FeatureKind;
use super::section::{fit_plane, plane_rms};
use super::{FitError, FitOptions, TubeMesh};
use crate::math::{Point3, UnitVector3};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// One skin of the tube wall (or its mid-surface): an open surface with two
/// open ends.
#[derive(Debug, Clone)]
pub struct Skin {
    /// Its triangles (indices into the mesh's triangles).
    pub triangles: Vec<u32>,
    /// Its vertices (indices into the mesh's vertices, sorted).
    pub vertices: Vec<u32>,
    /// Its two open ends, as vertex sets.
    pub loops: [Vec<u32>; 2],
}

/// A flat face closing an end (mesh frame, mm).
#[derive(Debug, Clone)]
pub struct Cap {
    /// Its vertices (sorted).
    pub vertices: Vec<u32>,
    /// Centroid of its vertices (mm).
    pub centroid: Point3,
    /// Its plane's normal (either sense).
    pub normal: UnitVector3,
}

/// The mesh seen as a tube: one skin (mid-surface) or two (wall), and flat caps.
#[derive(Debug, Clone)]
pub struct Surfaces {
    /// The skins, largest first.
    pub skins: Vec<Skin>,
    /// Flat end faces.
    pub caps: Vec<Cap>,
    /// Triangles of small stray pieces left out of the fit.
    pub ignored_triangles: usize,
    /// Separate closed pieces beside the tube (tabs): their triangles.
    pub pieces: Vec<Vec<u32>>,
}

struct UnionFind(Vec<u32>);

impl UnionFind {
    fn new(n: usize) -> Self {
        Self((0..n as u32).collect())
    }
    fn find(&mut self, mut i: u32) -> u32 {
        while self.0[i as usize] != i {
            let p = self.0[self.0[i as usize] as usize];
            self.0[i as usize] = p;
            i = p;
        }
        i
    }
    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}

/// Edges `(lo, hi, triangle)` of the given triangles, sorted.
fn edges(mesh: &TubeMesh, tris: &[u32]) -> Vec<(u32, u32, u32)> {
    let mut e = Vec::with_capacity(3 * tris.len());
    for &t in tris {
        let v = mesh.triangles[t as usize];
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            e.push((a.min(b), a.max(b), t));
        }
    }
    e.sort_unstable();
    e
}

/// Groups of `tris` joined across edges that `joins(t1, t2)` accepts.
fn pieces(mesh: &TubeMesh, tris: &[u32], joins: impl Fn(u32, u32) -> bool) -> Vec<Vec<u32>> {
    let index: HashMap<u32, u32> = tris
        .iter()
        .enumerate()
        .map(|(i, &t)| (t, i as u32))
        .collect();
    let mut uf = UnionFind::new(tris.len());
    let e = edges(mesh, tris);
    for group in e.chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
        for w in group.windows(2) {
            if joins(w[0].2, w[1].2) {
                uf.union(index[&w[0].2], index[&w[1].2]);
            }
        }
    }
    let mut by_root: HashMap<u32, Vec<u32>> = HashMap::new();
    for (i, &t) in tris.iter().enumerate() {
        by_root.entry(uf.find(i as u32)).or_default().push(t);
    }
    let mut out: Vec<Vec<u32>> = by_root.into_values().collect();
    out.sort_by_key(|p| (Reverse(p.len()), p[0]));
    out
}

/// The open ends of a set of triangles: loops of the edges used by one of
/// them only, as vertex sets (sorted, loops ordered by their first vertex).
pub fn boundary_loops(mesh: &TubeMesh, tris: &[u32]) -> Vec<Vec<u32>> {
    let e = edges(mesh, tris);
    let boundary: Vec<(u32, u32)> = e
        .chunk_by(|a, b| (a.0, a.1) == (b.0, b.1))
        .filter(|g| g.len() == 1)
        .map(|g| (g[0].0, g[0].1))
        .collect();
    let mut local: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in &boundary {
        for v in [a, b] {
            let n = local.len() as u32;
            local.entry(v).or_insert(n);
        }
    }
    let mut uf = UnionFind::new(local.len());
    for &(a, b) in &boundary {
        uf.union(local[&a], local[&b]);
    }
    let mut by_root: HashMap<u32, Vec<u32>> = HashMap::new();
    for (&v, &i) in &local {
        by_root.entry(uf.find(i)).or_default().push(v);
    }
    let mut loops: Vec<Vec<u32>> = by_root
        .into_values()
        .map(|mut l| {
            l.sort_unstable();
            l
        })
        .collect();
    loops.sort_by_key(|l| l[0]);
    loops
}

fn vertices_of(mesh: &TubeMesh, tris: &[u32]) -> Vec<u32> {
    let mut v: Vec<u32> = tris
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

fn unit_normal(mesh: &TubeMesh, t: u32) -> crate::math::Vector3 {
    let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.vertices[i as usize]);
    (b - a).cross(&(c - a)).normalize()
}

/// Finds the skins and caps of `mesh`.
///
/// A connected piece with two open ends is a skin as it is; any other piece
/// is split at creases ([`FitOptions::crease_angle_deg`]) into faces: flat
/// faces are caps, faces with two open ends skins.
///
/// # Errors
/// [`FitError::ClosedSurface`] for a closed face without flat faces,
/// [`FitError::Branch`] for a face with three open ends or more,
/// [`FitError::NotATube`] for one open end or a count of skins other than 1 or 2.
pub fn surfaces(mesh: &TubeMesh, opts: &FitOptions) -> Result<Surfaces, FitError> {
    let all: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
    let components = pieces(mesh, &all, |_, _| true);
    let small = (mesh.triangles.len() / 100).max(1);
    let cos_crease = opts.crease_angle_deg.to_radians().cos();
    let normals: Vec<_> = all.iter().map(|&t| unit_normal(mesh, t)).collect();
    let mut out = Surfaces {
        skins: Vec::new(),
        caps: Vec::new(),
        ignored_triangles: 0,
        pieces: Vec::new(),
    };
    for (ci, comp) in components.into_iter().enumerate() {
        let loops = boundary_loops(mesh, &comp);
        if ci > 0 && loops.is_empty() {
            // A closed piece beside the tube (the repair left out those under
            // 1 % of the area): a tab, not an end face.
            out.pieces.push(comp);
            continue;
        }
        if comp.len() < small {
            out.ignored_triangles += comp.len();
            continue;
        }
        if loops.len() >= 3 {
            return Err(branch_error(mesh, &comp, &loops));
        }
        if loops.len() == 2 && !concentric(mesh, &loops) {
            let pair = <[Vec<u32>; 2]>::try_from(loops).expect("two loops");
            out.skins.push(Skin {
                vertices: vertices_of(mesh, &comp),
                triangles: comp,
                loops: pair,
            });
            continue;
        }
        let faces = pieces(mesh, &comp, |a, b| {
            normals[a as usize].dot(&normals[b as usize]).abs() >= cos_crease
        });
        let flat: Vec<Option<(Cap, f64)>> = faces.iter().map(|f| flat_face(mesh, f)).collect();
        let small_face = (comp.len() / 200).max(1);
        for group in steps_joined(mesh, &faces, &flat) {
            if let [i] = group[..] {
                if let Some((cap, _)) = &flat[i] {
                    out.caps.push(cap.clone());
                    continue;
                }
            }
            let face: Vec<u32> = group
                .iter()
                .flat_map(|&i| faces[i].iter().copied())
                .collect();
            let vertices = vertices_of(mesh, &face);
            if face.len() < small_face {
                out.ignored_triangles += face.len();
                continue;
            }
            let loops = boundary_loops(mesh, &face);
            match loops.len() {
                0 => {
                    return Err(FitError::ClosedSurface {
                        file: mesh.file.clone(),
                        found: format!(
                            "a closed surface ({} vertices, {} triangles) with no open end and no flat end face: a blob",
                            vertices.len(),
                            face.len()
                        ),
                    })
                }
                1 => return Err(closed_end_error(mesh, &face, &loops[0], opts)),
                2 => {
                    let pair = <[Vec<u32>; 2]>::try_from(loops).expect("two loops");
                    out.skins.push(Skin {
                        triangles: face,
                        vertices,
                        loops: pair,
                    });
                }
                _ => return Err(branch_error(mesh, &face, &loops)),
            }
        }
    }
    out.skins.sort_by_key(|s| Reverse(s.triangles.len()));
    if out.skins.is_empty() || out.skins.len() > 2 {
        return Err(FitError::NotATube {
            file: mesh.file.clone(),
            found: format!(
                "{} tube surfaces with two open ends (need 1: the mid-surface, or 2: the skins of a wall); {} flat faces",
                out.skins.len(),
                out.caps.len()
            ),
        });
    }
    Ok(out)
}

/// Two open ends about one centre (within a twentieth of the smaller's
/// mean radius): the two skins of a wall opened at one end (a wall trimmed
/// at a feature), not one skin from end to end.
fn concentric(mesh: &TubeMesh, loops: &[Vec<u32>]) -> bool {
    let ring = |l: &[u32]| {
        let pts: Vec<Point3> = l.iter().map(|&v| mesh.vertices[v as usize]).collect();
        let c = Point3::from(
            pts.iter()
                .fold(crate::math::Vector3::zeros(), |a, p| a + p.coords)
                / pts.len() as f64,
        );
        let r = pts.iter().map(|p| (p - c).norm()).sum::<f64>() / pts.len() as f64;
        (c, r)
    };
    let ((c0, r0), (c1, r1)) = (ring(&loops[0]), ring(&loops[1]));
    (c1 - c0).norm() < 0.05 * r0.min(r1)
}

/// `face` as a flat face (its vertices within 1e-4 of its size plus 1 µm
/// of a plane) and that tolerance (mm), else `None`.
fn flat_face(mesh: &TubeMesh, face: &[u32]) -> Option<(Cap, f64)> {
    let vertices = vertices_of(mesh, face);
    let pts: Vec<Point3> = vertices
        .iter()
        .map(|&v| mesh.vertices[v as usize])
        .collect();
    let (centroid, normal, dev) = fit_plane(&pts)?;
    let extent = pts
        .iter()
        .map(|p| (p - centroid).norm())
        .fold(0.0, f64::max);
    let tol = 1e-4 * extent + 1e-3;
    let cap = Cap {
        vertices,
        centroid,
        normal,
    };
    (dev <= tol).then_some((cap, tol))
}

/// The faces of a closed piece (`faces`, `flat` their flat-face fits and
/// tolerances)
/// grouped into surfaces: a flat face whose neighbouring faces lie on both
/// sides of its plane is a step on one skin (a flange's or a collar's
/// side, a block's top), joined with them; a flat face whose neighbours
/// all lie on one side closes an end (a cap). Groups of face indices.
fn steps_joined(
    mesh: &TubeMesh,
    faces: &[Vec<u32>],
    flat: &[Option<(Cap, f64)>],
) -> Vec<Vec<usize>> {
    let face_of: HashMap<u32, usize> = faces
        .iter()
        .enumerate()
        .flat_map(|(i, f)| f.iter().map(move |&t| (t, i)))
        .collect();
    let all: Vec<u32> = faces.iter().flatten().copied().collect();
    let mut next: Vec<Vec<usize>> = vec![Vec::new(); faces.len()];
    for group in edges(mesh, &all).chunk_by(|a, b| (a.0, a.1) == (b.0, b.1)) {
        for w in group.windows(2) {
            let (a, b) = (face_of[&w[0].2], face_of[&w[1].2]);
            if a != b {
                next[a].push(b);
                next[b].push(a);
            }
        }
    }
    let mut uf = UnionFind::new(faces.len());
    for (i, cap) in flat.iter().enumerate() {
        let Some((cap, tol)) = cap else { continue };
        next[i].sort_unstable();
        next[i].dedup();
        let (mut above, mut below) = (false, false);
        for &j in &next[i] {
            let (lo, hi) = vertices_of(mesh, &faces[j])
                .iter()
                .map(|&v| (mesh.vertices[v as usize] - cap.centroid).dot(&cap.normal))
                .fold((0.0_f64, 0.0_f64), |a, x| (a.0.min(x), a.1.max(x)));
            above |= hi > *tol && lo >= -tol;
            below |= lo < -tol && hi <= *tol;
        }
        if above && below {
            for &j in &next[i] {
                uf.union(i as u32, j as u32);
            }
        }
    }
    let mut by_root: HashMap<u32, Vec<usize>> = HashMap::new();
    for i in 0..faces.len() {
        by_root.entry(uf.find(i as u32)).or_default().push(i);
    }
    let mut out: Vec<Vec<usize>> = by_root.into_values().collect();
    out.sort_unstable();
    out
}

/// The branch error of a piece with three open ends or more: names the first
/// level set (from the lowest end) that falls apart.
fn branch_error(mesh: &TubeMesh, tris: &[u32], loops: &[Vec<u32>]) -> FitError {
    let lowest = loops
        .iter()
        .min_by(|a, b| mean_z(mesh, a).total_cmp(&mean_z(mesh, b)))
        .expect("loops");
    let width = 3.0 * median_edge(mesh, tris);
    let sets = level_sets(mesh, tris, lowest, width);
    let found = format!("{} open ends: a branched tube", loops.len());
    match sets.bands.iter().position(|b| b.pieces >= 2) {
        Some(k) => {
            if let Some(e) = extra_loop_feature(mesh, loops, lowest, &sets, k, width) {
                return e;
            }
            let c = sets.bands[k].centroid;
            FitError::Branch {
                file: mesh.file.clone(),
                station: k,
                t_mm: (k as f64 + 0.5) * width,
                x: c.x,
                y: c.y,
                z: c.z,
                found: format!(
                    "{found}; the level set there falls apart in {} rings",
                    sets.bands[k].pieces
                ),
            }
        }
        None => {
            let c = Point3::from(
                loops[0]
                    .iter()
                    .fold(crate::math::Vector3::zeros(), |a, &v| {
                        a + mesh.vertices[v as usize].coords
                    })
                    / loops[0].len() as f64,
            );
            FitError::Branch {
                file: mesh.file.clone(),
                station: 0,
                t_mm: 0.0,
                x: c.x,
                y: c.y,
                z: c.z,
                found,
            }
        }
    }
}

/// The error of a surface with one open end: its other end is closed by a
/// surface that is not flat (a dome, a cone). Names that end (`start` or
/// `end`, as [`FitOptions::start`] would choose between the open rim and
/// the far point) and the level set of the distance from the open rim where
/// the closed end begins: the first whose ring is narrower than 0.97 times
/// the widest before it.
fn closed_end_error(mesh: &TubeMesh, tris: &[u32], rim: &[u32], opts: &FitOptions) -> FitError {
    let pts: Vec<Point3> = rim.iter().map(|&v| mesh.vertices[v as usize]).collect();
    let c = pts
        .iter()
        .fold(crate::math::Vector3::zeros(), |a, p| a + p.coords)
        / pts.len() as f64;
    let r = pts.iter().map(|p| (p.coords - c).norm()).sum::<f64>() / pts.len() as f64;
    let width = (3.0 * median_edge(mesh, tris)).max(r / 3.0);
    let sets = level_sets(mesh, tris, rim, width);
    // Each band's ring: the mean distance of its vertices to its centroid.
    let mut ring = vec![(0.0, 0usize); sets.bands.len()];
    for (v, &d) in sets.distance.iter().enumerate() {
        if d.is_finite() {
            let k = (d / width) as usize;
            ring[k].0 += (mesh.vertices[v] - sets.bands[k].centroid).norm();
            ring[k].1 += 1;
        }
    }
    let rho: Vec<f64> = ring.iter().map(|&(s, n)| s / n.max(1) as f64).collect();
    let mut widest = 0.0_f64;
    let k = rho
        .iter()
        .position(|&x| {
            let narrower = widest > 0.0 && x < 0.97 * widest;
            widest = widest.max(x);
            narrower
        })
        .unwrap_or(rho.len().saturating_sub(1));
    let far = sets
        .distance
        .iter()
        .enumerate()
        .filter(|(_, d)| d.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(Point3::from(c), |(v, _)| mesh.vertices[v]);
    let dome_first = match opts.start {
        crate::fit::StartEnd::Highest => far.z > c.z,
        crate::fit::StartEnd::Near(p) => {
            let p = Point3::new(p[0], p[1], p[2]);
            (far - p).norm() < (Point3::from(c) - p).norm()
        }
        crate::fit::StartEnd::Lowest | crate::fit::StartEnd::Capped => far.z < c.z,
    };
    let found = format!(
        "a surface of {} triangles with one open end only (radius {r:.2} mm): the other is closed by a surface that is not flat (a dome, a cone), {:.1} mm long",
        tris.len(),
        (sets.bands.len() - k) as f64 * width
    );
    let (station, t_mm) = if dome_first {
        (0, 0.0)
    } else {
        (k, k as f64 * width)
    };
    FitError::UnknownEnd {
        file: mesh.file.clone(),
        end: super::outcome::which(dome_first).into(),
        station,
        t_mm,
        found: format!("{found} (stations are level sets of the distance from the open end, {width:.2} mm apart)"),
    }
}

/// An extra open end whose surface ends soon after the level sets split
/// (within [`FEATURE_LOOP_RADII`] of its own radius: a sleeve, a block open
/// at one side) beside one that continues as the tube: a feature that is
/// not tube, not a branch (whose open ends all lie further on). Named by its
/// open end's outline (round: a collar; else a block), its distance from
/// the split and its size across.
fn extra_loop_feature(
    mesh: &TubeMesh,
    loops: &[Vec<u32>],
    lowest: &[u32],
    sets: &LevelSets,
    k: usize,
    width: f64,
) -> Option<FitError> {
    let d_split = k as f64 * width;
    let mut ending = Vec::new();
    let mut continuing = 0;
    for l in loops.iter().filter(|l| l.as_slice() != lowest) {
        let pts: Vec<Point3> = l.iter().map(|&v| mesh.vertices[v as usize]).collect();
        let c = pts
            .iter()
            .fold(crate::math::Vector3::zeros(), |a, p| a + p.coords)
            / pts.len() as f64;
        let rho: Vec<f64> = pts.iter().map(|p| (p.coords - c).norm()).collect();
        let r = rho.iter().sum::<f64>() / rho.len() as f64;
        let d = l
            .iter()
            .map(|&v| sets.distance[v as usize])
            .fold(f64::INFINITY, f64::min);
        if d - d_split < FEATURE_LOOP_RADII * r {
            let (lo, hi) = rho
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |a, &x| (a.0.min(x), a.1.max(x)));
            ending.push((d, lo, hi, Point3::from(c)));
        } else {
            continuing += 1;
        }
    }
    if continuing != 1 || ending.is_empty() {
        return None;
    }
    let (d, lo, hi, c) = ending[0];
    let kind = if hi - lo > 0.1 * hi {
        FeatureKind::Block
    } else {
        FeatureKind::Collar
    };
    let across = if hi - lo > 0.05 * hi {
        format!("{:.1} to {:.1} mm across", 2.0 * lo, 2.0 * hi)
    } else {
        format!("{:.1} mm across", 2.0 * hi)
    };
    Some(FitError::Feature {
        file: mesh.file.clone(),
        kind: kind.name(),
        station: k,
        last_station: (d / width) as usize,
        t_mm: d_split,
        t_end_mm: d,
        size: format!(
            "an open surface beside the tube that ends {:.1} mm further on, its open end {across} near ({:.1}, {:.1}, {:.1}) mm{}; not a branch: no tube continues past it (stations are level sets of the distance along the surface from the lowest open end, {width:.2} mm apart; --trim cannot cut it out: it holds an open end of the mesh)",
            d - d_split,
            c.x,
            c.y,
            c.z,
            match ending.len() {
                1 => String::new(),
                n => format!(" (and {} more)", n - 1),
            }
        ),
    })
}

/// An extra open end reached within this many of its own radii (mean
/// distance of its vertices from their centroid) past the split of the
/// level sets ends a feature, not a branch (dimensionless): a branch is a
/// tube, longer than it is wide.
const FEATURE_LOOP_RADII: f64 = 2.0;

fn mean_z(mesh: &TubeMesh, vs: &[u32]) -> f64 {
    vs.iter().map(|&v| mesh.vertices[v as usize].z).sum::<f64>() / vs.len().max(1) as f64
}

/// Median edge length of the triangles (mm).
pub fn median_edge(mesh: &TubeMesh, tris: &[u32]) -> f64 {
    let mut l: Vec<f64> = tris
        .iter()
        .step_by((tris.len() / 20_000).max(1))
        .flat_map(|&t| {
            let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.vertices[i as usize]);
            [(b - a).norm(), (c - b).norm(), (a - c).norm()]
        })
        .collect();
    if l.is_empty() {
        return 0.0;
    }
    let k = l.len() / 2;
    *l.select_nth_unstable_by(k, f64::total_cmp).1
}

/// One band of the geodesic distance from the start end.
#[derive(Debug, Clone, Copy)]
pub struct Band {
    /// Centroid of its vertices (mm).
    pub centroid: Point3,
    /// Its vertices.
    pub vertices: usize,
    /// Its connected rings holding at least a tenth of its vertices.
    pub pieces: usize,
}

/// Level sets of the geodesic (edge-path) distance from a set of vertices.
#[derive(Debug, Clone)]
pub struct LevelSets {
    /// Distance of each mesh vertex (mm; infinite off the surface).
    pub distance: Vec<f64>,
    /// Bands `[k w, (k + 1) w)`, `w` the width.
    pub bands: Vec<Band>,
}

/// Vertices whose distances differ by less than this many band widths
/// (dimensionless) lie at one distance: rounding apart (single-precision
/// coordinates give about 1e-6 of the band width).
const ONE_DISTANCE_BANDS: f64 = 1e-3;

/// Each mesh vertex's neighbours along the edges of `tris` (repeats kept).
fn adjacency(mesh: &TubeMesh, tris: &[u32]) -> Vec<Vec<u32>> {
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertices.len()];
    for &t in tris {
        let v = mesh.triangles[t as usize];
        for k in 0..3 {
            adj[v[k] as usize].push(v[(k + 1) % 3]);
            adj[v[(k + 1) % 3] as usize].push(v[k]);
        }
    }
    adj
}

/// The rings of a swept export (mm, mesh frame): when the vertices of
/// `tris` one edge, two edges, ... away from the loop `start` each number
/// as many as `start`, lie in a plane (within `flat_mm` RMS) and the last
/// of them is the loop `finish`, the exporter wrote the tube as flat rings
/// joined by strips, and these are its rings: the centroid of each, from
/// `start`'s to `finish`'s. `None` for any other mesh. Its rings are the
/// exporter's samples of the tube's axis, however far apart (a coil in
/// rings 3 tube radii apart, where the level sets of the distance along its
/// surface shear across its turn).
pub fn swept_rings(
    mesh: &TubeMesh,
    tris: &[u32],
    [start, finish]: [&[u32]; 2],
    flat_mm: f64,
) -> Option<Vec<Point3>> {
    let adj = adjacency(mesh, tris);
    let mut seen = vec![false; mesh.vertices.len()];
    let mut layer: Vec<u32> = start.to_vec();
    layer.iter().for_each(|&v| seen[v as usize] = true);
    let mut rings = Vec::new();
    while !layer.is_empty() {
        if layer.len() != start.len() {
            return None;
        }
        let pts: Vec<Point3> = layer.iter().map(|&v| mesh.vertices[v as usize]).collect();
        let (centroid, normal, _) = fit_plane(&pts)?;
        if plane_rms(&pts, &centroid, &normal) > flat_mm {
            return None;
        }
        rings.push(centroid);
        let mut next = Vec::new();
        for &v in &layer {
            for &w in &adj[v as usize] {
                if !std::mem::replace(&mut seen[w as usize], true) {
                    next.push(w);
                }
            }
        }
        if next.is_empty() {
            let last: std::collections::HashSet<u32> = layer.iter().copied().collect();
            return (rings.len() > 2 && finish.iter().all(|v| last.contains(v))).then_some(rings);
        }
        layer = next;
    }
    None
}

/// Dijkstra over the edges of `tris` from `sources`, then bands of `width` mm.
pub fn level_sets(mesh: &TubeMesh, tris: &[u32], sources: &[u32], width: f64) -> LevelSets {
    let n = mesh.vertices.len();
    let adj = adjacency(mesh, tris);
    let mut dist = vec![f64::INFINITY; n];
    let mut heap = BinaryHeap::new();
    for &s in sources {
        dist[s as usize] = 0.0;
        heap.push(Reverse((0u64, s)));
    }
    while let Some(Reverse((bits, v))) = heap.pop() {
        let d = f64::from_bits(bits);
        if d > dist[v as usize] {
            continue;
        }
        for &w in &adj[v as usize] {
            let nd = d + (mesh.vertices[w as usize] - mesh.vertices[v as usize]).norm();
            if nd < dist[w as usize] {
                dist[w as usize] = nd;
                // Non-negative f64 bits order as the values.
                heap.push(Reverse((nd.to_bits(), w)));
            }
        }
    }
    let width = width.max(1e-6);
    let band_of = |d: f64| (d.is_finite()).then(|| (d / width) as usize);
    let count = dist
        .iter()
        .filter_map(|&d| band_of(d))
        .max()
        .map_or(0, |k| k + 1);
    let mut sum = vec![crate::math::Vector3::zeros(); count];
    let mut num = vec![0usize; count];
    for (v, &d) in dist.iter().enumerate() {
        if let Some(k) = band_of(d) {
            sum[k] += mesh.vertices[v].coords;
            num[k] += 1;
        }
    }
    let mut uf = UnionFind::new(n);
    for (v, list) in adj.iter().enumerate() {
        for &w in list {
            if band_of(dist[v]).is_some() && band_of(dist[v]) == band_of(dist[w as usize]) {
                uf.union(v as u32, w);
            }
        }
    }
    let mut sizes: HashMap<u32, usize> = HashMap::new();
    for (v, &d) in dist.iter().enumerate() {
        if band_of(d).is_some() {
            *sizes.entry(uf.find(v as u32)).or_default() += 1;
        }
    }
    let mut pieces = vec![0usize; count];
    for (&root, &size) in &sizes {
        let k = band_of(dist[root as usize]).expect("on the surface");
        if size * 10 >= num[k] && size >= 3 {
            pieces[k] += 1;
        }
    }
    // A band whose vertices all lie at one distance holds only a ring of
    // vertices on its far boundary, split between two bands by rounding (a
    // flat step joining two radii, written in single precision): one ring.
    let mut spread = vec![(f64::INFINITY, f64::NEG_INFINITY); count];
    for &d in &dist {
        if let Some(k) = band_of(d) {
            spread[k] = (spread[k].0.min(d), spread[k].1.max(d));
        }
    }
    for (p, (lo, hi)) in pieces.iter_mut().zip(spread) {
        if hi - lo < ONE_DISTANCE_BANDS * width {
            *p = (*p).min(1);
        }
    }
    let bands = (0..count)
        .map(|k| Band {
            centroid: Point3::from(sum[k] / num[k].max(1) as f64),
            vertices: num[k],
            pieces: pieces[k],
        })
        .collect();
    LevelSets {
        distance: dist,
        bands,
    }
}
