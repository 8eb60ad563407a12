//! Where a key sits in a TOML or JSON text: the line and column a message
//! about a value should point to once the text has been read into a struct
//! (which keeps no positions).
//!
//! A key is named by its path from the top: table keys, and for arrays the
//! 0-based index as a decimal segment (`["joint", "2", "proximal"]` is the
//! `proximal` key of the third `[[joint]]`). When the whole path is not in
//! the text, the deepest part of it that is answers; `None` only when not even
//! the first segment is found (or the text does not parse).

use super::line_col;
use std::borrow::Cow;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// 1-based line and column (characters) of the key at `path` in TOML `text`
/// (of the element itself when the path ends at an array index).
pub fn toml_key(text: &str, path: &[&str]) -> Option<(u64, usize)> {
    let root = DeTable::parse(text).ok()?;
    let mut table: &DeTable<'_> = root.get_ref();
    let mut found = None;
    let mut rest = path;
    while let Some((seg, tail)) = rest.split_first() {
        let Some((key, value)) = table.iter().find(|(k, _)| k.get_ref() == seg) else {
            break;
        };
        found = Some(key.span().start);
        rest = tail;
        let mut value: &Spanned<DeValue<'_>> = value;
        // Descend through array indices.
        while let (DeValue::Array(items), Some((idx, tail))) = (value.get_ref(), rest.split_first())
        {
            let Some(item) = idx.parse::<usize>().ok().and_then(|i| items.get(i)) else {
                break;
            };
            found = Some(item.span().start);
            value = item;
            rest = tail;
        }
        match value.get_ref() {
            DeValue::Table(t) => table = t,
            _ => break,
        }
    }
    found.map(|at| line_col(text, at))
}

/// 1-based line and column (characters) of the key at `path` in JSON `text`
/// (its opening quote; of the element itself when the path ends at an array
/// index). The text is expected to be valid JSON (already parsed elsewhere).
pub fn json_key(text: &str, path: &[&str]) -> Option<(u64, usize)> {
    let mut s = Scanner {
        b: text.as_bytes(),
        i: 0,
    };
    s.ws();
    let mut found = None;
    // A path that leaves the text early still answers with what it reached.
    let _ = s.find(path, &mut found);
    found.map(|at| line_col(text, at))
}

/// A cursor over JSON bytes.
struct Scanner<'a> {
    b: &'a [u8],
    i: usize,
}

impl Scanner<'_> {
    fn ws(&mut self) {
        while self.b.get(self.i).is_some_and(u8::is_ascii_whitespace) {
            self.i += 1;
        }
    }

    fn eat(&mut self, c: u8) -> Option<()> {
        self.ws();
        (self.b.get(self.i) == Some(&c)).then(|| self.i += 1)
    }

    /// A string at the cursor, unescaped (enough for key comparison).
    fn string(&mut self) -> Option<Cow<'_, str>> {
        self.ws();
        if self.b.get(self.i) != Some(&b'"') {
            return None;
        }
        let start = self.i + 1;
        let mut j = start;
        let mut escaped = false;
        while let Some(&c) = self.b.get(j) {
            match c {
                b'\\' => {
                    escaped = true;
                    j += 2;
                }
                b'"' => break,
                _ => j += 1,
            }
        }
        let raw = self.b.get(start..j)?;
        self.i = j + 1;
        let raw = std::str::from_utf8(raw).ok()?;
        Some(if escaped {
            Cow::Owned(serde_json::from_str(&format!("\"{raw}\"")).ok()?)
        } else {
            Cow::Borrowed(raw)
        })
    }

    /// Skips the value at the cursor.
    fn skip(&mut self) -> Option<()> {
        self.ws();
        match *self.b.get(self.i)? {
            b'"' => self.string().map(drop),
            open @ (b'{' | b'[') => {
                let close = if open == b'{' { b'}' } else { b']' };
                self.i += 1;
                if self.eat(close).is_some() {
                    return Some(());
                }
                loop {
                    if open == b'{' {
                        self.string()?;
                        self.eat(b':')?;
                    }
                    self.skip()?;
                    if self.eat(b',').is_none() {
                        return self.eat(close);
                    }
                }
            }
            _ => {
                while self
                    .b
                    .get(self.i)
                    .is_some_and(|c| !matches!(c, b',' | b'}' | b']') && !c.is_ascii_whitespace())
                {
                    self.i += 1;
                }
                Some(())
            }
        }
    }

    /// Walks `path` from the value at the cursor, recording in `found` the
    /// byte offset of the deepest key or element reached.
    fn find(&mut self, path: &[&str], found: &mut Option<usize>) -> Option<()> {
        let Some((seg, rest)) = path.split_first() else {
            return Some(());
        };
        self.ws();
        match *self.b.get(self.i)? {
            b'{' => {
                self.i += 1;
                if self.eat(b'}').is_some() {
                    return Some(());
                }
                loop {
                    self.ws();
                    let at = self.i;
                    let key = self.string()?;
                    let hit = key == *seg;
                    self.eat(b':')?;
                    if hit {
                        *found = Some(at);
                        return self.find(rest, found);
                    }
                    self.skip()?;
                    self.eat(b',')?;
                }
            }
            b'[' => {
                let index: usize = seg.parse().ok()?;
                self.i += 1;
                for _ in 0..index {
                    self.skip()?;
                    self.eat(b',')?;
                }
                self.ws();
                if matches!(self.b.get(self.i), Some(b']') | None) {
                    return Some(());
                }
                *found = Some(self.i);
                self.find(rest, found)
            }
            _ => Some(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_toml_keys_in_tables_and_arrays_of_tables() {
        let text = "name = \"m\"\nhop_s = 0\n\n[[joint]]\nname = \"a\"\n\n[[joint]]\nname = \"b\"\n  proximal = \"x\"\n[pose]\nforward = \"+z\"\n";
        assert_eq!(toml_key(text, &["hop_s"]), Some((2, 1)));
        assert_eq!(toml_key(text, &["joint", "1", "proximal"]), Some((9, 3)));
        assert_eq!(toml_key(text, &["pose", "forward"]), Some((11, 1)));
        // The deepest part found answers: joint 1 has no `distal`.
        assert_eq!(toml_key(text, &["joint", "1", "distal"]), Some((7, 1)));
        assert_eq!(toml_key(text, &["nothing"]), None);
        assert_eq!(toml_key("a = [1, 2, 3]", &["a", "2"]), Some((1, 12)));
        assert_eq!(toml_key("x = \"unterminated", &["x"]), None);
    }

    #[test]
    fn finds_json_keys_past_nested_values_and_escapes() {
        let text = "{\n  \"a\": {\"x\": [1, {\"y\": \"}\\\"\"}], \"z\": null},\n  \"settings\": {\n    \"lambda1\": 0.05,\n    \"hop_s\": 0.0\n  },\n  \"list\": [ {\"k\": 1}, {\"k\": 2} ]\n}";
        assert_eq!(json_key(text, &["settings", "hop_s"]), Some((5, 5)));
        assert_eq!(json_key(text, &["settings"]), Some((3, 3)));
        assert_eq!(json_key(text, &["list", "1", "k"]), Some((7, 24)));
        assert_eq!(json_key(text, &["list", "1"]), Some((7, 23)));
        assert_eq!(json_key(text, &["settings", "absent"]), Some((3, 3)));
        assert_eq!(json_key(text, &["absent"]), None);
        assert_eq!(json_key("{\"a\\u0062\": 1}", &["ab"]), Some((1, 2)));
    }
}
