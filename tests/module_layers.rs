//! The library's layers, read from the source: no two top-level modules
//! (`acm`, `baselines`, `ik`, `trial`, `calibration`, `sidecar`, `simulate`,
//! ...) nor two commands of the command line name each other through any
//! chain; the core names neither the workbench nor the command line; the
//! solvers below the dispatch (`baselines`, `ik`) name no other solver.
//! A module and its own children may name each other.

mod module_graph;

use module_graph::{find_cycle, graph, modules, paths_after, related};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The layer a module belongs to: its top-level module, or for the command
/// line, its command (`cli::plot` for `cli::plot::views`).
fn layer(m: &str) -> String {
    let mut parts = m.split("::");
    match (parts.next(), parts.next()) {
        (Some("cli"), Some(command)) => format!("cli::{command}"),
        (Some(top), _) => top.to_string(),
        _ => String::new(),
    }
}

/// Which layer names which, over every file of `src/`.
fn layers() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let g = graph(&modules(&src, ""), &["acm_workbench"]);
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (m, named) in &g {
        let from = layer(m);
        let to = out.entry(from.clone()).or_default();
        to.extend(
            named
                .iter()
                .map(|n| layer(n))
                .filter(|n| *n != from && !related(&from, n)),
        );
    }
    out
}

#[test]
fn top_level_modules_import_no_cycle() {
    let g = layers();
    for expected in [
        "acm",
        "baselines",
        "ik",
        "trial",
        "calibration",
        "sidecar",
        "cli::plot",
    ] {
        assert!(
            g.contains_key(expected),
            "{expected} not read: {:?}",
            g.keys()
        );
    }
    let nodes: BTreeSet<String> = g.keys().cloned().collect();
    let edges = |m: &str| {
        g.get(m)
            .map(|s| s.iter().cloned().collect())
            .unwrap_or_default()
    };
    let cycle = find_cycle(&nodes, &edges);
    assert!(
        cycle.is_none(),
        "import cycle: {}",
        cycle.unwrap_or_default().join(" -> ")
    );
}

#[test]
fn the_core_names_neither_the_workbench_nor_the_command_line() {
    let g = layers();
    let wrong: Vec<String> = g
        .iter()
        .filter(|(m, _)| *m != "ui" && !m.starts_with("cli"))
        .flat_map(|(m, named)| {
            named
                .iter()
                .filter(|n| *n == "ui" || n.starts_with("cli"))
                .map(move |n| format!("{m} -> {n}"))
        })
        .collect();
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
fn baselines_and_ik_name_no_other_solver() {
    let g = layers();
    for (solver, others) in [("baselines", ["acm", "ik"]), ("ik", ["acm", "baselines"])] {
        for other in others {
            assert!(!g[solver].contains(other), "{solver} -> {other}");
        }
    }
}

#[test]
fn the_reader_expands_groups_and_skips_longer_names() {
    let code = "use crate::{acm::{self, Correction}, trial::Trial};\n\
                let x = my_crate::ik::y; crate::sidecar::write(a, b);";
    assert_eq!(
        paths_after(code, "crate::"),
        [
            "acm::self",
            "acm::Correction",
            "trial::Trial",
            "sidecar::write"
        ]
    );
    assert_eq!(layer("cli::plot::views"), "cli::plot");
    assert_eq!(layer("acm::chain"), "acm");
}
