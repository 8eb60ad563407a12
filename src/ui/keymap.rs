//! Keys become actions; the help overlay is generated from the same table.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// What a key asks for; the screen in front decides what it means there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    Quit,
    Help,
    Back,
    Up,
    Down,
    Left,
    Right,
    PageUp,
    PageDown,
    Enter,
    Filter,
    Sort,
    Run,
    Variant,
    Compare,
    Limits,
    Calibration,
    Histogram,
    ZoomIn,
    ZoomOut,
    CursorLeft,
    CursorRight,
    Home,
    End,
    Save,
    Choose,
    Marker,
    Pose,
    NextGlitch,
    KeepMine,
    TakeFile,
    Yes,
    No,
    Scatter,
    Globe,
    Applied,
    Stick,
    HeadingDrift,
    Play,
    TimeColour,
    Mouse,
}

impl Action {
    /// Moves a list's selection (Up/Down, PgUp/PgDn, Home/End): what
    /// [`crate::ui::cells::list_move`] answers.
    pub fn moves_in_list(self) -> bool {
        matches!(
            self,
            Action::Up
                | Action::Down
                | Action::PageUp
                | Action::PageDown
                | Action::Home
                | Action::End
        )
    }
}

/// Where a binding applies, for the help overlay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    Everywhere,
    Trials,
    Trial,
    Compare,
    Limits,
    Views,
    Calibration,
    Histogram,
}

impl Scope {
    pub fn title(self) -> &'static str {
        match self {
            Scope::Everywhere => "everywhere",
            Scope::Trials => "trials",
            Scope::Trial => "trial",
            Scope::Compare => "compare",
            Scope::Limits => "limits",
            Scope::Views => "views",
            Scope::Calibration => "calibration",
            Scope::Histogram => "histograms",
        }
    }
}

/// One binding: the key, what it does, where.
pub struct Binding {
    pub keys: &'static str,
    pub code: &'static [KeyCode],
    pub action: Action,
    pub scope: Scope,
    pub help: &'static str,
}

/// Every binding, in help order.
#[rustfmt::skip]
pub const BINDINGS: &[Binding] = &[
    Binding { keys: "q", code: &[KeyCode::Char('q')], action: Action::Quit, scope: Scope::Everywhere, help: "quit (asks if unsaved)" },
    Binding { keys: "?", code: &[KeyCode::Char('?'), KeyCode::F(1)], action: Action::Help, scope: Scope::Everywhere, help: "this help" },
    Binding { keys: "Esc", code: &[KeyCode::Esc, KeyCode::Backspace], action: Action::Back, scope: Scope::Everywhere, help: "back / cancel" },
    Binding { keys: "Up/Down j/k", code: &[KeyCode::Up, KeyCode::Char('k')], action: Action::Up, scope: Scope::Everywhere, help: "move selection" },
    Binding { keys: "", code: &[KeyCode::Down, KeyCode::Char('j')], action: Action::Down, scope: Scope::Everywhere, help: "" },
    Binding { keys: "PgUp/PgDn", code: &[KeyCode::PageUp], action: Action::PageUp, scope: Scope::Everywhere, help: "a page up / down" },
    Binding { keys: "", code: &[KeyCode::PageDown], action: Action::PageDown, scope: Scope::Everywhere, help: "" },
    Binding { keys: "Enter", code: &[KeyCode::Enter], action: Action::Enter, scope: Scope::Everywhere, help: "open / edit / commit" },
    Binding { keys: "/", code: &[KeyCode::Char('/')], action: Action::Filter, scope: Scope::Trials, help: "filter by name" },
    Binding { keys: "s", code: &[KeyCode::Char('s')], action: Action::Sort, scope: Scope::Trials, help: "sort name/dur/excursion" },
    Binding { keys: "C", code: &[KeyCode::Char('C')], action: Action::Calibration, scope: Scope::Trials, help: "calibration recordings" },
    Binding { keys: "H", code: &[KeyCode::Char('H')], action: Action::Histogram, scope: Scope::Trial, help: "histograms and limits" },
    Binding { keys: "r", code: &[KeyCode::Char('r')], action: Action::Run, scope: Scope::Trial, help: "run all variants" },
    Binding { keys: "v", code: &[KeyCode::Char('v')], action: Action::Variant, scope: Scope::Trial, help: "next variant" },
    Binding { keys: "c", code: &[KeyCode::Char('c')], action: Action::Compare, scope: Scope::Trial, help: "compare and save" },
    Binding { keys: "L", code: &[KeyCode::Char('L')], action: Action::Limits, scope: Scope::Everywhere, help: "limits editor" },
    Binding { keys: "+/-", code: &[KeyCode::Char('+'), KeyCode::Char('=')], action: Action::ZoomIn, scope: Scope::Trial, help: "zoom (or mouse wheel)" },
    Binding { keys: "", code: &[KeyCode::Char('-')], action: Action::ZoomOut, scope: Scope::Trial, help: "" },
    Binding { keys: "Left/Right h/l", code: &[KeyCode::Left, KeyCode::Char('h')], action: Action::Left, scope: Scope::Everywhere, help: "left / right (pan, column)" },
    Binding { keys: "", code: &[KeyCode::Right, KeyCode::Char('l')], action: Action::Right, scope: Scope::Everywhere, help: "" },
    Binding { keys: ", .", code: &[KeyCode::Char(',')], action: Action::CursorLeft, scope: Scope::Trial, help: "move the cursor" },
    Binding { keys: "", code: &[KeyCode::Char('.')], action: Action::CursorRight, scope: Scope::Trial, help: "" },
    Binding { keys: "Home/End", code: &[KeyCode::Home], action: Action::Home, scope: Scope::Everywhere, help: "first / last (trial: cursor)" },
    Binding { keys: "", code: &[KeyCode::End], action: Action::End, scope: Scope::Everywhere, help: "" },
    Binding { keys: "m", code: &[KeyCode::Char('m')], action: Action::Marker, scope: Scope::Trial, help: "braille / dot marker" },
    Binding { keys: "P", code: &[KeyCode::Char('P')], action: Action::Pose, scope: Scope::Trial, help: "pose calibration at cursor" },
    Binding { keys: "G", code: &[KeyCode::Char('G')], action: Action::NextGlitch, scope: Scope::Trial, help: "cursor to the next glitch" },
    Binding { keys: "Space", code: &[KeyCode::Char(' ')], action: Action::Choose, scope: Scope::Compare, help: "choose the variant" },
    Binding { keys: "w", code: &[KeyCode::Char('w')], action: Action::Save, scope: Scope::Everywhere, help: "save variant / limits" },
    Binding { keys: "K / T", code: &[KeyCode::Char('K')], action: Action::KeepMine, scope: Scope::Limits, help: "reload: mine / file's" },
    Binding { keys: "", code: &[KeyCode::Char('T')], action: Action::TakeFile, scope: Scope::Limits, help: "" },
    Binding { keys: "x", code: &[KeyCode::Char('x')], action: Action::Scatter, scope: Scope::Trial, help: "3-D scatter view" },
    Binding { keys: "o", code: &[KeyCode::Char('o')], action: Action::Globe, scope: Scope::Trial, help: "globographic view" },
    Binding { keys: "a", code: &[KeyCode::Char('a')], action: Action::Applied, scope: Scope::Trial, help: "applied correction view" },
    Binding { keys: "f", code: &[KeyCode::Char('f')], action: Action::Stick, scope: Scope::Trial, help: "stick figure view" },
    Binding { keys: "D", code: &[KeyCode::Char('D')], action: Action::HeadingDrift, scope: Scope::Trial, help: "heading drift per IMU" },
    Binding { keys: "t", code: &[KeyCode::Char('t')], action: Action::TimeColour, scope: Scope::Views, help: "colour by time / limits" },
    Binding { keys: "p", code: &[KeyCode::Char('p')], action: Action::Play, scope: Scope::Views, help: "play / pause (or Space)" },
    Binding { keys: "M", code: &[KeyCode::Char('M')], action: Action::Mouse, scope: Scope::Everywhere, help: "mouse capture on / off" },
    Binding { keys: "y / n", code: &[KeyCode::Char('y')], action: Action::Yes, scope: Scope::Everywhere, help: "answer a question" },
    Binding { keys: "", code: &[KeyCode::Char('n')], action: Action::No, scope: Scope::Everywhere, help: "" },
    // What keys bound above do on other screens (for their help).
    Binding { keys: "r", code: &[KeyCode::Char('r')], action: Action::Run, scope: Scope::Trials, help: "run all variants of the selected" },
    Binding { keys: "v", code: &[KeyCode::Char('v')], action: Action::Variant, scope: Scope::Trials, help: "next variant" },
    Binding { keys: "H", code: &[KeyCode::Char('H')], action: Action::Histogram, scope: Scope::Trials, help: "histograms of the listed trials" },
    Binding { keys: "Left/Right", code: &[KeyCode::Left], action: Action::Left, scope: Scope::Compare, help: "pick the variant column" },
    Binding { keys: "", code: &[KeyCode::Right], action: Action::Right, scope: Scope::Compare, help: "" },
    Binding { keys: "w", code: &[KeyCode::Char('w')], action: Action::Save, scope: Scope::Compare, help: "save the chosen variant" },
    Binding { keys: "o", code: &[KeyCode::Char('o')], action: Action::Globe, scope: Scope::Compare, help: "override auto's choice for the joint" },
    Binding { keys: "r", code: &[KeyCode::Char('r')], action: Action::Run, scope: Scope::Compare, help: "run all variants again" },
    Binding { keys: "x", code: &[KeyCode::Char('x')], action: Action::Scatter, scope: Scope::Views, help: "3-D scatter view" },
    Binding { keys: "o", code: &[KeyCode::Char('o')], action: Action::Globe, scope: Scope::Views, help: "globographic view" },
    Binding { keys: "a", code: &[KeyCode::Char('a')], action: Action::Applied, scope: Scope::Views, help: "applied correction view" },
    Binding { keys: "f", code: &[KeyCode::Char('f')], action: Action::Stick, scope: Scope::Views, help: "stick figure view" },
    Binding { keys: "D", code: &[KeyCode::Char('D')], action: Action::HeadingDrift, scope: Scope::Views, help: "heading drift per IMU" },
    Binding { keys: "r", code: &[KeyCode::Char('r')], action: Action::Run, scope: Scope::Calibration, help: "read the recordings again" },
    Binding { keys: "Enter", code: &[KeyCode::Enter], action: Action::Enter, scope: Scope::Histogram, help: "suggest limits (90% intervals)" },
    Binding { keys: "w", code: &[KeyCode::Char('w')], action: Action::Save, scope: Scope::Histogram, help: "write centroids.csv (asks)" },
    Binding { keys: "Left/Right", code: &[KeyCode::Left], action: Action::Left, scope: Scope::Histogram, help: "previous / next span" },
    Binding { keys: "", code: &[KeyCode::Right], action: Action::Right, scope: Scope::Histogram, help: "" },
    Binding { keys: "+/-", code: &[KeyCode::Char('+')], action: Action::ZoomIn, scope: Scope::Histogram, help: "span length" },
    Binding { keys: "", code: &[KeyCode::Char('-')], action: Action::ZoomOut, scope: Scope::Histogram, help: "" },
    Binding { keys: "Home/End", code: &[KeyCode::Home], action: Action::Home, scope: Scope::Histogram, help: "first 30 s / whole trial" },
    Binding { keys: "", code: &[KeyCode::End], action: Action::End, scope: Scope::Histogram, help: "" },
];

/// The action of a key press, if any. Of the Ctrl-combinations only Ctrl-C
/// is bound: it quits as `q` does (asking when something would be lost).
pub fn action(key: &KeyEvent) -> Option<Action> {
    if key.modifiers.contains(KeyModifiers::CONTROL) && key.code == KeyCode::Char('c') {
        return Some(Action::Quit);
    }
    if key.modifiers.contains(KeyModifiers::CONTROL) || key.modifiers.contains(KeyModifiers::ALT) {
        return None;
    }
    BINDINGS
        .iter()
        .find(|b| b.code.contains(&key.code))
        .map(|b| b.action)
}

/// Help lines: (keys, text, scope) of every documented binding.
pub fn help_lines() -> Vec<(&'static str, &'static str, Scope)> {
    BINDINGS
        .iter()
        .filter(|b| !b.keys.is_empty())
        .map(|b| (b.keys, b.help, b.scope))
        .collect()
}

/// A status-bar hint: the keys as shown, the key the hint's action is
/// tested with, the action, and what it does on that screen.
pub struct Hint {
    pub keys: &'static str,
    pub key: KeyCode,
    pub action: Action,
    pub text: &'static str,
}

const fn hint(keys: &'static str, key: KeyCode, action: Action, text: &'static str) -> Hint {
    Hint {
        keys,
        key,
        action,
        text,
    }
}

const TRIALS_HINTS: &[Hint] = &[
    hint("Enter", KeyCode::Enter, Action::Enter, "open"),
    hint("r", KeyCode::Char('r'), Action::Run, "run"),
    hint("/", KeyCode::Char('/'), Action::Filter, "filter"),
    hint("s", KeyCode::Char('s'), Action::Sort, "sort"),
    hint("v", KeyCode::Char('v'), Action::Variant, "variant"),
    hint("L", KeyCode::Char('L'), Action::Limits, "limits"),
    hint("?", KeyCode::Char('?'), Action::Help, "help"),
    hint("q", KeyCode::Char('q'), Action::Quit, "quit"),
];

const TRIAL_HINTS: &[Hint] = &[
    hint("r", KeyCode::Char('r'), Action::Run, "run"),
    hint("v", KeyCode::Char('v'), Action::Variant, "variant"),
    hint("c", KeyCode::Char('c'), Action::Compare, "compare"),
    hint("+-", KeyCode::Char('+'), Action::ZoomIn, "zoom"),
    hint("<- ->", KeyCode::Right, Action::Right, "pan"),
    hint(", .", KeyCode::Char('.'), Action::CursorRight, "cursor"),
    hint("x o a f D", KeyCode::Char('x'), Action::Scatter, "views"),
    hint("?", KeyCode::Char('?'), Action::Help, "help"),
];

const COMPARE_HINTS: &[Hint] = &[
    hint("<- ->", KeyCode::Left, Action::Left, "variant"),
    hint("Space", KeyCode::Char(' '), Action::Choose, "choose"),
    hint("w", KeyCode::Char('w'), Action::Save, "save"),
    hint("o", KeyCode::Char('o'), Action::Globe, "override auto"),
    hint("r", KeyCode::Char('r'), Action::Run, "run"),
    hint("Esc", KeyCode::Esc, Action::Back, "back"),
    hint("?", KeyCode::Char('?'), Action::Help, "help"),
];

const LIMITS_HINTS: &[Hint] = &[
    hint("Enter", KeyCode::Enter, Action::Enter, "edit"),
    hint("<- ->", KeyCode::Left, Action::Left, "column"),
    hint("w", KeyCode::Char('w'), Action::Save, "save"),
    hint("Esc", KeyCode::Esc, Action::Back, "back"),
    hint("?", KeyCode::Char('?'), Action::Help, "help"),
    hint("q", KeyCode::Char('q'), Action::Quit, "quit"),
];

const VIEWS_HINTS: &[Hint] = &[
    hint("x", KeyCode::Char('x'), Action::Scatter, "scatter"),
    hint("o", KeyCode::Char('o'), Action::Globe, "globe"),
    hint("a", KeyCode::Char('a'), Action::Applied, "applied"),
    hint("f", KeyCode::Char('f'), Action::Stick, "stick"),
    hint("D", KeyCode::Char('D'), Action::HeadingDrift, "heading"),
    hint("t", KeyCode::Char('t'), Action::TimeColour, "time"),
    hint("Esc", KeyCode::Esc, Action::Back, "back"),
    hint("?", KeyCode::Char('?'), Action::Help, "help"),
];

const CALIBRATION_HINTS: &[Hint] = &[
    hint("Up/Down", KeyCode::Down, Action::Down, "recording"),
    hint("r", KeyCode::Char('r'), Action::Run, "read again"),
    hint("Esc", KeyCode::Esc, Action::Back, "back"),
    hint("?", KeyCode::Char('?'), Action::Help, "help"),
    hint("q", KeyCode::Char('q'), Action::Quit, "quit"),
];

const HISTOGRAM_HINTS: &[Hint] = &[
    hint("Enter", KeyCode::Enter, Action::Enter, "suggest"),
    hint("w", KeyCode::Char('w'), Action::Save, "centroids"),
    hint("<- ->", KeyCode::Right, Action::Right, "span"),
    hint("+-", KeyCode::Char('-'), Action::ZoomOut, "length"),
    hint("Home", KeyCode::Home, Action::Home, "30 s"),
    hint("End", KeyCode::End, Action::End, "all"),
    hint("Esc", KeyCode::Esc, Action::Back, "back"),
    hint("?", KeyCode::Char('?'), Action::Help, "help"),
];

/// The status-bar hints of the screen whose keys are `scope`'s, most used
/// first (a narrow terminal shows the first ones). `?` help ends every
/// screen's hints.
pub fn hints(scope: Scope) -> &'static [Hint] {
    match scope {
        Scope::Trials | Scope::Everywhere => TRIALS_HINTS,
        Scope::Trial => TRIAL_HINTS,
        Scope::Compare => COMPARE_HINTS,
        Scope::Limits => LIMITS_HINTS,
        Scope::Views => VIEWS_HINTS,
        Scope::Calibration => CALIBRATION_HINTS,
        Scope::Histogram => HISTOGRAM_HINTS,
    }
}

/// The hints as the status bar shows them.
pub fn hint_line(scope: Scope) -> String {
    hints(scope)
        .iter()
        .map(|h| format!("{} {}", h.keys, h.text))
        .collect::<Vec<_>>()
        .join("  ")
}

/// What the trial screen's figure columns mean (the help lists them after
/// the keys): (label, meaning).
pub const FIGURE_LEGEND: &[(&str, &str)] = &[
    ("out%b", "% outside the limits, before"),
    ("out%a", "% outside, after (variant)"),
    ("exc b", "mean excursion, deg, before"),
    ("exc a", "mean excursion, deg, after"),
    ("shift", "mean |corrected - raw|, deg"),
    ("corr", "mean correction angle, deg"),
    ("exc", "joints: X+Y+Z excursion, deg"),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The README's keys paragraph names every one-character key the help
    /// documents (checked against the keymap, so neither drifts).
    #[test]
    fn readme_keys_match_the_keymap() {
        let readme = include_str!("../../README.md");
        let start = readme
            .find("\nKeys: ")
            .expect("the README's keys paragraph");
        let para = &readme[start..];
        let para = &para[..para.find("\n\n").unwrap_or(para.len())];
        let mut missing = vec![];
        for b in BINDINGS.iter().filter(|b| !b.keys.is_empty()) {
            for k in b.keys.split([' ', '/']).filter(|k| k.chars().count() == 1) {
                if !para.contains(&format!("`{k}`")) {
                    missing.push(format!("{k} ({})", b.help));
                }
            }
        }
        assert!(missing.is_empty(), "not in the README's keys: {missing:?}");
    }

    /// Every key resolves to the action of its first binding; the help-only
    /// rows further down repeat a key with the same action.
    #[test]
    fn repeated_keys_keep_their_action() {
        for (i, b) in BINDINGS.iter().enumerate() {
            for c in b.code {
                let first = BINDINGS.iter().position(|x| x.code.contains(c)).unwrap();
                assert_eq!(BINDINGS[first].action, b.action, "{c:?} in row {i}");
            }
        }
    }
}
