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

/// The crates of the terminal and the command line, which the core must not pull.
const TERMINAL_CRATES: [&str; 5] = ["clap", "ratatui", "crossterm", "notify", "signal-hook"];

/// The package names in `cargo tree`'s normal (non-dev, non-build) dependency
/// tree of this package with the given feature flags, read offline from the lock file.
fn normal_dependencies(features: &[&str]) -> BTreeSet<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["tree", "--offline", "-e", "normal", "--prefix", "none"])
        .args(["--format", "{p}", "-p", "acm-workbench"])
        .args(features)
        .output()
        .expect("run cargo tree");
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

#[test]
fn the_library_alone_pulls_no_terminal_crate() {
    let core = normal_dependencies(&["--no-default-features"]);
    assert!(
        core.contains("nalgebra") && core.contains("csv"),
        "{core:?}"
    );
    let pulled: Vec<&str> = TERMINAL_CRATES
        .iter()
        .copied()
        .filter(|c| {
            core.iter().any(|d| {
                d == c || d.starts_with(&format!("{c}-")) || d.starts_with(&format!("{c}_"))
            })
        })
        .collect();
    assert!(pulled.is_empty(), "the core pulls {pulled:?}");
    // The same query with the workbench's feature lists them all, so the test can fail.
    let full = normal_dependencies(&[]);
    for c in TERMINAL_CRATES {
        assert!(
            full.contains(c),
            "{c} missing from the full tree: the query reads nothing"
        );
    }
}
