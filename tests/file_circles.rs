//! No two source files name each other in a circle, except autograd's tape and its ops (the
//! tape records ops, ops push onto the tape): README "Where the code lives" (issue 26 item 6).
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
