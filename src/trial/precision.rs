//! The precision of a trial's orientation numbers: as read, and as written.
//!
//! A reader counts, while parsing, the decimal places of every orientation
//! number of the file (quaternion components, or Euler angles in degrees)
//! and records the most and the fewest on the trial ([`Decimals`]). The
//! writers then write orientation numbers with that many decimals
//! ([`Precision::Auto`]), so a lab file at six decimals comes back at six
//! decimals, not with seventeen digits of false precision; `--precision
//! full|N` overrides it ([`Precision`]).
//!
//! Rules, in order ([`Precision::style`]):
//!
//! * `full`, a trial without a record (simulated, computed), a record of
//!   [`FULL_FROM`] or more decimals, or a record of the other kind of
//!   numbers (Euler angles read, quaternions written, or the reverse):
//!   today's shortest round-trip text (what `format!("{v}")` writes).
//! * `auto` with fewer decimals than a measuring device gives
//!   ([`QUATERNION_FLOOR`] for quaternion components, [`EULER_FLOOR`] for
//!   degrees: about 0.01 degree either way): the numbers are taken as exact
//!   values (a hand-written `1,0,0,0`), and written in full; rounding a
//!   correction to them would undo it.
//! * otherwise fixed notation rounded (exactly, half to even on the binary
//!   value) to that many decimals; trailing zeros are kept when every number
//!   of the file had the same places (a `%.6f` writer: `0.500000`, the text
//!   such a file holds) and trimmed otherwise (`0.5`, as shortest-digit
//!   writers such as this program's own write it). Either way an unchanged
//!   number comes back as the text it was read from (see
//!   [`quaternion_round_trips`] for when a quaternion is unchanged).

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// From this many decimal places on, numbers are written in full (shortest
/// round-trip digits): 15 decimals are already below the spacing of `f64`
/// values near 1 that matters for orientations.
pub const FULL_FROM: u8 = 15;
/// Fewest decimals of quaternion components that `auto` keeps (5e-5 per
/// component, about 0.006 degree); fewer are taken as exact values.
pub const QUATERNION_FLOOR: u8 = 4;
/// Fewest decimals of Euler angles (degrees) that `auto` keeps (0.005 degree).
pub const EULER_FLOOR: u8 = 2;
/// Largest `N` of `--precision N`.
pub const MAX_DECIMALS: u8 = 17;

/// Which orientation numbers a file held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleNumbers {
    /// Quaternion components `w, x, y, z`.
    Quaternion,
    /// Euler angles, degrees.
    EulerDeg,
}

impl AngleNumbers {
    /// The orientation numbers a file in `format` holds (Xsens: written as `.sto`).
    pub fn written_in(format: super::TrialFormat) -> AngleNumbers {
        if format == super::TrialFormat::EulerCsv {
            AngleNumbers::EulerDeg
        } else {
            AngleNumbers::Quaternion
        }
    }

    /// Fewest decimals `auto` keeps for these numbers.
    fn floor(self) -> u8 {
        match self {
            AngleNumbers::Quaternion => QUATERNION_FLOOR,
            AngleNumbers::EulerDeg => EULER_FLOOR,
        }
    }
}

/// The decimal places of a trial file's orientation numbers, as read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Decimals {
    /// What the numbers were.
    pub numbers: AngleNumbers,
    /// The most decimal places of any of them (below [`FULL_FROM`]).
    pub most: u8,
    /// The fewest decimal places of any of them.
    pub fewest: u8,
}

impl Decimals {
    /// The record of a trial read in parts (rows of a growing file, one
    /// export per sensor): as if read at once. `None` (full precision or
    /// unknown) wins, as do mixed kinds of numbers.
    pub fn merge(a: Option<Decimals>, b: Option<Decimals>) -> Option<Decimals> {
        let (a, b) = (a?, b?);
        (a.numbers == b.numbers).then(|| Decimals {
            numbers: a.numbers,
            most: a.most.max(b.most),
            fewest: a.fewest.min(b.fewest),
        })
    }

    /// Whether every number had the same places (trailing zeros written).
    pub fn padded(self) -> bool {
        self.most == self.fewest
    }
}

/// Fixed notation: a number rounded to `decimals` places, trailing zeros
/// kept (`padded`) or trimmed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fixed {
    /// Decimal places every number is rounded to.
    pub decimals: u8,
    /// Whether trailing zeros are written (`0.500000`) or trimmed (`0.5`).
    pub padded: bool,
}

/// The decimal places of a number's text: digits after the point (or a
/// decimal comma), less the exponent (`0.125` 3, `1.5e-5` 6, `2.5E3` 0,
/// `7` 0, `0,25` 2), at most 255.
pub fn decimals_of(text: &str) -> u8 {
    let b = text.as_bytes();
    let (mantissa, exponent) = match b.iter().position(|&c| c == b'e' || c == b'E') {
        Some(i) => (&b[..i], exponent_of(&b[i + 1..])),
        None => (b, 0),
    };
    let fraction = mantissa
        .iter()
        .position(|&c| c == b'.' || c == b',')
        .map_or(0, |i| mantissa.len() - i - 1);
    (fraction as i64 - exponent).clamp(0, 255) as u8
}

/// The value of an exponent's text (`-05`, `+3`, `12`), saturating.
fn exponent_of(text: &[u8]) -> i64 {
    let (sign, digits) = match text.first() {
        Some(b'-') => (-1, &text[1..]),
        Some(b'+') => (1, &text[1..]),
        _ => (1, text),
    };
    let magnitude = digits
        .iter()
        .take_while(|c| c.is_ascii_digit())
        .fold(0i64, |acc, &c| {
            (acc * 10 + i64::from(c - b'0')).min(1 << 20)
        });
    sign * magnitude
}

/// Counts the decimal places of orientation numbers as a reader parses them.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Tally {
    most: u8,
    fewest: u8,
    seen: bool,
}

impl Tally {
    /// Counts one number's text.
    #[inline]
    pub(crate) fn see(&mut self, text: &str) {
        let d = decimals_of(text);
        if self.seen {
            self.most = self.most.max(d);
            self.fewest = self.fewest.min(d);
        } else {
            (self.most, self.fewest, self.seen) = (d, d, true);
        }
    }

    /// Adds what `other` saw (the counts of another part of the same file).
    pub(crate) fn merge(&mut self, other: Tally) {
        if !other.seen {
            return;
        }
        if self.seen {
            self.most = self.most.max(other.most);
            self.fewest = self.fewest.min(other.fewest);
        } else {
            *self = other;
        }
    }

    /// The record of what was seen: `None` when nothing was, or some number
    /// had [`FULL_FROM`] or more places (full precision).
    pub(crate) fn finish(self, numbers: AngleNumbers) -> Option<Decimals> {
        (self.seen && self.most < FULL_FROM).then_some(Decimals {
            numbers,
            most: self.most,
            fewest: self.fewest,
        })
    }
}

/// How orientation numbers are written: `--precision auto|full|N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum Precision {
    /// As read ([`Decimals`]); full when unknown.
    #[default]
    Auto,
    /// Shortest round-trip digits (up to 17 significant).
    Full,
    /// This many decimal places, trailing zeros trimmed ([`FULL_FROM`] or
    /// more: full).
    Decimals(u8),
}

impl Precision {
    /// Whether this is the default (`auto`), left out of sidecars.
    pub fn is_auto(&self) -> bool {
        *self == Precision::Auto
    }

    /// How to write `numbers` of a trial whose orientation numbers were read
    /// as `read`: `None` for full precision (see the module's rules).
    pub fn style(self, read: Option<Decimals>, numbers: AngleNumbers) -> Option<Fixed> {
        let fixed = match self {
            Precision::Full => None,
            Precision::Decimals(decimals) => Some(Fixed {
                decimals,
                padded: false,
            }),
            Precision::Auto => read
                .filter(|r| r.numbers == numbers && r.most >= numbers.floor())
                .map(|r| Fixed {
                    decimals: r.most,
                    padded: r.padded(),
                }),
        };
        fixed.filter(|f| f.decimals < FULL_FROM)
    }

    /// Reads `auto`, `full` or a number of decimals `0..=17`.
    pub fn parse(text: &str) -> Result<Precision, String> {
        match text.trim() {
            "auto" => Ok(Precision::Auto),
            "full" => Ok(Precision::Full),
            t => match t.parse::<u8>() {
                Ok(n) if n <= MAX_DECIMALS => Ok(Precision::Decimals(n)),
                _ => Err(format!(
                    "expected auto, full or a number of decimal places 0..={MAX_DECIMALS}, found '{t}'"
                )),
            },
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Precision::Auto => f.write_str("auto"),
            Precision::Full => f.write_str("full"),
            Precision::Decimals(n) => write!(f, "{n}"),
        }
    }
}

impl From<Precision> for String {
    fn from(p: Precision) -> String {
        p.to_string()
    }
}

impl TryFrom<String> for Precision {
    type Error = String;
    fn try_from(text: String) -> Result<Precision, String> {
        Precision::parse(&text)
    }
}

/// Appends `v` rounded to `style.decimals` places in fixed notation (exactly
/// rounded, as `format!("{v:.N}")`), trailing zeros trimmed unless
/// `style.padded`. A nonzero number that rounds to zero is written without
/// its sign (`0.000000`, `0`); `-0.0` itself keeps it (`-0.000000`), as C's
/// `printf` writes it, so such text reads back and is written again alike.
pub(crate) fn push_fixed(out: &mut String, v: f64, style: Fixed) {
    let start = out.len();
    let _ = write!(out, "{:.*}", usize::from(style.decimals), v);
    if !style.padded && out[start..].contains('.') {
        let kept = out.trim_end_matches('0').trim_end_matches('.').len();
        out.truncate(kept);
    }
    let rounded_to_zero = out[start..]
        .bytes()
        .all(|b| matches!(b, b'-' | b'0' | b'.'));
    if rounded_to_zero && v != 0.0 && out[start..].starts_with('-') {
        out.remove(start);
    }
}

/// Whether a quaternion read from text `q` (the numbers as parsed, `d`
/// decimals each) is written back as the same text at `d` decimals when
/// nothing changes it: the reader divides it by its norm `n`, the writer
/// rounds each `q_i / n` to `d` places, which gives back `q_i` exactly when
/// `|q_i| |1/n - 1| < 0.5e-d` for every component (less a margin of a few
/// `f64` roundings, this test's own). A quaternion rounded from a unit one
/// to `d` places has `|n - 1| <= sum |q_i| 0.5e-d <= 1e-d`, so most but not
/// all of them pass (the components near 1 of those with `|n - 1|` near its
/// bound do not); written with `w >= 0`, a row read with `w < 0` comes back
/// with every sign flipped (`-0.5` as `0.5`, `0` as `-0`).
pub fn quaternion_round_trips(q: [f64; 4], d: u8) -> bool {
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    let half_step = 0.5 * 10f64.powi(-i32::from(d));
    let off = (1.0 / n - 1.0).abs();
    q.iter().all(|c| c.abs() * off < half_step * (1.0 - 1e-6))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(v: f64, decimals: u8, padded: bool) -> String {
        let mut out = String::from("x");
        push_fixed(&mut out, v, Fixed { decimals, padded });
        out[1..].to_string()
    }

    #[test]
    fn counts_decimal_places_of_any_notation() {
        let cases = [
            ("0.125", 3),
            ("-0.500000", 6),
            ("1", 0),
            ("-0", 0),
            ("1.", 0),
            (".5", 1),
            ("1.5e-5", 6),
            ("1E-7", 7),
            ("2.5E3", 0),
            ("2.5e+1", 0),
            ("12.3456e1", 3),
            ("0.0000001", 7),
            ("1e-400", 255),
            ("0,25", 2),
        ];
        for (text, want) in cases {
            assert_eq!(decimals_of(text), want, "{text}");
        }
    }

    #[test]
    fn tally_keeps_most_and_fewest_and_gives_up_at_full_precision() {
        let mut t = Tally::default();
        assert_eq!(t.finish(AngleNumbers::Quaternion), None);
        for text in ["0.5", "0.123456", "1"] {
            t.see(text);
        }
        let d = t.finish(AngleNumbers::Quaternion).unwrap();
        assert_eq!((d.most, d.fewest, d.padded()), (6, 0, false));
        t.see("0.30000000000000004");
        assert_eq!(t.finish(AngleNumbers::Quaternion), None);
    }

    #[test]
    fn merging_parts_is_reading_them_at_once() {
        let q = |most, fewest| {
            Some(Decimals {
                numbers: AngleNumbers::Quaternion,
                most,
                fewest,
            })
        };
        assert_eq!(Decimals::merge(q(6, 6), q(5, 3)), q(6, 3));
        assert_eq!(Decimals::merge(q(6, 6), None), None);
        let e = Some(Decimals {
            numbers: AngleNumbers::EulerDeg,
            most: 6,
            fewest: 6,
        });
        assert_eq!(Decimals::merge(q(6, 6), e), None);
    }

    #[test]
    fn fixed_text_rounds_exactly_and_trims_or_pads() {
        assert_eq!(fixed(0.5, 6, true), "0.500000");
        assert_eq!(fixed(0.5, 6, false), "0.5");
        assert_eq!(fixed(1.0, 6, false), "1");
        assert_eq!(fixed(-0.1234565, 6, false), "-0.123456"); // binary value below the tie
        assert_eq!(fixed(0.9999996, 6, false), "1");
        assert_eq!(fixed(-3e-9, 6, true), "0.000000");
        assert_eq!(fixed(-3e-9, 6, false), "0");
        assert_eq!(fixed(-0.0, 6, true), "-0.000000");
        assert_eq!(fixed(-0.0, 6, false), "-0");
        assert_eq!(fixed(123.456, 0, false), "123");
        assert_eq!(fixed(-12.5, 2, true), "-12.50");
    }

    #[test]
    fn fixed_text_reads_back_within_half_a_step() {
        for k in 0..20_000 {
            let v = (f64::from(k) * 0.618_033_988_75).sin();
            for d in [4u8, 6, 9, 14] {
                let text = fixed(v, d, false);
                let back: f64 = text.parse().unwrap();
                assert!((back - v).abs() <= 0.5 * 10f64.powi(-i32::from(d)) + 1e-16);
                assert!(decimals_of(&text) <= d, "{text}");
            }
        }
    }

    #[test]
    fn style_follows_the_rules() {
        let read = |numbers, most, fewest| {
            Some(Decimals {
                numbers,
                most,
                fewest,
            })
        };
        let (q, e) = (AngleNumbers::Quaternion, AngleNumbers::EulerDeg);
        let six = Fixed {
            decimals: 6,
            padded: true,
        };
        assert_eq!(Precision::Auto.style(read(q, 6, 6), q), Some(six));
        assert_eq!(Precision::Auto.style(read(q, 6, 6), e), None);
        assert_eq!(Precision::Auto.style(read(q, 3, 0), q), None);
        assert_eq!(
            Precision::Auto.style(read(e, 2, 1), e).map(|f| f.padded),
            Some(false)
        );
        assert_eq!(Precision::Auto.style(None, q), None);
        assert_eq!(Precision::Full.style(read(q, 6, 6), q), None);
        assert_eq!(
            Precision::Decimals(3).style(None, e),
            Some(Fixed {
                decimals: 3,
                padded: false
            })
        );
        assert_eq!(Precision::Decimals(15).style(read(q, 6, 6), q), None);
    }

    #[test]
    fn precision_reads_and_writes_its_names() {
        for (text, p) in [
            ("auto", Precision::Auto),
            ("full", Precision::Full),
            ("6", Precision::Decimals(6)),
            ("0", Precision::Decimals(0)),
        ] {
            assert_eq!(Precision::parse(text), Ok(p));
            assert_eq!(p.to_string(), text);
            let json = serde_json::to_string(&p).unwrap();
            assert_eq!(serde_json::from_str::<Precision>(&json).unwrap(), p);
        }
        for bad in ["18", "-1", "six", ""] {
            assert!(Precision::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn round_trip_test_matches_the_writer() {
        // Quaternions rounded to 6 places from unit ones: the test says which
        // come back as the same text, and the writer agrees on every one.
        let mut passed = 0;
        for k in 0..20_000 {
            let t = f64::from(k);
            let raw = [
                (t * 0.37).cos(),
                (t * 0.71).sin(),
                (t * 1.13).sin() * 0.5,
                (t * 0.29).cos() * 0.3,
            ];
            let n = raw.iter().map(|c| c * c).sum::<f64>().sqrt();
            let text: Vec<String> = raw.iter().map(|c| format!("{:.6}", c / n)).collect();
            let q: Vec<f64> = text.iter().map(|s| s.parse().unwrap()).collect();
            let q = [q[0], q[1], q[2], q[3]];
            let m = q.iter().map(|c| c * c).sum::<f64>().sqrt();
            let style = Fixed {
                decimals: 6,
                padded: true,
            };
            let same = q
                .iter()
                .zip(&text)
                .all(|(c, s)| fixed(c / m, 6, style.padded) == *s);
            if quaternion_round_trips(q, 6) {
                passed += 1;
                assert!(same, "{text:?}");
            }
        }
        assert!(passed > 15_000, "{passed}");
    }
}
