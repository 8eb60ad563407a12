//! Colour themes from `themes/*.toml`, embedded in the binary. Every style also
//! carries modifiers where meaning matters, so that `NO_COLOR` loses nothing.

use super::glyphs::Glyphs;
use ratatui::style::{Color, Modifier, Style};
use serde::Deserialize;
use std::collections::BTreeMap;

/// The themes shipped with the program: (name, TOML text).
pub const THEMES: &[(&str, &str)] = &[
    ("dark", include_str!("../../themes/dark.toml")),
    ("light", include_str!("../../themes/light.toml")),
    (
        "high-contrast",
        include_str!("../../themes/high-contrast.toml"),
    ),
];

#[derive(Debug, Deserialize)]
struct StyleSpec {
    fg: Option<String>,
    bg: Option<String>,
    #[serde(default)]
    modifiers: Vec<String>,
}

/// Styles of every element the screens draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Theme {
    pub name: String,
    pub title: Style,
    pub header: Style,
    pub selected: Style,
    pub dim: Style,
    pub status: Style,
    pub ok: Style,
    pub warn: Style,
    pub error: Style,
    pub limit: Style,
    pub centroid: Style,
    pub raw: Style,
    pub corrected: Style,
    pub cursor: Style,
    pub invalid: Style,
    pub edited: Style,
    /// Plain ASCII markers in the charts and views (`--ascii`: fonts
    /// without braille or block symbols).
    pub ascii: bool,
}

fn modifier(name: &str) -> Result<Modifier, String> {
    Ok(match name {
        "bold" => Modifier::BOLD,
        "dim" => Modifier::DIM,
        "italic" => Modifier::ITALIC,
        "underlined" => Modifier::UNDERLINED,
        "reversed" => Modifier::REVERSED,
        _ => return Err(format!("unknown modifier '{name}'")),
    })
}

impl Theme {
    /// The names of the built-in themes.
    pub fn names() -> Vec<&'static str> {
        THEMES.iter().map(|(n, _)| *n).collect()
    }

    /// A built-in theme; `no_color` keeps only the modifiers.
    pub fn builtin(name: &str, no_color: bool) -> Result<Theme, String> {
        let (_, text) = THEMES.iter().find(|(n, _)| *n == name).ok_or_else(|| {
            format!(
                "unknown theme '{name}' (themes: {})",
                Theme::names().join(", ")
            )
        })?;
        Theme::parse(text, no_color)
    }

    /// Parses a theme TOML.
    pub fn parse(text: &str, no_color: bool) -> Result<Theme, String> {
        let mut table: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
        let name = table
            .remove("name")
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        let mut specs: BTreeMap<String, StyleSpec> = BTreeMap::new();
        for (k, v) in table {
            let spec: StyleSpec = v.try_into().map_err(|e| format!("{k}: {e}"))?;
            specs.insert(k, spec);
        }
        let mut style = |key: &str| -> Result<Style, String> {
            let Some(spec) = specs.remove(key) else {
                return Ok(Style::default());
            };
            let mut s = Style::default();
            if !no_color {
                if let Some(fg) = &spec.fg {
                    s = s.fg(fg
                        .parse::<Color>()
                        .map_err(|_| format!("{key}: bad colour '{fg}'"))?);
                }
                if let Some(bg) = &spec.bg {
                    s = s.bg(bg
                        .parse::<Color>()
                        .map_err(|_| format!("{key}: bad colour '{bg}'"))?);
                }
            }
            for m in &spec.modifiers {
                s = s.add_modifier(modifier(m)?);
            }
            Ok(s)
        };
        Ok(Theme {
            name,
            title: style("title")?,
            header: style("header")?,
            selected: style("selected")?.add_modifier(Modifier::REVERSED),
            dim: style("dim")?,
            status: style("status")?,
            ok: style("ok")?,
            warn: style("warn")?,
            error: style("error")?,
            limit: style("limit")?,
            centroid: style("centroid")?,
            raw: style("raw")?,
            corrected: style("corrected")?,
            cursor: style("cursor")?,
            invalid: style("invalid")?,
            edited: style("edited")?,
            ascii: false,
        })
    }

    /// The same theme with ASCII markers (`--ascii`) or not.
    pub fn with_ascii(self, ascii: bool) -> Theme {
        Theme { ascii, ..self }
    }

    /// The charts' marker set: braille (or, with `m`, dots) unless ASCII.
    pub fn glyphs(&self, braille: bool) -> Glyphs {
        Glyphs::new(braille, self.ascii)
    }

    /// Whether the theme has colours (none under `NO_COLOR`).
    pub fn has_colour(&self) -> bool {
        self.limit.fg.is_some() || self.raw.fg.is_some()
    }
}

impl Default for Theme {
    fn default() -> Self {
        Theme::builtin("dark", false).expect("built-in theme is valid")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_themes_parse_with_ansi_names_only() {
        for (name, text) in THEMES {
            let t = Theme::builtin(name, false).unwrap();
            assert_eq!(&t.name, name);
            assert!(!text.contains('#') || !text.contains("fg = \"#"));
            let plain = Theme::builtin(name, true).unwrap();
            assert_eq!(plain.limit.fg, None);
        }
    }
}
