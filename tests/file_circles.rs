//! No two source files name each other in a circle, except autograd's tape and its ops (the
//! tape records ops, ops push onto the tape): README "Where the code lives" (issue 26 item 6).
//! And no lower layer names a higher one (issue 40 item 2): the ground floor (files, drawing,
//! curve statistics) < autograd < nn < envs < algos and policy files < experiment, deploy, plot,
//! render, report < cli, api, bench.
//!
//! A file names another when its code outside `#[cfg(test)]` holds a `crate::`, `super::` or
//! `self::` path (in a `use`, grouped `use` items included, or inline) that resolves to an item
//! of that file's module. Re-exports by bare path in a `mod.rs` (`pub use child::Item`) are the
//! module's public face and are not counted.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The one circle allowed.
const ALLOWED: [&str; 2] = ["autograd/ops/mod.rs", "autograd/tape.rs"];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path of a file: `envs/box_pushing/mod.rs` -> `[envs, box_pushing]`.
fn module_of(file: &str) -> Vec<String> {
    let mut parts: Vec<String> = file
        .trim_end_matches(".rs")
        .split('/')
        .map(str::to_string)
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// Code before the first `#[cfg(test)]`, without line comments.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every path starting at `crate`, `super` or `self` in `code`, as segments after the head,
/// with grouped items expanded (`use super::{a, b::C}` gives `super a` and `super b C`).
fn paths(code: &str) -> Vec<(String, Vec<String>)> {
    let bytes = code.as_bytes();
    let ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut out = Vec::new();
    for head in ["crate", "super", "self"] {
        let mut from = 0;
        while let Some(i) = code[from..].find(head) {
            let at = from + i;
            from = at + head.len();
            if (at > 0 && ident(bytes[at - 1])) || !code[from..].starts_with("::") {
                continue;
            }
            // Segments up to the end of the path, or a group.
            let mut segs = Vec::new();
            let mut rest = &code[from..];
            while let Some(r) = rest.strip_prefix("::") {
                let n = r.bytes().take_while(|&b| ident(b)).count();
                if n == 0 {
                    break;
                }
                segs.push(r[..n].to_string());
                rest = &r[n..];
            }
            if let Some(group) = rest.strip_prefix("::{") {
                let end = group.find('}').unwrap_or(group.len());
                for item in group[..end].split(',') {
                    let item = item.split(" as ").next().unwrap_or("").trim();
                    if item.is_empty() || item == "self" {
                        continue;
                    }
                    let mut s = segs.clone();
                    s.extend(item.split("::").map(|x| x.trim().to_string()));
                    out.push((head.to_string(), s));
                }
            }
            out.push((head.to_string(), segs));
        }
    }
    out
}

#[test]
fn no_two_files_name_each_other_in_a_circle_but_the_tape_and_its_ops() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let names: Vec<String> = files
        .iter()
        .map(|p| p.strip_prefix(&src).unwrap().display().to_string())
        .collect();
    let by_module: BTreeMap<Vec<String>, String> =
        names.iter().map(|n| (module_of(n), n.clone())).collect();
    let resolve = |segs: &[String]| -> Option<String> {
        (1..=segs.len())
            .rev()
            .find_map(|k| by_module.get(&segs[..k]).cloned())
    };
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (path, name) in files.iter().zip(&names) {
        let me = module_of(name);
        let text = code(&std::fs::read_to_string(path).unwrap());
        let targets = edges.entry(name.clone()).or_default();
        for (head, mut segs) in paths(&text) {
            let mut base = match head.as_str() {
                "crate" => Vec::new(),
                "super" => me[..me.len().saturating_sub(1)].to_vec(),
                _ => me.clone(),
            };
            while segs.first().map(String::as_str) == Some("super") {
                base.pop();
                segs.remove(0);
            }
            base.extend(segs);
            if let Some(target) = resolve(&base) {
                if &target != name {
                    targets.insert(target);
                }
            }
        }
    }
    // Files on a circle: those that reach themselves.
    let mut on_circles = BTreeSet::new();
    for start in edges.keys() {
        let mut seen = BTreeSet::new();
        let mut stack: Vec<&String> = edges[start].iter().collect();
        while let Some(f) = stack.pop() {
            if f == start {
                on_circles.insert(start.clone());
                break;
            }
            if seen.insert(f.clone()) {
                stack.extend(edges.get(f).into_iter().flatten());
            }
        }
    }
    let allowed: BTreeSet<String> = ALLOWED.iter().map(|s| s.to_string()).collect();
    assert!(
        on_circles.is_subset(&allowed),
        "files on a circle: {:?}",
        on_circles.difference(&allowed).collect::<Vec<_>>()
    );
    // The check sees circles: the tape and its ops are one.
    assert_eq!(on_circles, allowed);
}

/// The layers, lowest first: a file may name its own layer's modules and lower ones.
const LAYERS: [&[&str]; 7] = [
    &["files", "draw", "curve_stats"],
    &["autograd"],
    &["nn"],
    &["envs"],
    &["algos", "policy_files"],
    &["experiment", "deploy", "plot", "render", "report"],
    &["cli", "api", "bench", "lib", "main"],
];

/// The layer of a top-level module (`lib` and `main` for the crate's root files).
fn layer(top: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&top))
}

/// Every `crate::` path in `code` (a file of top-level module `top`) that names a higher layer's
/// module, as "top -> module (path)"; an unplaced top-level module is an error too.
fn layer_violations(top: &str, code: &str) -> Vec<String> {
    let Some(mine) = layer(top) else {
        return vec![format!(
            "{top}: not in LAYERS (place the new module in a layer)"
        )];
    };
    let mut out = Vec::new();
    for (head, segs) in paths(code) {
        let Some(target) = segs.first().filter(|_| head == "crate") else {
            continue;
        };
        match layer(target) {
            Some(theirs) if theirs <= mine => {}
            Some(_) => out.push(format!("{top} -> {target} (crate::{})", segs.join("::"))),
            None => out.push(format!("{target}: not in LAYERS (named by {top})")),
        }
    }
    out
}

#[test]
fn no_lower_layer_names_a_higher_one() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut violations = Vec::new();
    for path in &files {
        let name = path.strip_prefix(&src).unwrap().display().to_string();
        let top = name.split('/').next().unwrap().trim_end_matches(".rs");
        let text = code(&std::fs::read_to_string(path).unwrap());
        violations.extend(
            layer_violations(top, &text)
                .into_iter()
                .map(|v| format!("{name}: {v}")),
        );
    }
    assert!(violations.is_empty(), "{violations:#?}");
}

#[test]
fn the_layer_check_sees_a_domain_naming_a_learner() {
    let envs = "use crate::algos::actor_critic::published::settings;\nuse crate::nn::Mlp;";
    assert_eq!(
        layer_violations("envs", envs),
        ["envs -> algos (crate::algos::actor_critic::published::settings)"]
    );
    let grouped = "use crate::{autograd::Tape, deploy::Manifest};";
    assert_eq!(
        layer_violations("nn", grouped),
        ["nn -> deploy (crate::deploy::Manifest)"]
    );
    assert!(layer_violations("cli", envs).is_empty());
    assert_eq!(layer_violations("newthing", "").len(), 1);
    // Test code is not held to it (the circles check's `code` keeps only what precedes it).
    let test_only = code("fn f() {}\n#[cfg(test)]\nmod tests { use crate::cli::main; }");
    assert!(layer_violations("envs", &test_only).is_empty());
}
