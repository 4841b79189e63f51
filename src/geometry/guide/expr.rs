//! Expression guide curves `x(t), y(t), z(t)` and scalar expressions of `t`
//! with analytic derivatives (parsed and differentiated by the `exmex` crate).

use super::GuideCurve;
use crate::geometry::GeometryError;
use crate::math::{Point3, Vector3};
use exmex::prelude::*;
use exmex::Differentiate;
use std::collections::BTreeMap;

/// Longest expression text accepted (characters); longer input is refused
/// before parsing.
pub const MAX_EXPRESSION_LEN: usize = 4096;
/// Most variables (the parameter plus named constants) one expression may use.
const MAX_VARS: usize = 16;
/// Deepest nesting of parentheses accepted: the symbolic derivatives recurse
/// once per level (400 nested `sin(` overflowed the stack).
pub const MAX_EXPRESSION_NESTING: usize = 32;
/// Most tokens (numbers, names, operators) in one expression. Each operator
/// on the way from the top of the expression to a use of the parameter can
/// copy what lies below it when differentiated: 3000 unary minus signs took
/// 15 s, a chain of 24 divisions by `t` 5 GB.
pub const MAX_EXPRESSION_TOKENS: usize = 256;
/// Most uses of the parameter in one expression: each use adds a term to the
/// derivatives (a product of 60 factors of `t` took 3 GB to differentiate
/// three times).
pub const MAX_PARAMETER_USES: usize = 24;
/// Work bound of one differentiation: the next derivative is computed only
/// if the current one's characters × tokens stay below this (its size is at
/// most about that product), else the expression is refused as too complex.
const DERIVATIVE_WORK_LIMIT: usize = 1 << 20;
/// Longest derivative text kept (characters).
const MAX_DERIVATIVE_LEN: usize = 1 << 16;

/// The shape of an expression's text: deepest parenthesis nesting, tokens,
/// and uses of the parameter (identifiers: a letter or `_`, then letters,
/// digits or `_`; numbers count as one token).
#[derive(Debug, Clone, Copy)]
struct Shape {
    nesting: usize,
    tokens: usize,
    uses: usize,
}

fn shape(text: &str, param: &str) -> Shape {
    let mut out = Shape {
        nesting: 0,
        tokens: 0,
        uses: 0,
    };
    let mut depth = 0usize;
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        if c.is_whitespace() {
            continue;
        }
        out.tokens += 1;
        match c {
            '(' => {
                depth += 1;
                out.nesting = out.nesting.max(depth);
            }
            ')' => depth = depth.saturating_sub(1),
            c if c.is_alphanumeric() || c == '_' || c == '.' => {
                let mut end = i + c.len_utf8();
                while let Some(&(j, d)) = chars.peek() {
                    if !(d.is_alphanumeric() || d == '_' || d == '.') {
                        break;
                    }
                    end = j + d.len_utf8();
                    chars.next();
                }
                if &text[i..end] == param {
                    out.uses += 1;
                }
            }
            _ => {}
        }
    }
    out
}

/// Stack of the thread that differentiates: the derivatives are built by
/// recursion as deep as the expression (within the limits above, several MiB
/// in a debug build; more than a 2 MiB test or worker thread has).
const DIFFERENTIATION_STACK_BYTES: usize = 64 << 20;

/// `[f, f', f'', f''']` with respect to variable `k`, computed on a thread
/// with a stack of [`DIFFERENTIATION_STACK_BYTES`]; refuses an expression whose
/// next derivative would exceed the work bound.
fn derivatives(f: FlatEx<f64>, k: usize, param: &str) -> Result<Vec<FlatEx<f64>>, String> {
    let run = move || -> Result<Vec<FlatEx<f64>>, String> {
        let mut chain = vec![f];
        for order in 1..=3 {
            let last = chain.last().cloned().expect("chain starts non-empty");
            let size = last.unparse().len();
            let work = size.saturating_mul(shape(last.unparse(), param).tokens);
            if work > DERIVATIVE_WORK_LIMIT {
                return Err(format!(
                    "too complex to differentiate {order} times: derivative {} has {size} \
                     characters (characters x tokens = {work}, the limit is {DERIVATIVE_WORK_LIMIT})",
                    order - 1
                ));
            }
            let d = last
                .partial(k)
                .map_err(|e| format!("cannot differentiate: {e}"))?;
            chain.push(d);
        }
        let size = chain[3].unparse().len();
        if size > MAX_DERIVATIVE_LEN {
            return Err(format!(
                "too complex: its third derivative has {size} characters; the limit is {MAX_DERIVATIVE_LEN}"
            ));
        }
        Ok(chain)
    };
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("waam-expression-derivatives".into())
            .stack_size(DIFFERENTIATION_STACK_BYTES)
            .spawn_scoped(scope, run)
            .map_err(|e| format!("cannot start the differentiation thread: {e}"))?
            .join()
            .map_err(|_| "the expression library failed while differentiating".to_string())?
    })
}

/// A scalar expression of one parameter (`t` by default) and named constants,
/// with its first three derivatives computed symbolically once, at parse time.
///
/// Syntax: `+ - * / ^`, parentheses, `sin cos tan asin acos atan sinh cosh tanh
/// exp ln log10 sqrt cbrt abs`, constants `PI`, `π`, `E`, `TAU`; e.g.
/// `"5 + cos(8*PI*t/40)"`.
#[derive(Clone)]
pub struct Expression {
    text: String,
    /// `[f, f', f'', f''']`.
    chain: Vec<FlatEx<f64>>,
    /// Index of the parameter among the expression's variables, if it appears.
    slot: Option<usize>,
    /// Values of all variables, constants filled in, parameter slot zero.
    template: Vec<f64>,
}

impl std::fmt::Debug for Expression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("Expression").field(&self.text).finish()
    }
}

impl Expression {
    /// Parses `text` as a function of `param` (e.g. `"t"`), with the named
    /// `constants` substituted by value.
    ///
    /// # Errors
    /// [`GeometryError::Expression`] when the text is too long, nests too deep,
    /// has too many tokens or uses of the parameter (the limits are
    /// [`MAX_EXPRESSION_LEN`], [`MAX_EXPRESSION_NESTING`],
    /// [`MAX_EXPRESSION_TOKENS`], [`MAX_PARAMETER_USES`]), does not parse, uses
    /// an unknown variable or function, or its derivatives would grow too large
    /// to compute (each message says which, with the limit).
    pub fn parse(
        text: &str,
        param: &str,
        constants: &BTreeMap<String, f64>,
    ) -> Result<Self, GeometryError> {
        let err = |reason: String| GeometryError::Expression {
            text: text.to_string(),
            reason,
        };
        if text.len() > MAX_EXPRESSION_LEN {
            return Err(err(format!(
                "expression is {} characters long; the limit is {MAX_EXPRESSION_LEN}",
                text.len()
            )));
        }
        if text.trim().is_empty() {
            return Err(err("expression is empty".into()));
        }
        let sh = shape(text, param);
        if sh.nesting > MAX_EXPRESSION_NESTING {
            return Err(err(format!(
                "parentheses nest {} deep; the limit is {MAX_EXPRESSION_NESTING}",
                sh.nesting
            )));
        }
        if sh.tokens > MAX_EXPRESSION_TOKENS {
            return Err(err(format!(
                "{} tokens (numbers, names, operators); the limit is {MAX_EXPRESSION_TOKENS}",
                sh.tokens
            )));
        }
        if sh.uses > MAX_PARAMETER_USES {
            return Err(err(format!(
                "uses `{param}` {} times; the limit is {MAX_PARAMETER_USES}",
                sh.uses
            )));
        }
        let f = exmex::parse::<f64>(text).map_err(|e| err(e.to_string()))?;
        let names: Vec<String> = f.var_names().to_vec();
        if names.len() > MAX_VARS {
            return Err(err(format!(
                "uses {} variables; the limit is {MAX_VARS}",
                names.len()
            )));
        }
        let mut template = vec![0.0; names.len()];
        let mut slot = None;
        for (i, name) in names.iter().enumerate() {
            if name == param {
                slot = Some(i);
            } else if let Some(v) = constants.get(name) {
                template[i] = *v;
            } else {
                let known: Vec<&str> = constants.keys().map(String::as_str).collect();
                return Err(err(format!(
                    "unknown variable `{name}` (the parameter is `{param}`; constants defined: [{}])",
                    known.join(", ")
                )));
            }
        }
        let chain = match slot {
            Some(k) => derivatives(f, k, param).map_err(err)?,
            None => vec![f],
        };
        Ok(Self {
            text: text.to_string(),
            chain,
            slot,
            template,
        })
    }

    /// Whether the expression uses its parameter (else it is a constant).
    pub fn depends_on_param(&self) -> bool {
        self.slot.is_some()
    }

    /// The source text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The `order`-th derivative (0..=3) at parameter value `t`. Returns NaN
    /// if the expression is undefined there (callers validate).
    pub fn eval_derivative(&self, order: usize, t: f64) -> f64 {
        let Some(k) = self.slot else {
            return if order == 0 { self.eval_const() } else { 0.0 };
        };
        let mut buf = [0.0; MAX_VARS];
        let vars = &mut buf[..self.template.len()];
        vars.copy_from_slice(&self.template);
        vars[k] = t;
        self.chain[order].eval(vars).unwrap_or(f64::NAN)
    }

    fn eval_const(&self) -> f64 {
        self.chain[0].eval(&self.template).unwrap_or(f64::NAN)
    }

    /// Value at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        self.eval_derivative(0, t)
    }
}

/// Guide curve given by three expressions `x(t), y(t), z(t)` (part frame, mm).
#[derive(Debug, Clone)]
pub struct ExprCurve {
    /// `x(t)` (mm).
    pub x: Expression,
    /// `y(t)` (mm).
    pub y: Expression,
    /// `z(t)` (mm).
    pub z: Expression,
}

impl ExprCurve {
    fn deriv(&self, order: usize, t: f64) -> Vector3 {
        Vector3::new(
            self.x.eval_derivative(order, t),
            self.y.eval_derivative(order, t),
            self.z.eval_derivative(order, t),
        )
    }
}

impl GuideCurve for ExprCurve {
    fn point(&self, t: f64) -> Point3 {
        Point3::from(self.deriv(0, t))
    }
    fn d1(&self, t: f64) -> Vector3 {
        self.deriv(1, t)
    }
    fn d2(&self, t: f64) -> Vector3 {
        self.deriv(2, t)
    }
    fn d3(&self, t: f64) -> Vector3 {
        self.deriv(3, t)
    }
}
