//! An independent tube-mesh generator for the fit tests: closed-form
//! centre lines parameterised by arc length, a rotation-minimising frame by
//! double reflection (Wang et al. 2008) on the sampled centre line, circles of
//! the given radius in the normal planes, quads split in two triangles; a
//! seeded Gaussian noise (xorshift64* + Box–Muller); binary and ASCII STL
//! written by hand. Nothing here uses the library's tube code.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use waam_slicer::math::{Point3, Vector3};

/// A truth tube: centre line `c(s)` (s = arc length, mm) and radius `rho(s)`.
pub struct Truth {
    pub name: &'static str,
    pub length: f64,
    pub centre: Box<dyn Fn(f64) -> Point3 + Sync>,
    pub radius: Box<dyn Fn(f64) -> f64 + Sync>,
}

/// Arc of radius `r` turning from direction `d0` toward `toward` (unit, ⟂ d0).
fn arc(p0: Point3, d0: Vector3, toward: Vector3, r: f64, s: f64) -> Point3 {
    let a = s / r;
    p0 + d0 * (r * a.sin()) + toward * (r * (1.0 - a.cos()))
}

pub fn straight() -> Truth {
    Truth {
        name: "straight pipe",
        length: 80.0,
        centre: Box::new(|s| Point3::new(5.0, -3.0, s)),
        radius: Box::new(|_| 15.0),
    }
}

pub fn torus() -> Truth {
    let r = 50.0;
    Truth {
        name: "torus section",
        length: r * FRAC_PI_2,
        centre: Box::new(move |s| arc(Point3::origin(), Vector3::z(), Vector3::x(), r, s)),
        radius: Box::new(|_| 12.0),
    }
}

/// Straight `leg`, a 90° bend of radius `r` toward +x, straight `leg` along +x.
pub fn elbow_centre(leg: f64, r: f64) -> impl Fn(f64) -> Point3 + Sync {
    move |s| {
        let bend = r * FRAC_PI_2;
        if s <= leg {
            Point3::new(0.0, 0.0, s)
        } else if s <= leg + bend {
            arc(
                Point3::new(0.0, 0.0, leg),
                Vector3::z(),
                Vector3::x(),
                r,
                s - leg,
            )
        } else {
            Point3::new(r + (s - leg - bend), 0.0, leg + r)
        }
    }
}

/// The elbow's centre line (legs of 20 mm, a 90 degree bend of radius 40)
/// with the mid-surface radius 11 of a 2 mm wall about it (skins 10 and
/// 12: [`flanged_wall`] with `half` 1).
pub fn elbow_wall() -> Truth {
    Truth {
        name: "elbow wall",
        length: 40.0 + 40.0 * FRAC_PI_2,
        centre: Box::new(elbow_centre(20.0, 40.0)),
        radius: Box::new(|_| 11.0),
    }
}

pub fn elbow() -> Truth {
    let (leg, r) = (20.0, 40.0);
    Truth {
        name: "elbow",
        length: 2.0 * leg + r * FRAC_PI_2,
        centre: Box::new(elbow_centre(leg, r)),
        radius: Box::new(|_| 12.0),
    }
}

pub fn s_bend() -> Truth {
    let (leg, r) = (15.0, 45.0);
    let bend = r * FRAC_PI_2;
    Truth {
        name: "S-bend",
        length: 2.0 * leg + 2.0 * bend,
        centre: Box::new(move |s| {
            let p1 = Point3::new(0.0, 0.0, leg);
            let p2 = Point3::new(r, 0.0, leg + r);
            if s <= leg {
                Point3::new(0.0, 0.0, s)
            } else if s <= leg + bend {
                arc(p1, Vector3::z(), Vector3::x(), r, s - leg)
            } else if s <= leg + 2.0 * bend {
                arc(p2, Vector3::x(), Vector3::z(), r, s - leg - bend)
            } else {
                Point3::new(2.0 * r, 0.0, leg + 2.0 * r + (s - leg - 2.0 * bend))
            }
        }),
        radius: Box::new(|_| 10.0),
    }
}

pub fn helix() -> Truth {
    let (a, b) = (40.0, 60.0 / TAU); // 60 mm rise per turn
    let k = (a * a + b * b).sqrt();
    Truth {
        name: "helix",
        length: 0.75 * TAU * k,
        centre: Box::new(move |s| {
            let th = s / k;
            Point3::new(a * th.cos(), a * th.sin(), b * th)
        }),
        radius: Box::new(|_| 8.0),
    }
}

/// A coil of `coil_r` mm about Z rising `pitch` mm a turn over `turns`
/// turns, tube radius `r` mm (VesselMeshGenerator's helical mode).
pub fn coil(coil_r: f64, pitch: f64, turns: f64, r: f64) -> Truth {
    let b = pitch / TAU;
    let k = (coil_r * coil_r + b * b).sqrt();
    Truth {
        name: "coil",
        length: turns * TAU * k,
        centre: Box::new(move |s| {
            let th = s / k;
            Point3::new(coil_r * th.cos(), coil_r * th.sin(), b * th)
        }),
        radius: Box::new(move |_| r),
    }
}

pub fn swelling() -> Truth {
    let len = 90.0;
    Truth {
        name: "swelling radius",
        length: len,
        centre: Box::new(|s| Point3::new(0.0, 0.0, s)),
        radius: Box::new(move |s| 12.0 + 3.0 * (PI * s / len).sin() - 1.5 * (TAU * s / len).sin()),
    }
}

pub fn all() -> Vec<Truth> {
    vec![straight(), torus(), elbow(), s_bend(), helix(), swelling()]
}

/// Seeded Gaussian noise: xorshift64* and Box–Muller.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn gauss(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
}

/// Rings along the centre line: positions, tangents and RMF normals.
pub fn frames(t: &Truth, rings: usize) -> Vec<(f64, Point3, Vector3, Vector3)> {
    let tangent = |s: f64| {
        let h = 1e-5;
        ((t.centre)(s + h) - (t.centre)(s - h)).normalize()
    };
    let mut out = Vec::with_capacity(rings + 1);
    let t0 = tangent(0.0);
    let pick = if t0.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let mut r = (pick - t0 * pick.dot(&t0)).normalize();
    let mut prev = ((t.centre)(0.0), t0);
    for i in 0..=rings {
        let s = t.length * i as f64 / rings as f64;
        let (x, ti) = ((t.centre)(s), tangent(s));
        if i > 0 {
            // Double reflection.
            let v1 = x - prev.0;
            let c1 = v1.dot(&v1);
            let rl = r - v1 * (2.0 / c1 * v1.dot(&r));
            let tl = prev.1 - v1 * (2.0 / c1 * v1.dot(&prev.1));
            let v2 = ti - tl;
            let c2 = v2.dot(&v2);
            r = if c2 > 0.0 {
                rl - v2 * (2.0 / c2 * v2.dot(&rl))
            } else {
                rl
            };
            r = (r - ti * r.dot(&ti)).normalize();
        }
        out.push((s, x, ti, r));
        prev = (x, ti);
    }
    out
}

/// A mesh of the tube's surface with edges about `h` mm, `noise_mm` of
/// Gaussian noise on each coordinate; `offset` is added to the radius (a skin).
pub fn mesh(
    t: &Truth,
    h: f64,
    noise_mm: f64,
    offset: f64,
    seed: u64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let rmax = (0..=100)
        .map(|i| (t.radius)(t.length * i as f64 / 100.0))
        .fold(0.0, f64::max)
        + offset;
    let around = ((TAU * rmax / h).ceil() as usize).max(8);
    mesh_around(t, h, around, noise_mm, offset, seed)
}

/// As [`mesh`] with `around` points on each ring.
pub fn mesh_around(
    t: &Truth,
    h: f64,
    around: usize,
    noise_mm: f64,
    offset: f64,
    seed: u64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let rings = (t.length / h).ceil() as usize;
    let mut rng = Rng::new(seed);
    let mut v = Vec::new();
    for (i, (s, x, ti, n)) in frames(t, rings).into_iter().enumerate() {
        let b = ti.cross(&n);
        let rho = (t.radius)(s) + offset;
        // Stagger every other ring by half a step: well-shaped triangles.
        let shift = if i % 2 == 1 { 0.5 } else { 0.0 };
        for j in 0..around {
            let a = TAU * (j as f64 + shift) / around as f64;
            let mut p = x + (n * a.cos() + b * a.sin()) * rho;
            if noise_mm > 0.0 {
                p += Vector3::new(rng.gauss(), rng.gauss(), rng.gauss()) * noise_mm;
            }
            v.push(p);
        }
    }
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    let mut f = Vec::new();
    for i in 0..rings {
        for j in 0..around {
            f.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
            f.push([id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    (v, f)
}

/// The tube `t` (rings about `h` mm apart, `around` points each) with a
/// lug on one side between arc lengths `s0` and `s1`: the points within
/// `half_deg` degrees of the rings' first frame normal stand `height` mm
/// out from the wall (its sides slope over one ring).
pub fn lugged(
    t: &Truth,
    h: f64,
    around: usize,
    (s0, s1): (f64, f64),
    half_deg: f64,
    height: f64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let rings = (t.length / h).ceil() as usize;
    let all: Vec<Vec<Point3>> = frames(t, rings)
        .into_iter()
        .map(|(s, x, ti, n)| {
            let b = ti.cross(&n);
            ring_of(around, |a| {
                let on = (s0..=s1).contains(&s) && a.min(TAU - a).to_degrees() <= half_deg + 1e-9;
                let rho = (t.radius)(s) + if on { height } else { 0.0 };
                x + (n * a.cos() + b * a.sin()) * rho
            })
        })
        .collect();
    lofted(&all)
}

/// Binary STL bytes (f32), written by hand.
pub fn binary_stl(v: &[Point3], f: &[[u32; 3]]) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out.extend((f.len() as u32).to_le_bytes());
    for tri in f {
        let p = tri.map(|i| v[i as usize]);
        let n = (p[1] - p[0]).cross(&(p[2] - p[0])).normalize();
        for x in [n.x, n.y, n.z] {
            out.extend((x as f32).to_le_bytes());
        }
        for q in p {
            for x in [q.x, q.y, q.z] {
                out.extend((x as f32).to_le_bytes());
            }
        }
        out.extend([0u8, 0u8]);
    }
    out
}

/// ASCII STL text, written by hand.
pub fn ascii_stl(v: &[Point3], f: &[[u32; 3]]) -> String {
    let mut s = String::from("solid tube\n");
    for tri in f {
        let p = tri.map(|i| v[i as usize]);
        let n = (p[1] - p[0]).cross(&(p[2] - p[0])).normalize();
        s += &format!("facet normal {} {} {}\n outer loop\n", n.x, n.y, n.z);
        for q in p {
            s += &format!("  vertex {} {} {}\n", q.x, q.y, q.z);
        }
        s += " endloop\nendfacet\n";
    }
    s + "endsolid tube\n"
}

/// A UV sphere of radius `r` (closed blob).
pub fn sphere(r: f64, n: usize) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut v = vec![Point3::new(0.0, 0.0, -r)];
    for i in 1..n {
        let phi = -FRAC_PI_2 + PI * i as f64 / n as f64;
        for j in 0..2 * n {
            let th = PI * j as f64 / n as f64;
            v.push(Point3::new(
                r * phi.cos() * th.cos(),
                r * phi.cos() * th.sin(),
                r * phi.sin(),
            ));
        }
    }
    v.push(Point3::new(0.0, 0.0, r));
    let m = 2 * n;
    let ring = |i: usize, j: usize| (1 + (i - 1) * m + j % m) as u32;
    let top = (v.len() - 1) as u32;
    let mut f = Vec::new();
    for j in 0..m {
        f.push([0, ring(1, j + 1), ring(1, j)]);
        f.push([top, ring(n - 1, j), ring(n - 1, j + 1)]);
    }
    for i in 1..n - 1 {
        for j in 0..m {
            f.push([ring(i, j), ring(i, j + 1), ring(i + 1, j)]);
            f.push([ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)]);
        }
    }
    (v, f)
}

/// A Y (pair of pants): a trunk of radius `r` up to z = `h`, whose top ring
/// splits into two D-shaped halves (sharing the diameter along y) that
/// morph into two branches of radius `r / 2` centred at x = ±`r`, rising
/// `h` more. One manifold surface with three open ends.
pub fn y_branch(r: f64, h: f64, n: usize) -> (Vec<Point3>, Vec<[u32; 3]>) {
    // Ring of 4n points: the trunk's circle, angle from +y through -x (left
    // half: 0..=2n) and back through +x (right half: 2n..4n).
    let m = 4 * n;
    let layers = 20;
    let mut v = Vec::new();
    let mut f = Vec::new();
    let circle = |k: usize| {
        let a = FRAC_PI_2 + TAU * k as f64 / m as f64;
        (r * a.cos(), r * a.sin())
    };
    for i in 0..=layers {
        let z = h * i as f64 / layers as f64;
        for k in 0..m {
            let (x, y) = circle(k);
            v.push(Point3::new(x, y, z));
        }
    }
    let trunk = |i: usize, k: usize| (i * m + k % m) as u32;
    for i in 0..layers {
        for k in 0..m {
            f.push([trunk(i, k), trunk(i, k + 1), trunk(i + 1, k)]);
            f.push([trunk(i, k + 1), trunk(i + 1, k + 1), trunk(i + 1, k)]);
        }
    }
    // The septum: points on the diameter x = 0 from y = -r to y = r
    // (excluding the ends, which are trunk points k = 0 and k = 2n).
    let septum: Vec<u32> = (1..2 * n)
        .map(|j| {
            let y = -r + 2.0 * r * j as f64 / (2 * n) as f64;
            v.push(Point3::new(0.0, y, h));
            (v.len() - 1) as u32
        })
        .collect();
    for side in [-1.0_f64, 1.0] {
        // Base D ring of 4n points: half circle then the septum back.
        let mut base: Vec<u32> = Vec::new();
        if side < 0.0 {
            base.extend((0..=2 * n).map(|k| trunk(layers, k)));
            base.extend(septum.iter().copied()); // from y = -r up to +r
        } else {
            base.extend((2 * n..=4 * n).map(|k| trunk(layers, k)));
            base.extend(septum.iter().rev().copied());
        }
        let base_pts: Vec<Point3> = base.iter().map(|&i| v[i as usize]).collect();
        let mut prev = base.clone();
        let steps = 20;
        for i in 1..=steps {
            let s = i as f64 / steps as f64;
            let mut ring = Vec::new();
            for (k, p) in base_pts.iter().enumerate() {
                let a = TAU * k as f64 / m as f64 + if side < 0.0 { FRAC_PI_2 } else { -FRAC_PI_2 };
                let target = Point3::new(side * r + 0.5 * r * a.cos(), 0.5 * r * a.sin(), 2.0 * h);
                let q = p.coords * (1.0 - s) + target.coords * s;
                v.push(Point3::new(q.x, q.y, h + (2.0 * h - h) * s));
                ring.push((v.len() - 1) as u32);
            }
            for k in 0..m {
                let (a, b) = (prev[k], prev[(k + 1) % m]);
                let (c, d) = (ring[k], ring[(k + 1) % m]);
                f.push([a, b, c]);
                f.push([b, d, c]);
            }
            prev = ring;
        }
    }
    (v, f)
}

/// The mesh in metres: every coordinate divided by 1000, as many CAD tools export.
pub fn in_metres(v: &[Point3]) -> Vec<Point3> {
    v.iter().map(|p| p / 1000.0).collect()
}

/// An untidy export of `(v, f)`: the seam (the first vertex of every ring of
/// `around`) duplicated for the triangles that close the ring, a zero-area
/// triangle per ring, every third triangle's winding flipped, and a stray
/// right triangle of legs `side` and `2 side` at `stray`.
pub fn untidy(
    v: &[Point3],
    f: &[[u32; 3]],
    around: usize,
    stray: Point3,
    side: f64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut v = v.to_vec();
    let rings = v.len() / around;
    // Seam copies, nudged by far less than the weld tolerance.
    let copy: Vec<u32> = (0..rings)
        .map(|i| {
            v.push(v[i * around] + Vector3::new(1e-9, 0.0, 0.0));
            (v.len() - 1) as u32
        })
        .collect();
    let mut out = Vec::with_capacity(f.len() + rings + 1);
    for (k, t) in f.iter().enumerate() {
        // A triangle touching the ring's last point uses the seam's copy.
        let closes = t.iter().any(|&i| i as usize % around == around - 1);
        let mut t = t.map(|i| {
            if closes && i as usize % around == 0 {
                copy[i as usize / around]
            } else {
                i
            }
        });
        if k % 3 == 0 {
            t.swap(1, 2);
        }
        out.push(t);
    }
    for i in 0..rings.saturating_sub(1) {
        let a = (i * around) as u32;
        out.push([a, a, a + around as u32]);
    }
    let s = v.len() as u32;
    v.extend([
        stray,
        stray + Vector3::new(side, 0.0, 0.0),
        stray + Vector3::new(0.0, 2.0 * side, 0.0),
    ]);
    out.push([s, s + 1, s + 2]);
    (v, out)
}

/// A coarse export of the tube, as CAD tools write one: rings of vertices on
/// the true surface, as few as keep every facet within `chord_mm` of the
/// surface (checked at each stretch's middle, eight points around), so that
/// a straight leg is one stretch of long thin triangles and a bend a few;
/// as many points around as the same chord height allows (at least 8).
/// Returns the mesh and its points around.
pub fn coarse(t: &Truth, chord_mm: f64) -> (Vec<Point3>, Vec<[u32; 3]>, usize) {
    let rmax = (0..=100)
        .map(|i| (t.radius)(t.length * i as f64 / 100.0))
        .fold(0.0, f64::max);
    let around = ((PI / (1.0 - chord_mm / rmax).acos()).ceil() as usize).max(8);
    let m = (t.length / 0.1).ceil() as usize;
    let fr = frames(t, m);
    let point = |i: usize, a: f64| {
        let (s, x, ti, n) = fr[i];
        x + (n * a.cos() + ti.cross(&n) * a.sin()) * (t.radius)(s)
    };
    let within = |i0: usize, i1: usize| {
        (0..8).all(|k| {
            let a = TAU * k as f64 / 8.0;
            let mid = Point3::from((point(i0, a).coords + point(i1, a).coords) / 2.0);
            (mid - point((i0 + i1) / 2, a)).norm() <= chord_mm
        })
    };
    let mut rings = vec![0];
    for i in 2..=m {
        let last = rings[rings.len() - 1];
        if !within(last, i) && i - 1 > last {
            rings.push(i - 1);
        }
    }
    rings.push(m);
    let v: Vec<Point3> = rings
        .iter()
        .flat_map(|&i| (0..around).map(move |j| (i, TAU * j as f64 / around as f64)))
        .map(|(i, a)| point(i, a))
        .collect();
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    let mut f = Vec::new();
    for i in 0..rings.len() - 1 {
        for j in 0..around {
            f.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
            f.push([id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    (v, f, around)
}

/// A mesh lofted through `rings` of the same number of points: consecutive
/// rings joined by two triangles per quad (a ring of another shape, or two
/// rings in one plane, make a flat face between them).
pub fn lofted(rings: &[Vec<Point3>]) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let around = rings[0].len();
    let v: Vec<Point3> = rings.iter().flatten().copied().collect();
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    let mut f = Vec::new();
    for i in 0..rings.len() - 1 {
        for j in 0..around {
            f.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
            f.push([id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    (v, f)
}

/// A ring of `around` points about the z axis: at angle `a` (rad from +x),
/// the point `at(a)`.
pub fn ring_of(around: usize, at: impl Fn(f64) -> Point3) -> Vec<Point3> {
    (0..around)
        .map(|j| at(TAU * j as f64 / around as f64))
        .collect()
}

/// A circle of radius `r` at height `z` about the z axis.
pub fn circle_z(around: usize, r: f64, z: f64) -> Vec<Point3> {
    ring_of(around, |a| Point3::new(r * a.cos(), r * a.sin(), z))
}

/// Rings of a straight pipe of radius `r` about the z axis from `z0` to
/// `z1`, about `h` mm apart (both ends included).
pub fn pipe_rings(around: usize, r: f64, z0: f64, z1: f64, h: f64) -> Vec<Vec<Point3>> {
    let n = ((z1 - z0) / h).ceil().max(1.0) as usize;
    (0..=n)
        .map(|i| circle_z(around, r, z0 + (z1 - z0) * i as f64 / n as f64))
        .collect()
}

/// Closes the ring of `around` vertices starting at `first` with a flat
/// fan to a new vertex at `centre` (a flat cap).
pub fn fan_cap(
    v: &mut Vec<Point3>,
    f: &mut Vec<[u32; 3]>,
    first: u32,
    around: u32,
    centre: Point3,
) {
    v.push(centre);
    let c = v.len() as u32 - 1;
    for j in 0..around {
        f.push([first + j, first + (j + 1) % around, c]);
    }
}

/// A straight pipe of radius `r` about the z axis from z = 0 to the plane
/// z = `len` + tan(`tilt_deg`) x: its top end cut obliquely (each line of
/// the surface along z ends on the plane; the surface stays the cylinder).
pub fn oblique_pipe(
    r: f64,
    len: f64,
    tilt_deg: f64,
    around: usize,
    h: f64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let k = tilt_deg.to_radians().tan();
    let n = (len / h).ceil() as usize;
    let rings: Vec<Vec<Point3>> = (0..=n)
        .map(|i| {
            let u = i as f64 / n as f64;
            ring_of(around, |a| {
                let (x, y) = (r * a.cos(), r * a.sin());
                Point3::new(x, y, u * (len + k * x))
            })
        })
        .collect();
    lofted(&rings)
}

/// A straight pipe of radius `r` about the z axis from z = 0 whose top end
/// is a saddle: the rim at z = `len` + `amp` cos(2 a) (a pipe cut to meet
/// another pipe): not a plane.
pub fn saddle_pipe(
    r: f64,
    len: f64,
    amp: f64,
    around: usize,
    h: f64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let n = (len / h).ceil() as usize;
    let rings: Vec<Vec<Point3>> = (0..=n)
        .map(|i| {
            let u = i as f64 / n as f64;
            ring_of(around, |a| {
                Point3::new(r * a.cos(), r * a.sin(), u * (len + amp * (2.0 * a).cos()))
            })
        })
        .collect();
    lofted(&rings)
}

/// A straight pipe of radius `r` about the z axis from z = 0 (open) to
/// z = `len`, closed there by a hemispherical dome (rings every `h` mm of
/// arc, then a fan to the pole): a closed end that is not flat.
pub fn domed_pipe(r: f64, len: f64, around: usize, h: f64) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut rings = pipe_rings(around, r, 0.0, len, h);
    let m = ((FRAC_PI_2 * r / h).ceil() as usize).max(2);
    for i in 1..m {
        let phi = FRAC_PI_2 * i as f64 / m as f64;
        rings.push(circle_z(around, r * phi.cos(), len + r * phi.sin()));
    }
    let (mut v, mut f) = lofted(&rings);
    let last = (v.len() - around) as u32;
    fan_cap(
        &mut v,
        &mut f,
        last,
        around as u32,
        Point3::new(0.0, 0.0, len + r),
    );
    (v, f)
}

/// A straight pipe of radius `r` about the z axis from z = 0 to `len`
/// (rings about `h` apart, `around` points each) with a collar of outer
/// radius `outer` from z = `z0` to `z1`: flat rings at z0 and z1 join the
/// pipe to the collar's cylinder (a flange when short and wide).
pub fn collared_pipe(
    r: f64,
    len: f64,
    outer: f64,
    z0: f64,
    z1: f64,
    around: usize,
    h: f64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut rings = pipe_rings(around, r, 0.0, z0, h);
    rings.extend(pipe_rings(around, outer, z0, z1, h));
    rings.extend(pipe_rings(around, r, z1, len, h));
    lofted(&rings)
}

/// A straight tube about the z axis from z = 0 to `length` (mm) of radius
/// `r` (mm).
pub fn along_z(length: f64, r: f64) -> Truth {
    Truth {
        name: "straight along z",
        length,
        centre: Box::new(|s| Point3::new(0.0, 0.0, s)),
        radius: Box::new(move |_| r),
    }
}

/// A pipe wall exported as a solid along the tube `t` (its radius the
/// wall's mid-surface): watertight, two skins, the outer at `t`'s radius
/// plus `half` (mm), the bore at it minus `half`, except on each of
/// `flanges` (from arc length `s0` to `s1`, radius: sorted, apart, mm),
/// where the outer skin stands out to the flange's radius, joined by flat
/// steps; flat ring faces close both ends, from the bore to the outer skin
/// there. Rings about 1 mm apart in the normal planes (a flange's edges on
/// the nearest), `around` points each; the start's outer ring is written
/// twice (the fit welds it).
pub fn flanged_wall(
    t: &Truth,
    half: f64,
    flanges: &[(f64, f64, f64)],
    around: usize,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let rings = t.length.ceil() as usize;
    let fr = frames(t, rings);
    let ring = |i: usize, rho: f64| {
        let (_, x, ti, n) = fr[i];
        let b = ti.cross(&n);
        ring_of(around, |a| x + (n * a.cos() + b * a.sin()) * rho)
    };
    let at = |s: f64| (s / t.length * rings as f64).round() as usize;
    let flanges: Vec<(usize, usize, f64)> = flanges
        .iter()
        .map(|&(s0, s1, r)| (at(s0), at(s1), r))
        .collect();
    let mut out = Vec::new();
    for (i, frame) in fr.iter().enumerate() {
        let tube = (t.radius)(frame.0) + half;
        match flanges.iter().find(|f| (f.0..=f.1).contains(&i)) {
            Some(f) if f.0 == i && i > 0 => out.extend([ring(i, tube), ring(i, f.2)]),
            Some(f) if f.1 == i && i < rings => out.extend([ring(i, f.2), ring(i, tube)]),
            Some(f) => out.push(ring(i, f.2)),
            None => out.push(ring(i, tube)),
        }
    }
    let start = out[0].clone();
    out.extend(
        (0..=rings)
            .rev()
            .map(|i| ring(i, (t.radius)(fr[i].0) - half)),
    );
    out.push(start);
    lofted(&out)
}

/// A straight pipe of radius `r` about the z axis from z = 0 to `len` with
/// a lug on one side from z = `z0` to `z1`: the wall's points within
/// `half_deg` degrees of the +x axis stand out at radius `outer` there,
/// joined to the pipe by flat steps at z0 and z1 (the rings' points
/// outside the lug coincide across the steps; the fit welds them).
pub fn lugged_pipe(
    r: f64,
    len: f64,
    outer: f64,
    (z0, z1): (f64, f64),
    half_deg: f64,
    around: usize,
    h: f64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let lug = |z: f64| {
        ring_of(around, move |a| {
            let off = a.min(TAU - a).to_degrees() <= half_deg + 1e-9;
            let rho = if off { outer } else { r };
            Point3::new(rho * a.cos(), rho * a.sin(), z)
        })
    };
    let mut rings = pipe_rings(around, r, 0.0, z0, h);
    let n = ((z1 - z0) / h).ceil().max(1.0) as usize;
    rings.extend((0..=n).map(|i| lug(z0 + (z1 - z0) * i as f64 / n as f64)));
    rings.extend(pipe_rings(around, r, z1, len, h));
    lofted(&rings)
}

/// A straight pipe of radius `r` about the z axis from z = 0 to `len` whose
/// first `height` mm are a square block of side `side` (its open bottom a
/// square, a flat step at z = `height` from the square to the pipe).
pub fn blocked_pipe(
    r: f64,
    len: f64,
    side: f64,
    height: f64,
    around: usize,
    h: f64,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let a = 0.5 * side;
    let n = (height / h).ceil() as usize;
    let mut rings: Vec<Vec<Point3>> = (0..=n)
        .map(|i| {
            let z = height * i as f64 / n as f64;
            ring_of(around, |t| {
                let s = a / t.cos().abs().max(t.sin().abs());
                Point3::new(s * t.cos(), s * t.sin(), z)
            })
        })
        .collect();
    rings.extend(pipe_rings(around, r, height, len, h));
    lofted(&rings)
}

/// A closed box from `lo` to `hi` (12 triangles): a printing tab.
pub fn block(lo: Point3, hi: Point3) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let v: Vec<Point3> = (0..8)
        .map(|k| {
            Point3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let f = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (v, f)
}

/// `(v, f)` with `(v2, f2)` added as another piece.
pub fn join(
    (mut v, mut f): (Vec<Point3>, Vec<[u32; 3]>),
    (v2, f2): (Vec<Point3>, Vec<[u32; 3]>),
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let base = v.len() as u32;
    v.extend(v2);
    f.extend(f2.into_iter().map(|t| t.map(|i| i + base)));
    (v, f)
}

/// A straight pipe of radius `r` about the z axis from z = 0 to `len`
/// (rings 1 mm apart: `height` a whole number) inside a square sleeve of
/// side `side` from z = 0 to `height`, open at the bottom and joined to the
/// pipe at z = `height` by a flat step: a stop block around a bore, with
/// three open ends (the bore's two and the sleeve's).
pub fn sleeved_pipe(
    r: f64,
    len: f64,
    side: f64,
    height: f64,
    around: usize,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let (v, mut f) = lofted(&pipe_rings(around, r, 0.0, len, 1.0));
    let a = 0.5 * side;
    let sleeve: Vec<Vec<Point3>> = (0..=height as usize)
        .map(|i| {
            ring_of(around, |t| {
                let s = a / t.cos().abs().max(t.sin().abs());
                Point3::new(s * t.cos(), s * t.sin(), i as f64)
            })
        })
        .collect();
    let top = (v.len() + (sleeve.len() - 1) * around) as u32;
    let pipe_ring = (height as usize * around) as u32;
    let (mut v, f2) = join((v, Vec::new()), lofted(&sleeve));
    f.extend(f2);
    let n = around as u32;
    for j in 0..n {
        let (o0, o1) = (top + j, top + (j + 1) % n);
        let (i0, i1) = (pipe_ring + j, pipe_ring + (j + 1) % n);
        f.push([o0, o1, i0]);
        f.push([o1, i1, i0]);
    }
    v.shrink_to_fit();
    (v, f)
}

/// A coarse export of a bend: straight legs of `leg` mm (one stretch each),
/// a 90° bend of centre-line radius `bend_r` toward +x in `segments`
/// stretches, tube radius `r`, `around` points per ring (rings on the true
/// surface, normal to the centre line). With `central`, as an exporter that
/// takes each ring's plane from its neighbours' centres writes it
/// (pipe_network.py's sweep): a ring's normal is the direction from the
/// centre before it to the centre after it (from the one beside it at the
/// ends), so the rings where a leg joins the bend lean toward the bend, by
/// more the longer the leg.
pub fn coarse_bend(
    r: f64,
    bend_r: f64,
    leg: f64,
    segments: usize,
    around: usize,
    central: bool,
) -> (Truth, Vec<Point3>, Vec<[u32; 3]>) {
    let truth = Truth {
        name: "coarse bend",
        length: 2.0 * leg + bend_r * FRAC_PI_2,
        centre: Box::new(elbow_centre(leg, bend_r)),
        radius: Box::new(move |_| r),
    };
    let bend = truth.length - 2.0 * leg;
    let mut at: Vec<f64> = vec![0.0];
    at.extend((0..=segments).map(|i| leg + bend * i as f64 / segments as f64));
    at.push(2.0 * leg + bend);
    let m = (truth.length / 0.05).ceil() as usize;
    let fr = frames(&truth, m);
    let frame = |s: f64| fr[((s / truth.length) * m as f64).round() as usize];
    let rings: Vec<Vec<Point3>> = (0..at.len())
        .map(|i| {
            let (_, x, mut ti, mut n) = frame(at[i]);
            if central {
                let (before, after) = (
                    frame(at[i.saturating_sub(1)]).1,
                    frame(at[(i + 1).min(at.len() - 1)]).1,
                );
                ti = (after - before).normalize();
                n = (n - ti * n.dot(&ti)).normalize();
            }
            let b = ti.cross(&n);
            (0..around)
                .map(|j| {
                    let a = TAU * j as f64 / around as f64;
                    x + (n * a.cos() + b * a.sin()) * r
                })
                .collect()
        })
        .collect();
    let (v, f) = lofted(&rings);
    (truth, v, f)
}

/// A sine tube: centre line x = `a` sin(2 pi z / `l`), y = 0, z from 0 to
/// `l` (mm), radius `r` (mm); the arc length from a table 0.01 mm fine.
pub fn sine(a: f64, l: f64, r: f64) -> Truth {
    let n = (l / 0.01).ceil() as usize;
    let at = move |z: f64| Point3::new(a * (TAU * z / l).sin(), 0.0, z);
    let mut table = vec![(0.0, 0.0)];
    for i in 1..=n {
        let (z0, z1) = (l * (i - 1) as f64 / n as f64, l * i as f64 / n as f64);
        let s = table[i - 1].0 + (at(z1) - at(z0)).norm();
        table.push((s, z1));
    }
    let length = table[n].0;
    Truth {
        name: "sine tube",
        length,
        centre: Box::new(move |s| {
            let i = table.partition_point(|x| x.0 < s).clamp(1, n);
            let ((s0, z0), (s1, z1)) = (table[i - 1], table[i]);
            at(z0 + (z1 - z0) * ((s - s0) / (s1 - s0)).clamp(0.0, 1.0))
        }),
        radius: Box::new(move |_| r),
    }
}

/// The sine tube of [`sine`] as an exporter that frames each ring by its
/// tangent crossed with z writes it (ib565/colabdesign-stl's sweep):
/// `rings` rings evenly in z, `around` points each, the tangent by central
/// differences. Where x' changes sign (the crests) the frame turns by half
/// a turn between two rings, and the band of triangles between them twists
/// through the axis.
pub fn flipped_sine(
    a: f64,
    l: f64,
    r: f64,
    rings: usize,
    around: usize,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let c: Vec<Point3> = (0..rings)
        .map(|i| {
            let z = l * i as f64 / (rings - 1) as f64;
            Point3::new(a * (TAU * z / l).sin(), 0.0, z)
        })
        .collect();
    let mut v = Vec::new();
    for i in 0..rings {
        let t = (c[(i + 1).min(rings - 1)] - c[i.saturating_sub(1)]).normalize();
        let n = t.cross(&Vector3::z()).normalize();
        let b = t.cross(&n);
        v.extend((0..around).map(|j| {
            let u = TAU * j as f64 / around as f64;
            c[i] + (n * u.cos() + b * u.sin()) * r
        }));
    }
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    let mut f = Vec::new();
    for i in 0..rings - 1 {
        for j in 0..around {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, f)
}
