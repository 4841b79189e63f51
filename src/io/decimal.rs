//! Fast fixed-point decimal text for the CSV writers: `x` with `d` digits
//! after the point, by integer arithmetic instead of the standard library's
//! exact (and much slower) float formatting. The written value is within
//! half a unit of the last digit of `x` plus one part in 2^52 of `x`; a value
//! too large for 18 significant digits, or not finite, falls back to the
//! standard formatting (which writes `NaN`/`inf` as they are: the writers
//! never give it one).

use std::io::Write;

const POW10: [u64; 16] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
    1_000_000_000,
    10_000_000_000,
    100_000_000_000,
    1_000_000_000_000,
    10_000_000_000_000,
    100_000_000_000_000,
    1_000_000_000_000_000,
];

/// Appends `x` with `decimals` (≤ 15) digits after the point to `out`
/// (`-` for negative values other than those that round to zero).
pub fn push_fixed(out: &mut Vec<u8>, x: f64, decimals: usize) {
    let d = decimals.min(15);
    let scale = POW10[d] as f64;
    let scaled = (x.abs() * scale).round();
    if !(scaled.is_finite() && scaled < 9.0e18) {
        let _ = write!(out, "{x:.d$}");
        return;
    }
    let n = scaled as u64;
    if x.is_sign_negative() && n != 0 {
        out.push(b'-');
    }
    let (int, frac) = (n / POW10[d], n % POW10[d]);
    push_u64(out, int);
    if d > 0 {
        out.push(b'.');
        let mut digits = [b'0'; 15];
        let mut f = frac;
        for k in (0..d).rev() {
            digits[k] = b'0' + (f % 10) as u8;
            f /= 10;
        }
        out.extend_from_slice(&digits[..d]);
    }
}

/// Appends the decimal digits of `n` to `out`.
pub fn push_u64(out: &mut Vec<u8>, mut n: u64) {
    let mut buf = [0u8; 20];
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    out.extend_from_slice(&buf[i..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(x: f64, d: usize) -> String {
        let mut v = Vec::new();
        push_fixed(&mut v, x, d);
        String::from_utf8(v).unwrap()
    }

    #[test]
    fn agrees_with_the_standard_formatting_within_half_a_last_digit() {
        // a deterministic spread of magnitudes and signs
        let mut x = 0.123_456_789_f64;
        for i in 0..20_000 {
            x = (x * 7.3 + 0.911).fract()
                * 10f64.powi(i % 9 - 3)
                * if i % 3 == 0 { -1.0 } else { 1.0 };
            for d in [0, 3, 6, 9, 12] {
                let ours = text(x, d);
                let std = format!("{x:.d$}");
                if ours != std {
                    let (a, b): (f64, f64) = (ours.parse().unwrap(), std.parse().unwrap());
                    let unit = 10f64.powi(-(d as i32));
                    // the scaled value is exact to one part in 2^53 of x
                    let slack = x.abs() * 2.3e-16;
                    assert!(
                        (a - b).abs() <= unit * 1.000_001 + slack
                            && (a - x).abs() <= 0.5 * unit * 1.000_001 + slack,
                        "{x} at {d}: ours {ours}, std {std}"
                    );
                }
            }
        }
    }

    #[test]
    fn exact_cases_zero_signs_and_fallbacks() {
        assert_eq!(text(0.0, 3), "0.000");
        assert_eq!(text(-0.0, 3), "0.000");
        assert_eq!(text(-0.0004, 3), "0.000");
        assert_eq!(text(-1.5, 0), "-2");
        assert_eq!(text(1045.747, 6), "1045.747000");
        assert_eq!(text(-630.155, 3), "-630.155");
        assert_eq!(text(0.5, 12), "0.500000000000");
        assert_eq!(text(1e300, 2), format!("{:.2}", 1e300));
        let mut v = Vec::new();
        push_u64(&mut v, 0);
        push_u64(&mut v, 18_446_744_073_709_551_615);
        assert_eq!(v, b"018446744073709551615");
    }
}
