//! Orientation conventions, both ways, gimbal lock included. SPEC §6.3,
//! thesis eq. 3.2–3.3 and appendix B.
//!
//! * Bryant `R_X R_Y R_Z` (thesis): intrinsic X, Y', Z'': `Rx(R_X)·Ry(R_Y)·Rz(R_Z)`.
//! * FANUC `W P R`: rotations about the fixed X, Y, Z axes: `Rz(R)·Ry(P)·Rx(W)`.
//!   (Eq. 3.2 prints this product with the Z angle named `w`; the controller
//!   data of table 3.7 follow FANUC's naming, used here.)
//! * KUKA `A B C`: `Rz(A)·Ry(B)·Rx(C)`.
//! * ABB: unit quaternion `[q1, q2, q3, q4] = [w, x, y, z]`.
//!
//! All angles in rad inside; `*_deg` constructors and accessors at the edges.
//! At gimbal lock (middle angle ±90°) only a sum or difference of the outer
//! angles is determined: the conversion returns the representative with the
//! *last-applied* outer angle (`R_Z`, `W`, `C`) set to zero.

use serde::{Deserialize, Serialize};

use crate::math::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use crate::robot::kinematics::{rot_x, rot_y, rot_z};

/// Middle-angle cosine below which a decomposition is treated as gimbal-locked.
const GIMBAL_COS: f64 = 1e-12;

fn rx(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    rot_x(s, c)
}
fn ry(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    rot_y(s, c)
}
fn rz(a: f64) -> Matrix3 {
    let (s, c) = a.sin_cos();
    rot_z(s, c)
}

fn rotation(m: Matrix3) -> Rotation3 {
    Rotation3::from_matrix_unchecked(m)
}

/// Bryant angles (rad): `R = Rx(rx)·Ry(ry)·Rz(rz)` [thesis eq. 3.3, B.1].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bryant {
    /// `R_X` (rad).
    pub rx: f64,
    /// `R_Y` (rad), in `[-π/2, π/2]` when obtained from a rotation.
    pub ry: f64,
    /// `R_Z` (rad).
    pub rz: f64,
}

impl Bryant {
    /// The rotation `Rx(rx)·Ry(ry)·Rz(rz)`.
    pub fn to_rotation(&self) -> Rotation3 {
        rotation(rx(self.rx) * ry(self.ry) * rz(self.rz))
    }

    /// Decomposes a rotation [thesis eq. B.4, C.4]; at gimbal lock
    /// (`R_Y = ±π/2`) returns `R_Z = 0`.
    pub fn from_rotation(r: &Rotation3) -> Self {
        let m = r.matrix();
        // m = [[cY cZ, -cY sZ, sY], [.., .., -sX cY], [.., .., cX cY]]
        let s_y = m[(0, 2)].clamp(-1.0, 1.0);
        let c_y = m[(0, 0)].hypot(m[(0, 1)]);
        if c_y > GIMBAL_COS {
            Self {
                rx: (-m[(1, 2)]).atan2(m[(2, 2)]),
                ry: s_y.atan2(c_y),
                rz: (-m[(0, 1)]).atan2(m[(0, 0)]),
            }
        } else {
            // R_Y = +π/2: m[1,0] = sin(R_X + R_Z), m[1,1] = cos(R_X + R_Z);
            // R_Y = -π/2: m[1,0] = sin(R_Z - R_X), m[1,1] = cos(R_Z - R_X). R_Z = 0.
            Self {
                rx: (s_y.signum() * m[(1, 0)]).atan2(m[(1, 1)]),
                ry: s_y.signum() * std::f64::consts::FRAC_PI_2,
                rz: 0.0,
            }
        }
    }

    /// From degrees.
    pub fn from_degrees(rx_deg: f64, ry_deg: f64, rz_deg: f64) -> Self {
        Self {
            rx: rx_deg.to_radians(),
            ry: ry_deg.to_radians(),
            rz: rz_deg.to_radians(),
        }
    }

    /// `[R_X, R_Y, R_Z]` in degrees.
    pub fn to_degrees(&self) -> [f64; 3] {
        [
            self.rx.to_degrees(),
            self.ry.to_degrees(),
            self.rz.to_degrees(),
        ]
    }
}

/// FANUC `W P R` (rad): `R = Rz(r)·Ry(p)·Rx(w)`, rotations about the fixed X, Y, Z axes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FanucWpr {
    /// `W`, about fixed X (rad).
    pub w: f64,
    /// `P`, about fixed Y (rad), in `[-π/2, π/2]` when obtained from a rotation.
    pub p: f64,
    /// `R`, about fixed Z (rad).
    pub r: f64,
}

/// Decomposition `Rz(a)·Ry(b)·Rx(c)` shared by FANUC and KUKA; at gimbal lock `c = 0`.
fn zyx_from_rotation(m: &Matrix3) -> (f64, f64, f64) {
    // m = [[cA cB, .., ..], [sA cB, .., ..], [-sB, cB sC, cB cC]]
    let s_b = (-m[(2, 0)]).clamp(-1.0, 1.0);
    let c_b = m[(2, 1)].hypot(m[(2, 2)]);
    if c_b > GIMBAL_COS {
        (
            m[(1, 0)].atan2(m[(0, 0)]),
            s_b.atan2(c_b),
            m[(2, 1)].atan2(m[(2, 2)]),
        )
    } else {
        // B = ±π/2, C = 0: m[0,1] = -sA, m[1,1] = cA
        (
            (-m[(0, 1)]).atan2(m[(1, 1)]),
            s_b.signum() * std::f64::consts::FRAC_PI_2,
            0.0,
        )
    }
}

impl FanucWpr {
    /// The rotation `Rz(r)·Ry(p)·Rx(w)`.
    pub fn to_rotation(&self) -> Rotation3 {
        rotation(rz(self.r) * ry(self.p) * rx(self.w))
    }

    /// Decomposes a rotation [thesis eq. B.5 with FANUC's naming]; at gimbal
    /// lock (`P = ±90°`) returns `W = 0`.
    pub fn from_rotation(r: &Rotation3) -> Self {
        let (a, b, c) = zyx_from_rotation(r.matrix());
        Self { w: c, p: b, r: a }
    }

    /// From degrees (`W`, `P`, `R` as on the teach pendant).
    pub fn from_degrees(w_deg: f64, p_deg: f64, r_deg: f64) -> Self {
        Self {
            w: w_deg.to_radians(),
            p: p_deg.to_radians(),
            r: r_deg.to_radians(),
        }
    }

    /// `[W, P, R]` in degrees.
    pub fn to_degrees(&self) -> [f64; 3] {
        [
            self.w.to_degrees(),
            self.p.to_degrees(),
            self.r.to_degrees(),
        ]
    }
}

/// KUKA `A B C` (rad): `R = Rz(a)·Ry(b)·Rx(c)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KukaAbc {
    /// `A`, about Z (rad).
    pub a: f64,
    /// `B`, about Y' (rad), in `[-π/2, π/2]` when obtained from a rotation.
    pub b: f64,
    /// `C`, about X'' (rad).
    pub c: f64,
}

impl KukaAbc {
    /// The rotation `Rz(a)·Ry(b)·Rx(c)`.
    pub fn to_rotation(&self) -> Rotation3 {
        rotation(rz(self.a) * ry(self.b) * rx(self.c))
    }

    /// Decomposes a rotation; at gimbal lock (`B = ±90°`) returns `C = 0`.
    pub fn from_rotation(r: &Rotation3) -> Self {
        let (a, b, c) = zyx_from_rotation(r.matrix());
        Self { a, b, c }
    }

    /// From degrees.
    pub fn from_degrees(a_deg: f64, b_deg: f64, c_deg: f64) -> Self {
        Self {
            a: a_deg.to_radians(),
            b: b_deg.to_radians(),
            c: c_deg.to_radians(),
        }
    }

    /// `[A, B, C]` in degrees.
    pub fn to_degrees(&self) -> [f64; 3] {
        [
            self.a.to_degrees(),
            self.b.to_degrees(),
            self.c.to_degrees(),
        ]
    }
}

/// ABB quaternion `[q1, q2, q3, q4] = [w, x, y, z]` of a rotation, with `q1 >= 0`.
pub fn abb_quaternion(r: &Rotation3) -> [f64; 4] {
    let q = UnitQuaternion::from_rotation_matrix(r);
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    [s * q.w, s * q.i, s * q.j, s * q.k]
}

/// Rotation of an ABB quaternion `[w, x, y, z]` (normalised here; a zero or
/// non-finite quaternion gives `None`).
pub fn rotation_from_abb_quaternion(q: [f64; 4]) -> Option<Rotation3> {
    let v = nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]);
    let n = v.norm();
    if !(n.is_finite() && n > 0.0) {
        return None;
    }
    Some(UnitQuaternion::from_quaternion(v).to_rotation_matrix())
}

/// A FANUC Cartesian position `[X, Y, Z, W, P, R]` (mm, rad) as a rigid transform.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FanucPose {
    /// Position (mm).
    pub xyz_mm: [f64; 3],
    /// Orientation.
    pub wpr: FanucWpr,
}

impl FanucPose {
    /// From the teach-pendant form `[X, Y, Z, W, P, R]` in mm and degrees.
    pub fn from_xyzwpr_deg(v: [f64; 6]) -> Self {
        Self {
            xyz_mm: [v[0], v[1], v[2]],
            wpr: FanucWpr::from_degrees(v[3], v[4], v[5]),
        }
    }

    /// The teach-pendant form `[X, Y, Z, W, P, R]` in mm and degrees.
    pub fn to_xyzwpr_deg(&self) -> [f64; 6] {
        let [w, p, r] = self.wpr.to_degrees();
        [self.xyz_mm[0], self.xyz_mm[1], self.xyz_mm[2], w, p, r]
    }

    /// The rigid transform `parent_from_frame` this position describes.
    pub fn to_isometry(&self) -> Isometry3 {
        Isometry3::from_parts(
            Translation3::from(Vector3::from(self.xyz_mm)),
            UnitQuaternion::from_rotation_matrix(&self.wpr.to_rotation()),
        )
    }

    /// The FANUC position of a rigid transform.
    pub fn from_isometry(iso: &Isometry3) -> Self {
        let t = iso.translation.vector;
        Self {
            xyz_mm: [t.x, t.y, t.z],
            wpr: FanucWpr::from_rotation(&iso.rotation.to_rotation_matrix()),
        }
    }
}
