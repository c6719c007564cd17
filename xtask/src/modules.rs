//! `cargo xtask test`'s import-circle check: dependencies between sibling modules point one
//! way.
//!
//! For every folder of modules in the checked crates, the folder's children (its `*.rs` files
//! and its sub-folders with a `mod.rs`) are the nodes, and child A depends on child B when any
//! source of A names B: `crate::<folder path>::B` anywhere in A, or `super::B` in a file that
//! sits directly in the folder (both also as a `{…}` group). Comments, doc links and the test
//! module at the bottom of a file do not count; what a test uses is no design dependency.
//! Any strongly connected group of two or more children is a circle and fails the check,
//! naming its members and what each imports of the others.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// Source roots whose module folders are checked, relative to the workspace root.
pub const CHECKED: [&str; 5] = [
    "protocol/src",
    "firmware/recognizer/src",
    "firmware/store/src",
    "host/src",
    "xtask/src",
];

/// Checks every folder under [`CHECKED`]; fails listing the circles found.
pub fn check(root: &Path) -> Result<()> {
    let mut circles = Vec::new();
    for src in CHECKED {
        let dir = root.join(src);
        if dir.is_dir() {
            check_folder(&dir, &[], &mut circles)?;
        }
    }
    if circles.is_empty() {
        return Ok(());
    }
    bail!(
        "import circles between sibling modules (dependencies must point one way):\n{}",
        circles.join("\n")
    )
}

/// One module: its name and the files of its subtree.
struct Child {
    name: String,
    path: PathBuf,
}

fn children(dir: &Path) -> Result<Vec<Child>> {
    let mut out = Vec::new();
    let entries = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    for e in entries {
        let path = e?.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()).map(str::to_owned) else {
            continue;
        };
        if let Some(stem) = name.strip_suffix(".rs") {
            if !matches!(stem, "lib" | "main" | "mod") {
                out.push(Child {
                    name: stem.to_owned(),
                    path,
                });
            }
        } else if path.join("mod.rs").is_file() {
            out.push(Child { name, path });
        }
    }
    out.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(out)
}

fn sources(path: &Path) -> Result<Vec<PathBuf>> {
    if path.is_file() {
        return Ok(vec![path.to_path_buf()]);
    }
    let mut out = Vec::new();
    for e in std::fs::read_dir(path).with_context(|| format!("reading {}", path.display()))? {
        let p = e?.path();
        if p.is_dir() {
            out.extend(sources(&p)?);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    Ok(out)
}

fn check_folder(dir: &Path, module: &[String], circles: &mut Vec<String>) -> Result<()> {
    let kids = children(dir)?;
    let names: BTreeSet<&str> = kids.iter().map(|c| c.name.as_str()).collect();
    let prefix = format!(
        "crate::{}",
        module.iter().map(|m| format!("{m}::")).collect::<String>()
    );
    let mut graph: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    for kid in &kids {
        let mut named = BTreeSet::new();
        for file in sources(&kid.path)? {
            let text = std::fs::read_to_string(&file)
                .with_context(|| format!("reading {}", file.display()))?;
            let code = design_code(&text);
            named.extend(references(&code, &prefix));
            if kid.path.is_file() && !module.is_empty() {
                named.extend(references(&code, "super::"));
            }
        }
        let deps = names
            .iter()
            .copied()
            .filter(|n| *n != kid.name && named.contains(*n))
            .collect();
        graph.insert(kid.name.as_str(), deps);
    }
    for group in strongly_connected(&graph) {
        let edges: Vec<String> = group
            .iter()
            .map(|a| {
                let inside: Vec<&str> = graph[a]
                    .iter()
                    .copied()
                    .filter(|b| group.contains(b))
                    .collect();
                format!("{a} → {}", inside.join(", "))
            })
            .collect();
        circles.push(format!("  {}: {}", dir.display(), edges.join("; ")));
    }
    for kid in &kids {
        if kid.path.is_dir() {
            let mut sub = module.to_vec();
            sub.push(kid.name.clone());
            check_folder(&kid.path, &sub, circles)?;
        }
    }
    Ok(())
}

/// The code a file's design depends on: without comments, `#[cfg(doc)]` imports and the test
/// module at the bottom.
fn design_code(text: &str) -> String {
    let body = text.find("#[cfg(test)]\nmod ").map_or(text, |i| &text[..i]);
    let mut out = String::new();
    let mut doc_only = false;
    for line in body.lines() {
        let t = line.trim();
        if t.starts_with("//") {
            continue;
        }
        if t.starts_with("#[cfg(doc)]") {
            doc_only = true;
            continue;
        }
        if doc_only {
            doc_only = !t.ends_with(';');
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The first path segment after each `prefix` in `code`, and every first segment of a `{…}`
/// group right after it.
fn references(code: &str, prefix: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        // A longer path that merely ends in the prefix (`my_crate::`) is not it.
        let before = rest[..i].chars().next_back();
        rest = &rest[i + prefix.len()..];
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 1;
            let mut item = String::new();
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    _ => {}
                }
                if depth == 0 || (depth == 1 && c == ',') {
                    out.insert(ident(&item));
                    item.clear();
                    if depth == 0 {
                        break;
                    }
                } else {
                    item.push(c);
                }
            }
        } else {
            out.insert(ident(rest));
        }
    }
    out.remove("");
    out
}

/// Tarjan's strongly connected components of two or more nodes, each sorted.
fn strongly_connected<'a>(graph: &BTreeMap<&'a str, BTreeSet<&'a str>>) -> Vec<Vec<&'a str>> {
    struct State<'a> {
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<&'a str>>,
    }
    fn visit<'a>(v: &'a str, g: &BTreeMap<&'a str, BTreeSet<&'a str>>, s: &mut State<'a>) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on.insert(v);
        for &w in g.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(w, g, s);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if s.on.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on.remove(w);
                group.push(w);
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort_unstable();
                s.out.push(group);
            }
        }
    }
    let mut s = State {
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for &v in graph.keys() {
        if !s.index.contains_key(v) {
            visit(v, graph, &mut s);
        }
    }
    s.out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_and_groups_are_read_and_comments_and_tests_are_not() {
        let code = design_code(
            "use crate::a::b;\nuse super::{c, d::e, f as g};\n/// [`crate::x`]\n\
             #[cfg(doc)]\nuse crate::y;\nfn h() { crate::z::k(); other_crate::q(); }\n\
             #[cfg(test)]\nmod tests { use crate::t; }\n",
        );
        let named = references(&code, "crate::");
        assert_eq!(named, ["a", "z"].map(String::from).into());
        assert_eq!(
            references(&code, "super::"),
            ["c", "d", "f"].map(String::from).into()
        );
    }

    #[test]
    fn a_circle_is_found_and_a_chain_is_not() {
        let g = |edges: &[(&'static str, &'static str)]| {
            let mut g: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
            for &(a, b) in edges {
                g.entry(a).or_default().insert(b);
                g.entry(b).or_default();
            }
            g
        };
        assert!(strongly_connected(&g(&[("a", "b"), ("b", "c")])).is_empty());
        assert_eq!(
            strongly_connected(&g(&[("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")])),
            vec![vec!["a", "b", "c"]]
        );
    }

    #[test]
    fn the_workspace_has_no_import_circles() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        if let Err(e) = check(&root) {
            panic!("{e}");
        }
    }
}
