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
    let mut buf = [0u8; 24];
    let first = scaled_digits(&mut buf, n, x.is_sign_negative() && n != 0, d);
    out.extend_from_slice(&buf[first..]);
}

/// Writes `n / 10^d` with `d` (≤ 15) digits after the point, `-` first when
/// `negative`, right-aligned at the end of `buf`; returns where it starts.
/// The one digit writer of the CSV writers ([`push_fixed`]) and the program
/// emitters' exact fixed-point numbers (`program::fmt`).
pub(crate) fn scaled_digits(buf: &mut [u8; 24], n: u64, negative: bool, d: usize) -> usize {
    let d = d.min(15);
    // The digits of n, right to left, two at a time, one slot left for the
    // point; at least d + 1 of them (leading zeros).
    let mut digits = [b'0'; 24];
    let count = write_digits(&mut digits, n).max(d + 1);
    let end = buf.len();
    let mut i = end;
    if d > 0 {
        buf[end - d..].copy_from_slice(&digits[digits.len() - d..]);
        buf[end - d - 1] = b'.';
        i = end - d - 1;
    }
    let int = count - d;
    buf[i - int..i].copy_from_slice(&digits[digits.len() - count..digits.len() - d]);
    i -= int;
    if negative {
        i -= 1;
        buf[i] = b'-';
    }
    i
}

/// "00" to "99".
const PAIRS: &[u8; 200] = b"\
0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// Writes the decimal digits of `n` at the end of `buf` (right-aligned) and
/// returns how many (at least 1); the rest of `buf` is left as it was.
fn write_digits(buf: &mut [u8; 24], mut n: u64) -> usize {
    let mut i = buf.len();
    while n >= 100 {
        let k = (n % 100) as usize * 2;
        n /= 100;
        i -= 2;
        buf[i..i + 2].copy_from_slice(&PAIRS[k..k + 2]);
    }
    if n >= 10 {
        let k = n as usize * 2;
        i -= 2;
        buf[i..i + 2].copy_from_slice(&PAIRS[k..k + 2]);
    } else {
        i -= 1;
        buf[i] = b'0' + n as u8;
    }
    buf.len() - i
}

/// Appends the decimal digits of `n` to `out`.
pub fn push_u64(out: &mut Vec<u8>, n: u64) {
    let mut buf = [0u8; 24];
    let count = write_digits(&mut buf, n);
    out.extend_from_slice(&buf[buf.len() - count..]);
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

    /// The digits as the first version wrote them, one at a time (integer
    /// part, point, `d` zero-padded fraction digits): the pair-at-a-time
    /// writer must give the same bytes.
    fn reference(x: f64, d: usize) -> String {
        let scaled = (x.abs() * POW10[d] as f64).round();
        if !(scaled.is_finite() && scaled < 9.0e18) {
            return format!("{x:.d$}");
        }
        let n = scaled as u64;
        let sign = if x.is_sign_negative() && n != 0 {
            "-"
        } else {
            ""
        };
        let (int, frac) = (n / POW10[d], n % POW10[d]);
        if d == 0 {
            format!("{sign}{int}")
        } else {
            format!("{sign}{int}.{frac:0d$}")
        }
    }

    #[test]
    fn same_bytes_as_digit_by_digit() {
        let mut x = 0.987_654_321_f64;
        for i in 0..20_000 {
            x = (x * 3.7 + 0.173).fract()
                * 10f64.powi(i % 15 - 5)
                * if i % 2 == 0 { -1.0 } else { 1.0 };
            for d in [0, 1, 2, 6, 9, 12, 15] {
                assert_eq!(text(x, d), reference(x, d), "{x} at {d}");
            }
        }
        for n in [0u64, 9, 10, 99, 100, 101, 999_999, u64::MAX] {
            let mut v = Vec::new();
            push_u64(&mut v, n);
            assert_eq!(String::from_utf8(v).unwrap(), n.to_string());
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
