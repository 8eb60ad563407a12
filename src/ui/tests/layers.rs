//! The workbench's module layers, read from the source: a screen names no
//! other screen and not the router (opening another screen is a returned
//! navigation), and no two modules of the workbench import each other
//! through any chain. Test modules are left out: they may drive the router.

#[path = "../../../tests/module_graph/mod.rs"]
mod module_graph;

use module_graph::{code_of, find_cycle, module_of, paths_after, related};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Modules that route or drive the screens; a screen names none of them.
const ROUTER: [&str; 4] = ["ui::app", "ui::render", "ui::runtime", "ui::headless"];

/// The workbench's modules and the modules each one names.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    module_graph::graph(&module_graph::modules(&src, "ui"), &[])
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
            .map(|s| s.iter().filter(|n| !related(m, n)).cloned().collect())
            .unwrap_or_default()
    };
    let nodes: BTreeSet<String> = g.keys().cloned().collect();
    let cycle = find_cycle(&nodes, &edges);
    assert!(
        cycle.is_none(),
        "import cycle: {}",
        cycle.unwrap_or_default().join(" -> ")
    );
}

#[test]
fn the_reader_resolves_the_forms_in_use() {
    // The reader must resolve the forms the workbench uses.
    let code = "use super::app::{App};\nlet x = crate::ui::msg::Nav::To;\n// super::render\n";
    assert_eq!(paths_after(&code_of(code), "super::"), ["app::App"]);
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
