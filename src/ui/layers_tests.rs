//! The workbench's module layers, read from the source: a screen names no
//! other screen and not the router (opening another screen is a returned
//! navigation), and no two modules of the workbench import each other
//! through any chain. Test modules are left out: they may drive the router.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Modules that route or drive the screens; a screen names none of them.
const ROUTER: [&str; 4] = ["ui::app", "ui::render", "ui::runtime", "ui::headless"];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
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
fn module_of(root: &Path, file: &Path) -> String {
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

/// The source without its test module and comments.
fn code_of(text: &str) -> String {
    let code = text.split("#[cfg(test)]").next().unwrap_or("");
    code.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Paths like `a::b::c` that follow each `prefix` in `code`.
fn paths_after<'a>(code: &'a str, prefix: &str) -> Vec<&'a str> {
    let mut out = vec![];
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        let before = rest[..i].chars().last();
        let tail = &rest[i + prefix.len()..];
        let end = tail
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
            .unwrap_or(tail.len());
        if !before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':') {
            out.push(tail[..end].trim_end_matches(':'));
        }
        rest = &tail[end..];
    }
    out
}

/// The workbench's modules and the modules each one names.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = vec![];
    rust_files(&src.join("ui"), &mut files);
    let modules: BTreeMap<String, PathBuf> = files
        .iter()
        .map(|f| (module_of(&src, f), f.clone()))
        .filter(|(m, _)| !m.ends_with("tests"))
        .collect();
    let resolve = |path: &str| -> Option<String> {
        let parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
        (1..=parts.len())
            .rev()
            .map(|k| parts[..k].join("::"))
            .find(|m| modules.contains_key(m))
    };
    let mut g = BTreeMap::new();
    for (m, file) in &modules {
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        let parent = |x: &str| {
            x.rsplit_once("::")
                .map_or(String::new(), |(p, _)| p.to_string())
        };
        let mut named = BTreeSet::new();
        for p in paths_after(&code, "crate::ui::") {
            named.extend(resolve(&format!("ui::{p}")));
        }
        for p in paths_after(&code, "super::") {
            // `super::super::x` is the grandparent's `x`.
            let (mut base, mut rest) = (parent(m), p);
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

/// The screen a module belongs to (`ui::screens::views` for its children).
fn screen_of(m: &str) -> Option<String> {
    let rest = m.strip_prefix("ui::screens::")?;
    Some(format!("ui::screens::{}", rest.split("::").next()?))
}

#[test]
fn no_screen_names_another_screen_or_the_router() {
    let g = graph();
    assert!(g.contains_key("ui::screens::trials"), "{:?}", g.keys());
    let mut wrong = vec![];
    for (m, named) in &g {
        let Some(own) = screen_of(m) else { continue };
        for n in named {
            let other_screen = screen_of(n).is_some_and(|s| s != own);
            if other_screen || ROUTER.contains(&n.as_str()) {
                wrong.push(format!("{m} -> {n}"));
            }
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
fn workbench_modules_import_no_cycle() {
    let g = graph();
    // A module's own children (a screen folder's views) may name it back.
    let edges = |m: &str| -> Vec<String> {
        g.get(m)
            .map(|s| {
                s.iter()
                    .filter(|n| {
                        !(n.starts_with(&format!("{m}::")) || m.starts_with(&format!("{n}::")))
                    })
                    .cloned()
                    .collect()
            })
            .unwrap_or_default()
    };
    // Depth-first search for a back edge.
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
    for m in g.keys() {
        let cycle = visit(m, &edges, &mut state, &mut vec![]);
        assert!(
            cycle.is_none(),
            "import cycle: {}",
            cycle.unwrap().join(" -> ")
        );
    }
}

#[test]
fn the_reader_resolves_the_forms_in_use() {
    // The reader must resolve the forms the workbench uses.
    let code = "use super::app::{App};\nlet x = crate::ui::msg::Nav::To;\n// super::render\n";
    assert_eq!(paths_after(&code_of(code), "super::"), ["app"]);
    assert_eq!(
        paths_after(code_of(code).as_str(), "crate::ui::"),
        ["msg::Nav::To"]
    );
    assert_eq!(
        module_of(Path::new("/s"), Path::new("/s/ui/screens/views/mod.rs")),
        "ui::screens::views"
    );
    assert_eq!(
        screen_of("ui::screens::views::scatter").as_deref(),
        Some("ui::screens::views")
    );
}
