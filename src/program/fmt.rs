//! `Display` newtypes that own the number formatting of every emitter, so
//! that the same value prints the same way everywhere and no `-0.000`
//! reaches a controller.

use std::fmt;

/// A number with a fixed count of decimals, right-aligned in `width`
/// characters (0: no padding). Negative zero after rounding prints as zero.
#[derive(Debug, Clone, Copy)]
pub struct Fixed {
    /// The value.
    pub value: f64,
    /// Decimals.
    pub decimals: usize,
    /// Minimum width (characters).
    pub width: usize,
}

impl Fixed {
    /// `value` with `decimals` decimals, unpadded.
    pub fn new(value: f64, decimals: usize) -> Self {
        Self {
            value,
            decimals,
            width: 0,
        }
    }

    /// `value` with `decimals` decimals, right-aligned in `width` characters.
    pub fn padded(value: f64, decimals: usize, width: usize) -> Self {
        Self {
            value,
            decimals,
            width,
        }
    }
}

impl fmt::Display for Fixed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let scale = 10f64.powi(self.decimals as i32);
        let mut v = self.value;
        if (v * scale).round() == 0.0 {
            v = 0.0;
        }
        let mut buf = [0u8; 24];
        match fixed_digits(v, self.decimals, &mut buf) {
            Some(text) => write!(f, "{text:>w$}", w = self.width),
            None => write!(f, "{:>w$.d$}", v, w = self.width, d = self.decimals),
        }
    }
}

/// `v` with `decimals` decimals as `format!("{v:.decimals$}")` writes it,
/// from integers, or `None` where that cannot be decided cheaply (then the
/// standard formatter runs): the exact `|v|·10^decimals` lies within half an
/// ulp of its rounded product `x`, so rounding `x` to the nearest integer
/// gives the correctly rounded digits unless `x` is within an ulp of a
/// half-integer (ties and near-ties go to the standard formatter).
fn fixed_digits(v: f64, decimals: usize, buf: &mut [u8; 24]) -> Option<&str> {
    if decimals > 9 || !v.is_finite() {
        return None;
    }
    let scale = 10f64.powi(decimals as i32); // exact up to 10^22
    let x = v.abs() * scale;
    if !(x < 1e15) {
        return None;
    }
    let whole = x.floor();
    let frac = x - whole; // exact: the bits of x below the units
    if (frac - 0.5).abs() <= f64::EPSILON * x.max(1.0) {
        return None;
    }
    let n = whole as u64 + u64::from(frac > 0.5);
    let first = crate::util::decimal::scaled_digits(buf, n, v.is_sign_negative(), decimals);
    std::str::from_utf8(&buf[first..]).ok()
}

/// FANUC position lengths: mm, 3 decimals, width 9 (`X =  1045.747  mm`).
#[derive(Debug, Clone, Copy)]
pub struct FanucMm(pub f64);

impl fmt::Display for FanucMm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Fixed::padded(self.0, 3, 9).fmt(f)
    }
}

/// FANUC angles in degrees, 4 decimals (the controller's programming
/// resolution, SPEC §6.1), width 10.
#[derive(Debug, Clone, Copy)]
pub struct FanucDeg(pub f64);

impl fmt::Display for FanucDeg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Fixed::padded(self.0, 4, 10).fmt(f)
    }
}

/// Lengths in other controllers' files and in CSV: mm, 4 decimals, unpadded.
#[derive(Debug, Clone, Copy)]
pub struct Mm(pub f64);

impl fmt::Display for Mm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Fixed::new(self.0, 4).fmt(f)
    }
}

/// Angles in other controllers' files and in CSV: degrees, 5 decimals, unpadded.
#[derive(Debug, Clone, Copy)]
pub struct Deg(pub f64);

impl fmt::Display for Deg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Fixed::new(self.0, 5).fmt(f)
    }
}

/// An angle (rad) as [`Deg`] prints it, back in rad: configuration bits
/// (KUKA Status/Turn, ABB `confdata`) are taken from this value, so that a
/// joint at `-1e-12` rad, written `0.00000`, does not set a "negative" bit
/// that would send the controller to the other side of zero (a full turn
/// away for KUKA A4/A6).
pub fn as_printed_rad(v: f64) -> f64 {
    let scale = 1e5;
    let d = (v.to_degrees() * scale).round() / scale;
    if d == 0.0 {
        0.0
    } else {
        d.to_radians()
    }
}

/// `v` rounded down to `decimals` decimals (a speed written this way is
/// never faster than `v`; `1e-9` of slack keeps an exact value exact).
pub fn floor_to(v: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (v * scale + 1e-9).floor() / scale
}

/// `v` rounded up to `decimals` decimals (a segment time written this way
/// is never shorter than `v`; `1e-9` of slack keeps an exact value exact).
pub fn ceil_to(v: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (v * scale - 1e-9).ceil() / scale
}

/// Unitless components (direction cosines, quaternions): 7 decimals.
#[derive(Debug, Clone, Copy)]
pub struct Unitless(pub f64);

impl fmt::Display for Unitless {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Fixed::new(self.0, 7).fmt(f)
    }
}

/// Comment text for a controller file: ASCII only (KRL, RAPID and TP
/// editors choke on other bytes). Common symbols are spelled out (`§` →
/// `sec.`, `°` → ` deg`, `·` → `*`, dashes → `-`, `×` → `x`), accented
/// Latin letters lose their accent, control characters become spaces and
/// anything else `?`.
pub fn ascii_comment(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            ' '..='~' => out.push(c),
            '§' => out.push_str("sec."),
            '°' => out.push_str(" deg"),
            '·' | '×' => out.push(if c == '×' { 'x' } else { '*' }),
            '–' | '—' | '−' => out.push('-'),
            '‘' | '’' => out.push('\''),
            '“' | '”' => out.push('"'),
            'à' | 'á' | 'â' | 'ä' | 'ã' => out.push('a'),
            'é' | 'è' | 'ê' | 'ë' => out.push('e'),
            'î' | 'ï' | 'í' => out.push('i'),
            'ô' | 'ö' | 'ó' => out.push('o'),
            'ù' | 'û' | 'ü' | 'ú' => out.push('u'),
            'ç' => out.push('c'),
            'ñ' => out.push('n'),
            'ß' => out.push_str("ss"),
            'À' | 'Â' | 'Ä' => out.push('A'),
            'É' | 'È' | 'Ê' => out.push('E'),
            'Ô' | 'Ö' => out.push('O'),
            'Ü' => out.push('U'),
            'Ç' => out.push('C'),
            c if c.is_control() => out.push(' '),
            _ => out.push('?'),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_are_ascii() {
        assert_eq!(
            ascii_comment("ROBOWAM part carried, D_R of §3.3"),
            "ROBOWAM part carried, D_R of sec.3.3"
        );
        assert_eq!(
            ascii_comment("45° · 2 – Stäubli\tπ"),
            "45 deg * 2 - Staubli ?"
        );
        assert!(ascii_comment("dépôt porté ✓").is_ascii());
    }

    #[test]
    fn integer_digits_are_the_standard_formatters() {
        // random magnitudes and signs, values on the 10^-d grid and half
        // way between (ties and near-ties), every decimal count used
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut checked = 0;
        for k in 0..400_000u64 {
            let r = next();
            let mantissa = (r >> 11) as f64 / (1u64 << 53) as f64;
            let exponent = (next() % 24) as i32 - 8;
            let mut v = mantissa * 10f64.powi(exponent);
            let d = (k % 6) as usize;
            match k % 4 {
                1 => v = (v * 10f64.powi(d as i32)).round() / 10f64.powi(d as i32),
                2 => v = ((v * 10f64.powi(d as i32)).floor() + 0.5) / 10f64.powi(d as i32),
                _ => {}
            }
            if next() % 2 == 0 {
                v = -v;
            }
            let mut buf = [0u8; 24];
            if let Some(t) = fixed_digits(v, d, &mut buf) {
                assert_eq!(t, format!("{v:.d$}"), "{v:e}, {d} decimals");
                checked += 1;
            }
        }
        // exact ties such as 1.03125 at 4 decimals are left to the standard formatter
        assert!(fixed_digits(1.03125, 4, &mut [0u8; 24]).is_none());
        assert!(checked > 200_000, "{checked}");
    }

    #[test]
    fn no_negative_zero_and_padding() {
        assert_eq!(Fixed::new(-0.00004, 3).to_string(), "0.000");
        assert_eq!(FanucMm(-630.155).to_string(), " -630.155");
        assert_eq!(FanucDeg(1.0).to_string(), "    1.0000");
        assert_eq!(Deg(-0.0).to_string(), "0.00000");
    }
}
