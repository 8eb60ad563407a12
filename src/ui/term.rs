//! The terminal as `TERM` describes it, and the bytes the workbench sends it.
//!
//! * [`Caps`]: whether to ask for mouse reports and synchronized output;
//!   terminals that lack them (vt100, dumb, GNU screen for synchronized
//!   output) never receive those codes.
//! * [`BasicColours`]: a ratatui backend that sends the 16 basic colours as
//!   the basic SGR codes (`ESC[31m`, `ESC[91m`), which every colour terminal
//!   knows, instead of 256-colour codes (`ESC[38;5;1m`); indexed and RGB
//!   colours keep their extended codes.

use ratatui::backend::{Backend, ClearType, CrosstermBackend, WindowSize};
use ratatui::buffer::Cell;
use ratatui::layout::{Position, Size};
use ratatui::style::{Color, Modifier};
use std::fmt::Write as _;
use std::io::{self, Write};

/// What the terminal can do, as far as the workbench cares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Caps {
    /// Mouse reports (xterm's protocol).
    pub mouse: bool,
    /// Synchronized output (DEC private mode 2026).
    pub sync: bool,
    /// Colours at all (a dumb terminal or a vt100 shows none).
    pub colour: bool,
}

impl Caps {
    /// The capabilities of the terminal named `term` (the `TERM` variable).
    /// Unknown names get neither mouse reports nor synchronized output.
    pub fn from_term(term: Option<&str>) -> Caps {
        let t = term.unwrap_or("").trim().to_ascii_lowercase();
        let family = |names: &[&str]| {
            names
                .iter()
                .any(|n| t == *n || t.starts_with(&format!("{n}-")))
        };
        let none = Caps {
            mouse: false,
            sync: false,
            colour: false,
        };
        if t.is_empty()
            || family(&[
                "dumb", "unknown", "vt52", "vt100", "vt102", "vt220", "vt320", "vt420", "vt520",
            ])
        {
            return none;
        }
        let sync = family(&[
            "xterm",
            "tmux",
            "alacritty",
            "foot",
            "kitty",
            "xterm-kitty",
            "wezterm",
            "contour",
            "ghostty",
            "xterm-ghostty",
            "rio",
        ]);
        let mouse = sync
            || family(&[
                "screen",
                "rxvt",
                "rxvt-unicode",
                "st",
                "putty",
                "konsole",
                "gnome",
                "iterm",
                "iterm2",
                "mlterm",
                "eterm",
            ]);
        Caps {
            mouse,
            sync,
            colour: true,
        }
    }

    /// The capabilities of the terminal the process runs in.
    pub fn from_env() -> Caps {
        Caps::from_term(std::env::var("TERM").ok().as_deref())
    }
}

/// The SGR parameter of colour `c` as foreground (`fg`) or background: the
/// basic codes 30-37 / 90-97 (40-47 / 100-107) for the 16 named colours.
pub fn sgr_colour(c: Color, fg: bool) -> Option<String> {
    let base = if fg { 30 } else { 40 };
    let n = match c {
        Color::Reset => return None,
        Color::Black => base,
        Color::Red => base + 1,
        Color::Green => base + 2,
        Color::Yellow => base + 3,
        Color::Blue => base + 4,
        Color::Magenta => base + 5,
        Color::Cyan => base + 6,
        Color::Gray => base + 7,
        Color::DarkGray => base + 60,
        Color::LightRed => base + 61,
        Color::LightGreen => base + 62,
        Color::LightYellow => base + 63,
        Color::LightBlue => base + 64,
        Color::LightMagenta => base + 65,
        Color::LightCyan => base + 66,
        Color::White => base + 67,
        Color::Indexed(i) => return Some(format!("{};5;{i}", base + 8)),
        Color::Rgb(r, g, b) => return Some(format!("{};2;{r};{g};{b}", base + 8)),
    };
    Some(n.to_string())
}

/// One SGR sequence that sets exactly this style (it starts with a reset).
pub fn sgr(fg: Color, bg: Color, m: Modifier) -> String {
    let mut codes = vec!["0".to_string()];
    for (flag, code) in [
        (Modifier::BOLD, "1"),
        (Modifier::DIM, "2"),
        (Modifier::ITALIC, "3"),
        (Modifier::UNDERLINED, "4"),
        (Modifier::SLOW_BLINK, "5"),
        (Modifier::RAPID_BLINK, "6"),
        (Modifier::REVERSED, "7"),
        (Modifier::HIDDEN, "8"),
        (Modifier::CROSSED_OUT, "9"),
    ] {
        if m.contains(flag) {
            codes.push(code.into());
        }
    }
    codes.extend(sgr_colour(fg, true));
    codes.extend(sgr_colour(bg, false));
    format!("\x1b[{}m", codes.join(";"))
}

/// A crossterm backend whose cells are written with basic SGR codes (see the
/// module docs); everything else is crossterm's.
pub struct BasicColours<W: Write> {
    inner: CrosstermBackend<W>,
}

impl<W: Write> BasicColours<W> {
    pub fn new(writer: W) -> Self {
        BasicColours {
            inner: CrosstermBackend::new(writer),
        }
    }
}

impl<W: Write> Backend for BasicColours<W> {
    type Error = io::Error;

    fn draw<'a, I>(&mut self, content: I) -> io::Result<()>
    where
        I: Iterator<Item = (u16, u16, &'a Cell)>,
    {
        let mut out = String::new();
        let mut style = None;
        let mut last: Option<(u16, u16)> = None;
        for (x, y, cell) in content {
            if !matches!(last, Some((px, py)) if x == px + 1 && y == py) {
                let _ = write!(out, "\x1b[{};{}H", y + 1, x + 1);
            }
            last = Some((x, y));
            let s = (cell.fg, cell.bg, cell.modifier);
            if style != Some(s) {
                out.push_str(&sgr(cell.fg, cell.bg, cell.modifier));
                style = Some(s);
            }
            out.push_str(cell.symbol());
        }
        out.push_str("\x1b[0m");
        self.inner.write_all(out.as_bytes())
    }

    fn hide_cursor(&mut self) -> io::Result<()> {
        self.inner.hide_cursor()
    }

    fn show_cursor(&mut self) -> io::Result<()> {
        self.inner.show_cursor()
    }

    fn get_cursor_position(&mut self) -> io::Result<Position> {
        self.inner.get_cursor_position()
    }

    fn set_cursor_position<P: Into<Position>>(&mut self, position: P) -> io::Result<()> {
        self.inner.set_cursor_position(position)
    }

    fn clear(&mut self) -> io::Result<()> {
        self.inner.clear()
    }

    fn clear_region(&mut self, clear_type: ClearType) -> io::Result<()> {
        self.inner.clear_region(clear_type)
    }

    fn append_lines(&mut self, n: u16) -> io::Result<()> {
        self.inner.append_lines(n)
    }

    fn size(&self) -> io::Result<Size> {
        self.inner.size()
    }

    fn window_size(&mut self) -> io::Result<WindowSize> {
        self.inner.window_size()
    }

    fn flush(&mut self) -> io::Result<()> {
        Backend::flush(&mut self.inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::style::Style;

    #[test]
    fn term_names_decide_mouse_and_synchronized_output() {
        let caps = |t| Caps::from_term(Some(t));
        for t in ["vt100", "vt220", "dumb", ""] {
            let c = caps(t);
            assert!(!c.mouse && !c.sync, "{t}");
        }
        assert!(!caps("vt100").colour);
        let screen = caps("screen-256color");
        assert!(screen.mouse && !screen.sync && screen.colour);
        let xterm = caps("xterm-256color");
        assert!(xterm.mouse && xterm.sync);
        assert!(caps("tmux-256color").sync);
        assert!(!caps("linux").mouse && caps("linux").colour);
        assert_eq!(Caps::from_term(None), caps("dumb"));
    }

    /// What the terminal receives: the 16 named colours as basic codes, the
    /// others as extended ones, one reset-and-set sequence per style change.
    #[test]
    fn basic_colours_are_sent_as_basic_sgr() {
        let mut sent = Vec::<u8>::new();
        let mut cells = [
            Cell::default(),
            Cell::default(),
            Cell::default(),
            Cell::default(),
        ];
        cells[0]
            .set_symbol("a")
            .set_style(Style::default().fg(Color::Red));
        cells[1]
            .set_symbol("b")
            .set_style(Style::default().fg(Color::LightGreen).bg(Color::Gray));
        cells[2].set_symbol("c").set_style(
            Style::default()
                .fg(Color::Indexed(208))
                .add_modifier(Modifier::BOLD),
        );
        cells[3].set_symbol("d");
        let content = cells.iter().enumerate().map(|(i, c)| (i as u16, 2u16, c));
        BasicColours::new(&mut sent).draw(content).unwrap();
        let sent = String::from_utf8(sent).unwrap();
        assert_eq!(
            sent,
            "\x1b[3;1H\x1b[0;31ma\x1b[0;92;47mb\x1b[0;1;38;5;208mc\x1b[0md\x1b[0m"
        );
        assert!(!sent.contains("38;5;1m") && !sent.contains("38;5;9"));
    }
}
