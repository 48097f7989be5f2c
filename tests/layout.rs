//! The crate's layout holds: every path a library module names (`crate::...`,
//! `super::...`, and in a folder's `mod.rs` its own children) runs down the layers of
//! `src/`, and no module depends on itself through others.
//!
//! The layers, lowest first (`src/lib.rs` tells the same story as a tour):
//! `error`, `finite` < `physics` < `kernels` < `scene` < `engine` < `observe` < `output`
//! < `study` < `workbench`. A module may name modules of its own folder and of the
//! folders below it. The binary (`main.rs`, `cli.rs`) sits on top and uses the public
//! API as `grainlab::`. Test modules (`#[cfg(test)]`) may use anything and are left out.
//!
//! The check reads the source as text: comments, string and character literals are
//! blanked first, so a doc link or a message that names a path is not an import.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The folders (and root files) of `src/`, lowest layer first; one rank per entry, and
/// the root files `error` and `finite` share the lowest.
const LAYERS: &[&[&str]] = &[&["error", "finite"], &["physics"], &["kernels"], &["scene"], &["engine"], &["observe"], &["output"], &["study"], &["workbench"]];

/// Files of the binary, not the library.
const BINARY: &[&str] = &["main.rs", "cli.rs"];

/// The module path of a file relative to `src/`: `engine/world.rs` -> [engine, world],
/// `engine/mod.rs` -> [engine], `lib.rs` -> [].
fn module_of(rel: &str) -> Vec<String> {
    let mut parts: Vec<String> = rel.trim_end_matches(".rs").split('/').map(String::from).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The source with comments, string literals and character literals replaced by spaces
/// (newlines kept), so that only code is left.
fn code_only(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let blank = |ch: char| if ch == '\n' { '\n' } else { ' ' };
    let mut i = 0;
    while i < c.len() {
        let next = c.get(i + 1).copied();
        if c[i] == '/' && next == Some('/') {
            while i < c.len() && c[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c[i] == '/' && next == Some('*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(c[i]));
                    i += 1;
                }
            }
        } else if c[i] == 'r' && matches!(next, Some('"' | '#')) && !(i > 0 && is_ident(c[i - 1])) {
            // A raw string: r"..." or r#"..."#.
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= c.len() {
                    break;
                }
                if c[j] == '"' && (0..hashes).all(|h| c.get(j + 1 + h) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            for &ch in &c[i..j.min(c.len())] {
                out.push(blank(ch));
            }
            i = j;
        } else if c[i] == '"' {
            out.push(' ');
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < c.len() {
                    out.push(blank(c[i]));
                    i += 1;
                }
            }
            out.push(' ');
            i += 1;
        } else if c[i] == '\'' {
            // A character literal ('x', '\n', '\u{e9}'), or a lifetime ('a), left as is.
            let end = if next == Some('\\') {
                (i + 3..c.len()).find(|&j| c[j] == '\'')
            } else if c.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match end {
                Some(e) => {
                    for _ in i..=e {
                        out.push(' ');
                    }
                    i = e + 1;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// `code` without the items marked `#[cfg(test)]` (the item up to its `;`, or its
/// braced body).
fn without_tests(code: &str) -> String {
    let mut out = String::new();
    let mut rest = code;
    while let Some(k) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..k]);
        let item = &rest[k..];
        let open = item.find('{');
        let semi = item.find(';');
        let end = match (open, semi) {
            (Some(o), Some(s)) if s < o => s + 1,
            (None, Some(s)) => s + 1,
            (Some(o), _) => {
                let mut depth = 0;
                let mut end = item.len();
                for (j, ch) in item[o..].char_indices() {
                    match ch {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = o + j + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                end
            }
            (None, None) => item.len(),
        };
        out.extend(item[..end].chars().map(|ch| if ch == '\n' { '\n' } else { ' ' }));
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

fn is_ident(ch: char) -> bool {
    ch.is_alphanumeric() || ch == '_'
}

/// The paths that start at byte `at` of `code` (just after `crate::` or a like prefix),
/// each as its segments after `prefix`, with `{a, b::{c, d}}` groups expanded.
fn paths_at(code: &str, at: usize, prefix: Vec<String>) -> Vec<Vec<String>> {
    let b = code.as_bytes();
    let mut i = at;
    let mut segs = prefix;
    loop {
        while i < b.len() && (b[i] as char).is_whitespace() {
            i += 1;
        }
        if i < b.len() && b[i] == b'{' {
            // A group: split at the top-level commas.
            let mut depth = 0;
            let mut start = i + 1;
            let mut out = Vec::new();
            let mut j = i;
            while j < b.len() {
                match b[j] {
                    b'{' => depth += 1,
                    b'}' | b',' if depth == 1 => {
                        let item = code[start..j].trim();
                        if item == "self" {
                            out.push(segs.clone());
                        } else if !item.is_empty() {
                            out.extend(paths_at(item, 0, segs.clone()));
                        }
                        start = j + 1;
                        if b[j] == b'}' {
                            break;
                        }
                    }
                    b'}' => depth -= 1,
                    _ => {}
                }
                j += 1;
            }
            return out;
        }
        let s = i;
        while i < b.len() && is_ident(b[i] as char) {
            i += 1;
        }
        if i == s {
            return vec![segs];
        }
        segs.push(code[s..i].to_string());
        if code[i..].starts_with("::") {
            i += 2;
        } else {
            return vec![segs];
        }
    }
}

/// Every module path `code` (of module `me`, whose children are `children`) names: after
/// `crate::`, after `super::` (relative to `me`), and the children named bare.
fn named_paths(code: &str, me: &[String], children: &BTreeSet<String>) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let b = code.as_bytes();
    let starts_token = |k: usize| k == 0 || !(is_ident(b[k - 1] as char) || b[k - 1] == b':');
    for (k, _) in code.match_indices("crate::") {
        if starts_token(k) {
            out.extend(paths_at(code, k + "crate::".len(), Vec::new()));
        }
    }
    for (k, _) in code.match_indices("super::") {
        if starts_token(k) {
            let mut up = 1;
            let mut at = k + "super::".len();
            while code[at..].starts_with("super::") {
                up += 1;
                at += "super::".len();
            }
            let base = me[..me.len().saturating_sub(up)].to_vec();
            out.extend(paths_at(code, at, base));
        }
    }
    for child in children {
        let pat = format!("{child}::");
        for (k, _) in code.match_indices(&pat) {
            if starts_token(k) {
                let mut base = me.to_vec();
                base.push(child.clone());
                out.extend(paths_at(code, k + pat.len(), base));
            }
        }
        // `pub use child::*;`, `use child::{..}` are caught above; `pub mod child;` is a
        // declaration, not a use.
    }
    out
}

/// The dependency graph: module -> the modules it names (the longest module prefix of
/// each path), without itself.
fn graph(files: &BTreeMap<String, String>) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let modules: BTreeSet<Vec<String>> = files.keys().map(|f| module_of(f)).collect();
    let mut g = BTreeMap::new();
    for (rel, src) in files {
        let me = module_of(rel);
        let children: BTreeSet<String> = if rel.ends_with("mod.rs") {
            modules.iter().filter(|m| m.len() == me.len() + 1 && m.starts_with(&me)).map(|m| m[me.len()].clone()).collect()
        } else {
            BTreeSet::new()
        };
        let code = without_tests(&code_only(src));
        let mut deps = BTreeSet::new();
        for path in named_paths(&code, &me, &children) {
            let target = (0..=path.len()).rev().map(|k| path[..k].to_vec()).find(|p| modules.contains(p)).unwrap_or_default();
            if target != me && !target.is_empty() {
                deps.insert(target);
            }
        }
        g.insert(me, deps);
    }
    g
}

fn rank(module: &[String]) -> Option<usize> {
    let top = module.first()?;
    LAYERS.iter().position(|layer| layer.contains(&top.as_str()))
}

fn name(m: &[String]) -> String {
    if m.is_empty() { "crate".into() } else { m.join("::") }
}

/// Every import that runs up the layers (or from a module outside them).
fn upward(g: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<String> {
    let mut bad = Vec::new();
    for (from, deps) in g {
        if from.is_empty() {
            continue; // lib.rs: the tour and the re-exports
        }
        for to in deps {
            match (rank(from), rank(to)) {
                (Some(a), Some(b)) if b > a => bad.push(format!("{} -> {} (layer {} imports layer {})", name(from), name(to), a, b)),
                (Some(a), Some(b)) if a == b && from[0] != to[0] => bad.push(format!("{} -> {} (two modules of the lowest layer)", name(from), name(to))),
                (None, _) => bad.push(format!("{} is in no layer", name(from))),
                (_, None) => bad.push(format!("{} -> {}, which is in no layer", name(from), name(to))),
                _ => {}
            }
        }
    }
    bad.sort();
    bad.dedup();
    bad
}

/// The cycles: strongly connected components of more than one module (Tarjan).
fn cycles(g: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<&'a [String], usize>,
        low: BTreeMap<&'a [String], usize>,
        stack: Vec<&'a [String]>,
        on: BTreeSet<&'a [String]>,
        found: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a [String]) {
        let k = t.index.len();
        t.index.insert(v, k);
        t.low.insert(v, k);
        t.stack.push(v);
        t.on.insert(v);
        if let Some(deps) = t.g.get(v) {
            for w in deps {
                let w = w.as_slice();
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let lw = t.low[w];
                    let lv = t.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if t.on.contains(w) {
                    let iw = t.index[w];
                    let lv = t.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(w);
                comp.push(name(w));
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.found.push(comp);
            }
        }
    }
    let mut t = T { g, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), on: BTreeSet::new(), found: Vec::new() };
    for v in g.keys() {
        if !t.index.contains_key(v.as_slice()) {
            visit(&mut t, v);
        }
    }
    t.found
}

fn library_sources() -> BTreeMap<String, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<String, String>) {
        for entry in std::fs::read_dir(dir).expect("src/ is readable") {
            let path = entry.expect("an entry").path();
            if path.is_dir() {
                walk(&path, root, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
                if !BINARY.contains(&rel.as_str()) {
                    out.insert(rel, std::fs::read_to_string(&path).expect("a source file"));
                }
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = BTreeMap::new();
    walk(&root, &root, &mut out);
    out
}

#[test]
fn imports_run_down_the_layers_without_cycles() {
    let files = library_sources();
    assert!(files.len() > 40 && files.contains_key("engine/world.rs"), "the check reads src/ ({} files)", files.len());
    let g = graph(&files);
    // The check sees the imports it is about: a module that names none would make it
    // pass vacuously.
    let edges: usize = g.values().map(BTreeSet::len).sum();
    assert!(edges > 150, "only {edges} imports found");
    assert!(g[&module_of("engine/build.rs")].contains(&module_of("physics/walls.rs")));
    let up = upward(&g);
    assert!(up.is_empty(), "imports that run up the layers:\n  {}", up.join("\n  "));
    let cyc = cycles(&g);
    assert!(cyc.is_empty(), "import cycles:\n  {}", cyc.iter().map(|c| c.join(" <-> ")).collect::<Vec<_>>().join("\n  "));
}

/// Every library file sits in a layer: a new folder must be placed in `LAYERS`.
#[test]
fn every_module_is_in_a_layer() {
    let files = library_sources();
    let loose: Vec<&String> = files.keys().filter(|f| f.as_str() != "lib.rs" && rank(&module_of(f)).is_none()).collect();
    assert!(loose.is_empty(), "files in no layer: {loose:?}");
}

/// The check itself catches what it is for, on made-up sources: an upward import (also
/// through a group, `super::` and a bare child path), a cycle, and it ignores comments,
/// strings and test modules.
#[test]
fn the_check_catches_upward_imports_and_cycles() {
    let src = |pairs: &[(&str, &str)]| pairs.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect::<BTreeMap<_, _>>();
    // Clean: downward imports, with upward paths only in comments, strings, tests.
    let clean = src(&[
        ("physics/mod.rs", "pub mod dim;\npub mod walls;\n"),
        ("physics/dim.rs", "pub type V = f64; // crate::engine::world\n"),
        ("physics/walls.rs", "use super::dim::V;\nconst S: &str = \"crate::engine::world\";\n#[cfg(test)]\nmod tests { use crate::engine::world::W; }\n"),
        ("engine/mod.rs", "pub mod world;\n"),
        ("engine/world.rs", "use crate::physics::{dim::V, walls};\n/* crate::study */\n"),
    ]);
    let g = graph(&clean);
    assert!(upward(&g).is_empty(), "{:?}", upward(&g));
    assert!(cycles(&g).is_empty());
    assert!(g[&module_of("engine/world.rs")].contains(&module_of("physics/walls.rs")));
    assert!(g[&module_of("physics/walls.rs")].contains(&module_of("physics/dim.rs")));
    // Upward, through a nested group.
    let mut up = clean.clone();
    up.insert("physics/dim.rs".into(), "use crate::{engine::{world::W}, error};\n".into());
    assert_eq!(upward(&graph(&up)), vec!["physics::dim -> engine::world (layer 1 imports layer 4)".to_string()]);
    // Upward through super::super.
    let mut up = clean.clone();
    up.insert("physics/walls.rs".into(), "fn f() { super::super::engine::world::go() }\n".into());
    assert_eq!(upward(&graph(&up)).len(), 1);
    // A cycle inside a folder, one side through the folder's mod.rs naming a child bare.
    let mut cyc = clean.clone();
    cyc.insert("physics/mod.rs".into(), "pub mod dim;\npub mod walls;\npub fn f() { walls::g() }\n".into());
    cyc.insert("physics/walls.rs".into(), "use crate::physics::f;\n".into());
    assert_eq!(cycles(&graph(&cyc)), vec![vec!["physics".to_string(), "physics::walls".to_string()]]);
}
