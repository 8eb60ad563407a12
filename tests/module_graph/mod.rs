//! The module graph of the sources, read from the `use` paths and the full
//! paths (`crate::a::b`, `super::x`, `acm_workbench::a`) of each file: which
//! module names which. Test modules are left out (a test may drive anything
//! above it). Shared by the core's layering test (`tests/module_layers.rs`)
//! and the workbench's (`src/ui/tests/layers.rs`).

#![allow(dead_code)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `ui::screens::views` for `src/ui/screens/views/mod.rs`.
pub fn module_of(root: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(root).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts.join("::")
}

/// The source without its test items (each `#[cfg(test)]` item: a `mod x;`
/// line or a braced block, wherever it stands) and comments.
pub fn code_of(text: &str) -> String {
    let braces = |l: &str| l.matches('{').count() as i64 - l.matches('}').count() as i64;
    let mut out = vec![];
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim() == "#[cfg(test)]" {
            let (mut depth, mut opened) = (0, false);
            for item in lines.by_ref() {
                depth += braces(item);
                opened |= item.contains('{');
                let ends = if opened {
                    depth <= 0
                } else {
                    item.trim_end().ends_with(';')
                };
                if ends {
                    break;
                }
            }
        } else if !line.trim_start().starts_with("//") {
            out.push(line);
        }
    }
    out.join("\n")
}

#[test]
fn test_items_are_left_out_wherever_they_stand() {
    let text = "use crate::a;\n#[cfg(test)]\nmod tests;\nuse crate::b;\n#[cfg(test)]\nfn f() {\n    crate::c();\n}\n// crate::d\nuse crate::e;\n#[cfg(test)]\nmod t {\n    use crate::f;\n}\n";
    assert_eq!(code_of(text), "use crate::a;\nuse crate::b;\nuse crate::e;");
}

fn is_path_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == ':'
}

/// The paths a use tree starting at `tail` names: `a::b` for `a::b::C`,
/// and every branch of a group (`{a, b::{c, d}}`). Returns them with the
/// length of `tail` they took.
fn use_tree(tail: &str) -> (Vec<String>, usize) {
    let end = tail.find(|c: char| !is_path_char(c)).unwrap_or(tail.len());
    let head = tail[..end].trim_end_matches(':');
    let group = tail[end..].starts_with('{') && (end == 0 || tail[..end].ends_with("::"));
    if !group {
        return (vec![head.to_string()], end);
    }
    // A group: split its branches at the commas outside inner groups.
    let body = &tail[end + 1..];
    let (mut out, mut at) = (vec![], 0);
    loop {
        let rest = body[at..].trim_start();
        at = body.len() - rest.len();
        if rest.starts_with('}') || rest.is_empty() {
            at += 1;
            break;
        }
        let (branches, took) = use_tree(rest);
        let join = |b: &String| match (head.is_empty(), b.is_empty()) {
            (_, true) => head.to_string(),
            (true, false) => b.clone(),
            (false, false) => format!("{head}::{b}"),
        };
        out.extend(branches.iter().map(join));
        at += took;
        let rest = &body[at..];
        // Skip to the branch's comma or the group's end (`as x`, spaces).
        let skip = rest.find([',', '}']).unwrap_or(rest.len());
        at += skip;
        if body[at..].starts_with(',') {
            at += 1;
        }
    }
    (out, (end + 1 + at).min(tail.len()))
}

/// Paths like `a::b::c` that follow each `prefix` in `code` (groups expanded).
pub fn paths_after(code: &str, prefix: &str) -> Vec<String> {
    let mut out = vec![];
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        let before = rest[..i].chars().last();
        let tail = &rest[i + prefix.len()..];
        let (paths, took) = use_tree(tail);
        if !before.is_some_and(is_path_char) {
            out.extend(paths);
        }
        rest = &tail[took.max(1).min(tail.len())..];
    }
    out
}

/// The modules of the files under `src/<under>` (all of `src` for ""), by
/// module path, test modules (`tests` and its children) left out.
pub fn modules(src: &Path, under: &str) -> BTreeMap<String, PathBuf> {
    let mut files = vec![];
    rust_files(&src.join(under), &mut files);
    files
        .iter()
        .map(|f| (module_of(src, f), f.clone()))
        .filter(|(m, _)| !m.split("::").any(|p| p == "tests") && m != "lib" && m != "main")
        .collect()
}

fn parent(m: &str) -> String {
    m.rsplit_once("::")
        .map_or(String::new(), |(p, _)| p.to_string())
}

/// Each module and the modules it names: through `crate::` (and the other
/// `roots`, such as the library's name in the binary) and `super::`.
pub fn graph(
    modules: &BTreeMap<String, PathBuf>,
    roots: &[&str],
) -> BTreeMap<String, BTreeSet<String>> {
    let resolve = |path: &str| -> Option<String> {
        let parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
        (1..=parts.len())
            .rev()
            .map(|k| parts[..k].join("::"))
            .find(|m| modules.contains_key(m))
    };
    let mut g = BTreeMap::new();
    for (m, file) in modules {
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        let mut named = BTreeSet::new();
        for root in std::iter::once(&"crate").chain(roots) {
            for p in paths_after(&code, &format!("{root}::")) {
                named.extend(resolve(&p));
            }
        }
        for p in paths_after(&code, "super::") {
            // `super::super::x` is the grandparent's `x`.
            let (mut base, mut rest) = (parent(m), p.as_str());
            while let Some(r) = rest.strip_prefix("super::") {
                base = parent(&base);
                rest = r;
            }
            named.extend(resolve(&format!("{base}::{rest}")));
        }
        named.remove(m);
        g.insert(m.clone(), named);
    }
    g
}

/// Whether `a` is `b`'s ancestor or descendant (a module and its children
/// may name each other).
pub fn related(a: &str, b: &str) -> bool {
    a.starts_with(&format!("{b}::")) || b.starts_with(&format!("{a}::"))
}

/// A cycle of `edges`, if there is one, as the modules along it.
pub fn find_cycle(
    nodes: &BTreeSet<String>,
    edges: &dyn Fn(&str) -> Vec<String>,
) -> Option<Vec<String>> {
    fn visit(
        m: &str,
        edges: &dyn Fn(&str) -> Vec<String>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(m) {
            Some(1) => {
                let k = stack.iter().position(|s| s == m).unwrap_or(0);
                let mut cycle = stack[k..].to_vec();
                cycle.push(m.to_string());
                return Some(cycle);
            }
            Some(_) => return None,
            None => {}
        }
        state.insert(m.to_string(), 1);
        stack.push(m.to_string());
        for n in edges(m) {
            if let Some(c) = visit(&n, edges, state, stack) {
                return Some(c);
            }
        }
        stack.pop();
        state.insert(m.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    nodes
        .iter()
        .find_map(|m| visit(m, edges, &mut state, &mut vec![]))
}
