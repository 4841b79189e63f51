//! Profile radius law `A(t)` of a tube (mm): constant, one expression, or
//! piecewise expressions [SPEC §2; thesis eq. 2.2, 2.8, 3.19].

use super::guide::Expression;

/// One piece of a piecewise radius law: applies for `t` up to `until`
/// (inclusive) and above the previous piece's bound.
#[derive(Debug, Clone)]
pub struct ProfilePiece {
    /// Upper bound of `t` for this piece (guide parameter units); the last
    /// piece extends to +∞.
    pub until: f64,
    /// `A(t)` on this piece (mm).
    pub radius: Expression,
}

/// The profile radius `A(t)` (mm) as a function of the guide parameter.
#[derive(Debug, Clone)]
pub enum ProfileLaw {
    /// Constant radius (mm).
    Constant(f64),
    /// `A(t)` given by one expression (mm).
    Expression(Expression),
    /// Piecewise expressions, ordered by `until`.
    Piecewise(Vec<ProfilePiece>),
}

impl ProfileLaw {
    fn select(&self, t: f64) -> Option<&Expression> {
        match self {
            ProfileLaw::Constant(_) => None,
            ProfileLaw::Expression(e) => Some(e),
            ProfileLaw::Piecewise(pieces) => {
                // No pieces: no radius (NaN), which `Tube::new` refuses.
                let i = pieces
                    .partition_point(|p| p.until < t)
                    .min(pieces.len().saturating_sub(1));
                pieces.get(i).map(|p| &p.radius)
            }
        }
    }

    /// `A(t)` (mm). NaN where an expression is undefined (the tube validates).
    pub fn radius(&self, t: f64) -> f64 {
        match self {
            ProfileLaw::Constant(a) => *a,
            _ => self.select(t).map_or(f64::NAN, |e| e.eval(t)),
        }
    }

    /// `dA/dt` (mm per parameter unit).
    pub fn radius_derivative(&self, t: f64) -> f64 {
        match self {
            ProfileLaw::Constant(_) => 0.0,
            _ => self.select(t).map_or(f64::NAN, |e| e.eval_derivative(1, t)),
        }
    }
}
