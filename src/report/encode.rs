//! The page's data encodings: base64 of little-endian typed arrays and a
//! minimal JSON writer (strings escaped so that nothing in them can close
//! the `<script>` element they are embedded in).

use std::fmt::Write as _;

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648 §4, with `=` padding) of `bytes`.
pub fn base64(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        let sextet = |k: u32| char::from(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize]);
        out.push(sextet(0));
        out.push(sextet(1));
        out.push(if chunk.len() > 1 { sextet(2) } else { '=' });
        out.push(if chunk.len() > 2 { sextet(3) } else { '=' });
    }
    out
}

/// Base64 of `values` as a little-endian `Float32Array`.
pub fn f32s(values: &[f32]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    base64(&bytes)
}

/// Base64 of `values` as a little-endian `Uint32Array`.
pub fn u32s(values: &[u32]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    base64(&bytes)
}

/// Base64 of `values` as an `Int8Array`.
pub fn i8s(values: &[i8]) -> String {
    let bytes: Vec<u8> = values.iter().map(|v| v.to_le_bytes()[0]).collect();
    base64(&bytes)
}

/// A unit-vector component (−1..1) as a signed byte (±127).
pub fn unit_i8(v: f64) -> i8 {
    (v.clamp(-1.0, 1.0) * 127.0).round() as i8
}

/// A JSON string literal of `s`; `<`, `>` and `&` are written as `\u00XX`
/// so that `</script>` or `<!--` in a name cannot end the data element.
pub fn json_str(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '<' | '>' | '&' | '\u{2028}' | '\u{2029}' => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A JSON number; a non-finite value is `null` (JSON has no NaN).
pub fn json_num(v: f64) -> String {
    if v.is_finite() {
        // `{}` of an f64 is the shortest text that reads back to the same value.
        format!("{v}")
    } else {
        "null".into()
    }
}

/// A JSON array of numbers.
pub fn json_nums(vs: &[f64]) -> String {
    let items: Vec<String> = vs.iter().map(|v| json_num(*v)).collect();
    format!("[{}]", items.join(","))
}

/// Escapes `s` for HTML text or a double-quoted attribute.
pub fn html_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A JSON object built key by key, in insertion order.
#[derive(Debug, Default)]
pub struct JsonObject {
    text: String,
}

impl JsonObject {
    /// An empty object.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `key` with an already-encoded JSON `value`.
    pub fn raw(&mut self, key: &str, value: impl AsRef<str>) -> &mut Self {
        if !self.text.is_empty() {
            self.text.push(',');
        }
        self.text.push_str(&json_str(key));
        self.text.push(':');
        self.text.push_str(value.as_ref());
        self
    }

    /// Adds a string.
    pub fn str(&mut self, key: &str, value: &str) -> &mut Self {
        self.raw(key, json_str(value))
    }

    /// Adds a number (`null` if not finite).
    pub fn num(&mut self, key: &str, value: f64) -> &mut Self {
        self.raw(key, json_num(value))
    }

    /// The object's text.
    pub fn finish(&self) -> String {
        format!("{{{}}}", self.text)
    }
}
