//! The marker set of the charts and views: every element has a glyph of its
//! own, so that none is told apart by colour alone (`NO_COLOR`, monochrome
//! terminals, colour blindness). With `--ascii` every glyph is a plain ASCII
//! character, for fonts without braille or block symbols.

use ratatui::symbols::Marker;

/// How the charts draw each element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Glyphs {
    /// The uncorrected angle.
    pub raw: Marker,
    /// The corrected angle of the variant shown.
    pub corrected: Marker,
    /// The corrected angle of a growing trial past its newest solve
    /// (extrapolated from it).
    pub extrapolated: Marker,
    /// A reference (ground-truth or motion-capture) angle.
    pub reference: Marker,
    /// Lower and upper limit lines.
    pub limit: Marker,
    /// The centroid line.
    pub centroid: Marker,
    /// The time cursor.
    pub cursor: Marker,
    /// Glitch markers.
    pub glitch: Marker,
    /// Scatter classes: within the limits, up to 10 deg out, beyond.
    pub classes: [Marker; 3],
    /// The views' outlines (the globe's rim and grid, the limit band): the
    /// fine marker, but its own character in ASCII, where the points inside
    /// have the fine marker's.
    pub outline: Marker,
}

/// Time bands of the views when there is no colour: earliest `1` to latest `6`.
pub const TIME_DIGITS: [char; 6] = ['1', '2', '3', '4', '5', '6'];

/// Series labels of charts with many lines (the heading view's IMUs), in turn.
pub const SERIES: &[u8] = b"123456789abcdefghijklmnopqrstuvwxyz";

impl Glyphs {
    /// The set for braille (`m` toggles it off: one dot per cell) or ASCII.
    pub fn new(braille: bool, ascii: bool) -> Glyphs {
        if ascii {
            return Glyphs {
                raw: Marker::Custom('.'),
                corrected: Marker::Custom('*'),
                extrapolated: Marker::Custom('~'),
                reference: Marker::Custom('o'),
                limit: Marker::Custom('='),
                centroid: Marker::Custom('-'),
                cursor: Marker::Custom('|'),
                glitch: Marker::Custom('x'),
                classes: [
                    Marker::Custom('.'),
                    Marker::Custom('+'),
                    Marker::Custom('x'),
                ],
                outline: Marker::Custom(':'),
            };
        }
        let fine = if braille {
            Marker::Braille
        } else {
            Marker::Dot
        };
        Glyphs {
            raw: fine,
            corrected: Marker::HalfBlock,
            extrapolated: Marker::Custom('░'),
            reference: Marker::Custom('∘'),
            limit: Marker::Custom('═'),
            centroid: Marker::Custom('┄'),
            cursor: Marker::Custom('┊'),
            glitch: Marker::Custom('×'),
            classes: [fine, Marker::Custom('+'), Marker::Custom('×')],
            outline: fine,
        }
    }

    /// The fine marker of the views' point clouds and outlines.
    pub fn fine(&self) -> Marker {
        self.classes[0]
    }
}

/// What a marker looks like in a legend (a short horizontal stretch of it).
pub fn sample(m: Marker) -> String {
    match m {
        Marker::Braille => "⠒⠒".into(),
        Marker::HalfBlock => "▄▀".into(),
        Marker::Dot => "••".into(),
        Marker::Block => "██".into(),
        Marker::Bar => "▄▄".into(),
        Marker::Custom(c) => format!("{c}{c}"),
        _ => "▖▘".into(),
    }
}

/// Cells per dot of `m`: (across, down).
pub fn dots_per_cell(m: Marker) -> (usize, usize) {
    match m {
        Marker::Braille | Marker::Octant => (2, 4),
        Marker::HalfBlock => (1, 2),
        Marker::Quadrant => (2, 2),
        Marker::Sextant => (2, 3),
        _ => (1, 1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every element of a chart has a glyph of its own in every set, and the
    /// ASCII set is ASCII.
    #[test]
    fn glyphs_are_distinct_and_ascii_is_ascii() {
        for (braille, ascii) in [(true, false), (false, false), (true, true)] {
            let g = Glyphs::new(braille, ascii);
            let all = [
                g.raw,
                g.corrected,
                g.extrapolated,
                g.reference,
                g.limit,
                g.centroid,
                g.cursor,
                g.glitch,
            ];
            let samples: Vec<String> = all.iter().map(|m| sample(*m)).collect();
            for (i, a) in samples.iter().enumerate() {
                for b in &samples[i + 1..] {
                    assert_ne!(a, b, "braille {braille} ascii {ascii}");
                }
            }
            let classes: Vec<String> = g.classes.iter().map(|m| sample(*m)).collect();
            assert!(
                classes[0] != classes[1] && classes[1] != classes[2] && classes[0] != classes[2]
            );
            if ascii {
                assert!(samples.iter().chain(&classes).all(|s| s.is_ascii()));
                // The views' outlines read apart from the points inside them.
                assert!(!classes.contains(&sample(g.outline)));
            }
        }
    }
}
