//! Exact and fast conversion of `f64` to and from the text of trial files.
//!
//! [`push_f64`] appends exactly the text `format!("{v}")` gives (the shortest
//! digits that read back to the same `f64`, never an exponent: `0.0000001`,
//! `1`, `-0`, `1000000000000000000000`), with the digits from `ryu`
//! rearranged into that layout and no allocation beyond the output's growth.
//! [`parse_f64`] returns exactly what `str::parse::<f64>` returns for every
//! input, errors included: `fast-float2` reads the finite numbers and anything
//! else (infinities, NaN, malformed text) goes to the standard parser, so
//! messages built on its result do not change. Both are checked against the
//! standard library on a few hundred thousand values (bit patterns including
//! subnormals, integers, tiny and huge magnitudes) in this module's tests.

use std::fmt::Write as _;
use std::num::ParseFloatError;

/// Zeros appended in chunks (a `Display` of an `f64` has at most 324 of them).
const ZEROS: &str = "0000000000000000000000000000000000000000000000000000000000000000";

fn push_zeros(out: &mut String, mut n: usize) {
    while n > 0 {
        let k = n.min(ZEROS.len());
        out.push_str(&ZEROS[..k]);
        n -= k;
    }
}

/// Appends `v` to `out` exactly as `write!(out, "{v}")` would.
#[inline]
pub(crate) fn push_f64(out: &mut String, v: f64) {
    if !v.is_finite() || may_be_tie(v) {
        // "NaN", "inf", "-inf" (never written by the trial writers), and the
        // rare values where ryu and `{}` may pick different digits.
        let _ = write!(out, "{v}");
        return;
    }
    let mut buf = ryu::Buffer::new();
    let text = buf.format_finite(v);
    let digits_text = match text.strip_prefix('-') {
        Some(rest) => {
            out.push('-');
            rest
        }
        None => text,
    };
    let Some((mantissa, exponent)) = digits_text.split_once('e') else {
        // ryu writes "123.45", "0.00123" or "1200.0"; Display drops the ".0".
        out.push_str(digits_text.strip_suffix(".0").unwrap_or(digits_text));
        return;
    };
    // ryu writes "d" or "d.ddd", then "e" and a signed exponent of at most three digits.
    let (lead, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let (Some(exp), 1) = (small_exponent(exponent), lead.len()) else {
        // Not ryu's layout: let the standard library write it.
        out.truncate(out.len() - (text.len() - digits_text.len()));
        let _ = write!(out, "{v}");
        return;
    };
    // Digits before the decimal point in positional notation.
    let point = 1 + exp;
    if point <= 0 {
        out.push_str("0.");
        push_zeros(out, point.unsigned_abs() as usize);
        out.push_str(lead);
        out.push_str(frac);
    } else if point as usize > frac.len() {
        out.push_str(lead);
        out.push_str(frac);
        push_zeros(out, point as usize - 1 - frac.len());
    } else {
        // ryu uses an exponent only outside 1e-5..1e16, so this is not reached; exact anyway.
        let (int_part, frac_part) = frac.split_at(point as usize - 1);
        out.push_str(lead);
        out.push_str(int_part);
        out.push('.');
        out.push_str(frac_part);
    }
}

/// Whether `v` might lie exactly halfway between its two nearest shortest
/// decimal representations, where ryu rounds to an even last digit and `{}`
/// rounds up (1248961574693653.25: ryu `...653.2`, `{}` `...653.3`).
///
/// Such a tie at `n <= 17` digits means `v = (10 D + 5) 10^j` exactly, with
/// both `D 10^(j+1)` and `(D + 1) 10^(j+1)` reading back as `v`. Writing
/// `v = q 2^j'` with `q` odd: `10 D + 5` is odd times 5, so `j' = j`; both
/// neighbours read back only if the spacing of doubles at `v` is at least
/// `10^(j+1)`, and that spacing is at most `2^j`, so `j <= -2`; and
/// `2 D + 1 = 5^(-j-1) q` with `2 D + 1 < 2e17` gives `j >= -25`. Subnormals
/// (spacing `2^-1074`) cannot meet both. This test is that necessary
/// condition on the lowest set bit of `v`: false for nearly every value a
/// trial holds (times at 50 Hz, quaternion components), true for a few
/// dyadic ones such as 0.25, which then take the standard library's path.
#[inline]
fn may_be_tie(v: f64) -> bool {
    let bits = v.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    if biased == 0 || biased == 0x7ff {
        return false;
    }
    let mantissa = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
    // v = mantissa 2^(biased - 1075); its lowest set bit:
    let lowest = biased - 1075 + mantissa.trailing_zeros() as i32;
    (-25..=-2).contains(&lowest)
}

/// The exponent ryu writes after `e` (`-7`, `22`, `-324`), when it is one.
fn small_exponent(text: &str) -> Option<i32> {
    let (negative, digits) = match text.strip_prefix('-') {
        Some(d) => (true, d),
        None => (false, text),
    };
    if digits.is_empty() || digits.len() > 3 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let magnitude = digits
        .bytes()
        .fold(0i32, |acc, b| acc * 10 + i32::from(b - b'0'));
    Some(if negative { -magnitude } else { magnitude })
}

/// Reads `text` exactly as `text.parse::<f64>()` does (same value, same
/// error), faster for the finite numbers trial files hold.
#[inline]
pub(crate) fn parse_f64(text: &str) -> Result<f64, ParseFloatError> {
    match fast_float2::parse::<f64, _>(text) {
        Ok(v) if v.is_finite() => Ok(v),
        _ => text.parse::<f64>(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn check_format(v: f64) {
        let mut out = String::from("x,");
        push_f64(&mut out, v);
        assert_eq!(&out[2..], format!("{v}"), "bits {:#018x}", v.to_bits());
    }

    fn check_parse(text: &str) {
        let want = text.parse::<f64>();
        let got = parse_f64(text);
        match (&want, &got) {
            (Ok(a), Ok(b)) => assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "{text:?}: {a} vs {b}"
            ),
            (Err(a), Err(b)) => assert_eq!(a, b, "{text:?}"),
            _ => panic!("{text:?}: std {want:?}, fast {got:?}"),
        }
    }

    /// Values of every kind: raw bit patterns (all exponents, subnormals),
    /// integers, unit-range numbers as quaternions hold, tiny and huge.
    fn values(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let v = match i % 10 {
                8 | 9 => {
                    // Dyadic values q 2^j, where ryu's and `{}`'s ties live.
                    let q = (rng.random::<u64>() >> rng.random_range(11..63)) | 1;
                    let sign = if rng.random::<bool>() { -1.0 } else { 1.0 };
                    sign * q as f64 * 2f64.powi(rng.random_range(-40..4))
                }
                0 | 1 => f64::from_bits(rng.random::<u64>()),
                2 => f64::from_bits(rng.random::<u64>() & 0x800f_ffff_ffff_ffff), // subnormal
                3 => rng.random_range(-1.0..1.0),
                4 => rng.random_range(-1e7..1e7f64).round(),
                5 => (rng.random_range(-1.0..1.0) * 1e6f64).round() / 1e6, // six decimals
                6 => rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(-30..-4)),
                _ => rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(15..309)),
            };
            out.push(v);
        }
        out
    }

    #[test]
    fn formats_as_display_does() {
        let specials = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-5,
            1e-4,
            1e-7,
            1e15,
            1e16,
            1e17,
            1e21,
            1e22,
            123456789012345680.0,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            f64::EPSILON,
            5e-324,
            -5e-324,
            f64::from_bits(0x000f_ffff_ffff_ffff), // largest subnormal
            0.30000000000000004,
            9007199254740993.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for v in specials {
            check_format(v);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(19);
        for v in values(&mut rng, 400_000) {
            check_format(v);
        }
        // Powers of ten and two and their neighbours, where layouts and
        // the spacing of doubles switch.
        for e in -325..=308 {
            let p = 10f64.powi(e);
            for v in [p, p.next_up(), p.next_down(), -p, 1.5 * p, 9.999999 * p] {
                check_format(v);
            }
        }
        for e in -1074..=1023 {
            let p = 2f64.powi(e);
            for v in [p, p.next_up(), p.next_down(), 3.0 * p, 1.25 * p] {
                check_format(v);
            }
        }
        // Every tie between 2^50 and 2^51 (spacing 0.25) near a few starts.
        for start in [1u64 << 50, 1_248_961_574_693_653, (1 << 51) - 500] {
            for k in 0..2000u64 {
                check_format((start + k) as f64 + 0.25);
                check_format((start + k) as f64 + 0.75);
            }
        }
    }

    #[test]
    fn trial_numbers_take_the_fast_path() {
        // Times at 50 Hz and unit-range components never need the fallback;
        // 0.25 and 0.75 (dyadic, lowest bit 2^-2) do.
        let mut rng = ChaCha8Rng::seed_from_u64(22);
        for k in 1..100_000 {
            assert!(!may_be_tie(f64::from(k) / 50.0), "{k}");
            let c: f64 = rng.random_range(-1.0..1.0);
            assert!(!may_be_tie(c), "{c}");
        }
        assert!(may_be_tie(0.25) && may_be_tie(0.75));
        assert!(!may_be_tie(1.5) && !may_be_tie(1.0) && !may_be_tie(1e300));
    }

    #[test]
    fn parses_as_str_parse_does() {
        let mut rng = ChaCha8Rng::seed_from_u64(20);
        let mut text = String::new();
        for v in values(&mut rng, 300_000) {
            // Display's text, the exponent form and a truncated form (rounding).
            text.clear();
            push_f64(&mut text, v);
            check_parse(&text);
            check_parse(&format!("{v:e}"));
            check_parse(&format!("{v:.6}"));
            check_parse(&format!("{v:E}"));
            if text.len() > 3 {
                check_parse(&text[..text.len() - 1]);
            }
        }
        // Halfway cases and long inputs: many digits past the 17th.
        for _ in 0..20_000 {
            let n = rng.random_range(1..60);
            let digits: String = (0..n)
                .map(|_| char::from(b'0' + rng.random_range(0..10u8)))
                .collect();
            let exp = rng.random_range(-340..320);
            check_parse(&format!("{digits}e{exp}"));
            check_parse(&format!("0.{digits}"));
            check_parse(&format!("{digits}.5"));
        }
    }

    #[test]
    fn rejects_and_accepts_what_str_parse_does() {
        let fixed = [
            "",
            " ",
            "+",
            "-",
            ".",
            "e",
            "e5",
            "1e",
            "1e+",
            "1e-",
            "1.",
            ".5",
            "+.5",
            "-.5",
            "+1",
            "--1",
            "+-1",
            "1..2",
            "1.2.3",
            "1e5.5",
            "0x10",
            "1_000",
            "1,5",
            " 1",
            "1 ",
            "inf",
            "-inf",
            "+inf",
            "INF",
            "infinity",
            "Infinity",
            "-infinity",
            "infinit",
            "nan",
            "NaN",
            "-nan",
            "+nan",
            "nan(1)",
            "1e400",
            "-1e400",
            "1e-400",
            "1d5",
            "1f",
            "١",
            "0e0",
            "00.00",
            "1E5",
            "1e+05",
            "1e0005",
            "+0",
            "-0",
            "1.e5",
            ".e5",
            "0.000",
        ];
        for t in fixed {
            check_parse(t);
        }
        // Random strings over the characters numbers are made of.
        let alphabet = b"0123456789.eE+-infaINFAtyx ,_";
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        for _ in 0..200_000 {
            let n = rng.random_range(0..10);
            let t: String = (0..n)
                .map(|_| char::from(alphabet[rng.random_range(0..alphabet.len())]))
                .collect();
            check_parse(&t);
        }
    }
}
