//! The module import graph of a crate, for `cargo xtask tidy`'s rule "no import circles inside a
//! crate" (docs/architecture.md, "Invariants").
//!
//! Every source file under `src/` is a module (`lib.rs` and `main.rs` are the root, `a.rs` and
//! `a/mod.rs` are `a`, `a/b.rs` is `a::b`). Module `A` imports module `B` when the code of `A`
//! (comments, strings and `#[cfg(test)]` modules left out) names a path `crate::…`,
//! `super::…`, `self::…` or, in a `use`, a child module of `A`, and the item it names is defined
//! in `B`. Re-exports (`pub use`) are followed to the module that defines the item and import
//! nothing themselves, so that a facade (`lib.rs`, a `mod.rs` of re-exports) is no part of a
//! circle. A circle is a strongly connected set of two or more modules.

use std::collections::{BTreeMap, BTreeSet};

/// How many re-exports a path is followed through before the resolution stops.
const MAX_REEXPORT_DEPTH: usize = 16;

/// The module path of the file `relative` (relative to the crate's `src/`): `""` for the root,
/// `a::b` for `a/b.rs` or `a/b/mod.rs`; `None` for a file of no module (`bin/`, not `.rs`).
pub fn module_of(relative: &str) -> Option<String> {
    let stem = relative.strip_suffix(".rs")?;
    if stem.starts_with("bin/") {
        return None;
    }
    let mut parts: Vec<&str> = stem.split('/').collect();
    if matches!(parts.last(), Some(&"mod")) {
        parts.pop();
    }
    if matches!(parts.as_slice(), [root] if *root == "lib" || *root == "main") {
        parts.clear();
    }
    Some(parts.join("::"))
}

/// `source` without comments, string and character literals (replaced by nothing, keeping
/// the line breaks) and without the bodies of `#[cfg(test)]` modules.
fn code_of(source: &str) -> String {
    let chars: Vec<char> = source.chars().collect();
    let mut out = String::with_capacity(source.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < chars.len() {
                if chars[i] == '/' && chars.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if chars[i] == '*' && chars.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if chars[i] == '\n' {
                        out.push('\n');
                    }
                    i += 1;
                }
            }
        } else if c == 'r'
            && (next == Some('"') || next == Some('#'))
            && !chars
                .get(i.wrapping_sub(1))
                .is_some_and(|p| p.is_alphanumeric() || *p == '_')
        {
            // A raw string r"…" or r#"…"# (or an identifier such as `r#type`).
            let mut j = i + 1;
            while chars.get(j) == Some(&'#') {
                j += 1;
            }
            if chars.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            let hashes = j - i - 1;
            j += 1;
            while j < chars.len() {
                if chars[j] == '"' && (1..=hashes).all(|k| chars.get(j + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                if chars[j] == '\n' {
                    out.push('\n');
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j;
        } else if c == '"' {
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    i += 1;
                } else if chars[i] == '\n' {
                    out.push('\n');
                }
                i += 1;
            }
            out.push_str("\"\"");
            i += 1;
        } else if c == '\'' {
            // A character literal ('x', '\n', '\u{..}'), else a lifetime.
            if next == Some('\\') {
                i += 2;
                while i < chars.len() && chars[i] != '\'' {
                    i += 1;
                }
                i += 1;
                out.push_str("' '");
            } else if chars.get(i + 2) == Some(&'\'') {
                i += 3;
                out.push_str("' '");
            } else {
                out.push(c);
                i += 1;
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    without_test_modules(&out)
}

/// `code` without the `#[cfg(test)] mod name { … }` blocks.
fn without_test_modules(code: &str) -> String {
    let mut out = String::with_capacity(code.len());
    let mut rest = code;
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let after = &rest[at + "#[cfg(test)]".len()..];
        let trimmed = after.trim_start();
        let is_inline_mod = trimmed
            .strip_prefix("mod ")
            .and_then(|tail| {
                tail.find(['{', ';'])
                    .map(|end| tail.as_bytes()[end] == b'{')
            })
            .unwrap_or(false);
        if !is_inline_mod {
            rest = after;
            continue;
        }
        let open = after.find('{').unwrap_or(after.len());
        let mut depth = 0usize;
        let mut end = after.len();
        for (k, ch) in after[open..].char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = open + k + 1;
                        break;
                    }
                }
                _ => {}
            }
        }
        rest = &after[end..];
    }
    out.push_str(rest);
    out
}

/// The names of the `#[cfg(test)] mod name;` declarations of `code` (test modules in files of
/// their own).
fn test_module_files(source: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut rest = source;
    while let Some(at) = rest.find("#[cfg(test)]") {
        rest = &rest[at + "#[cfg(test)]".len()..];
        let trimmed = rest.trim_start();
        if let Some(tail) = trimmed.strip_prefix("mod ") {
            let name: String = tail
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if tail[name.len()..].trim_start().starts_with(';') {
                names.push(name);
            }
        }
    }
    names
}

/// One `use` item: whether it is a re-export (`pub use`, `pub(crate) use`), and the paths it
/// brings in, each with the name it is known by (`as` renames; `*` for a glob).
struct UseItem {
    public: bool,
    paths: Vec<(Vec<String>, String)>,
}

/// Expands the use tree `tree` (the text between `use` and `;`) under `prefix`.
fn expand_use_tree(tree: &str, prefix: &[String], out: &mut Vec<(Vec<String>, String)>) {
    let tree = tree.trim();
    if tree.is_empty() {
        return;
    }
    // Split at the top-level `{`.
    if let Some(open) = tree.find('{') {
        let head: Vec<String> = split_path(&tree[..open]);
        let close = tree.rfind('}').unwrap_or(tree.len());
        let inner = &tree[open + 1..close];
        let mut base = prefix.to_vec();
        base.extend(head);
        let mut depth = 0usize;
        let mut start = 0;
        for (k, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth = depth.saturating_sub(1),
                ',' if depth == 0 => {
                    expand_use_tree(&inner[start..k], &base, out);
                    start = k + 1;
                }
                _ => {}
            }
        }
        expand_use_tree(&inner[start..], &base, out);
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((path, alias)) => (path, Some(alias.trim().to_string())),
        None => (tree, None),
    };
    let mut full = prefix.to_vec();
    full.extend(split_path(path));
    if full.last().is_some_and(|last| last == "self") {
        full.pop();
    }
    let name = alias.unwrap_or_else(|| full.last().cloned().unwrap_or_default());
    out.push((full, name));
}

/// The segments of the path `text` (`a :: b ::` gives `a`, `b`).
fn split_path(text: &str) -> Vec<String> {
    text.split("::")
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(str::to_string)
        .collect()
}

/// The `use` items of `code` (comments and strings removed).
fn use_items(code: &str) -> Vec<UseItem> {
    let mut items = Vec::new();
    for statement in statements(code) {
        let statement = statement.trim();
        let (public, body) = if let Some(rest) = statement.strip_prefix("pub ") {
            (true, rest.trim_start())
        } else if let Some(rest) = statement.strip_prefix("pub(") {
            let close = rest.find(')').map_or(rest.len(), |c| c + 1);
            (true, rest[close..].trim_start())
        } else {
            (false, statement)
        };
        let Some(tree) = body.strip_prefix("use ") else {
            continue;
        };
        let mut paths = Vec::new();
        expand_use_tree(tree, &[], &mut paths);
        items.push(UseItem { public, paths });
    }
    items
}

/// The `use` statements of `code`: from a `use` (or `pub use`, `pub(…) use`) at the start of a
/// line (after attributes) to its `;`.
fn statements(code: &str) -> Vec<&str> {
    let mut found = Vec::new();
    let mut offset = 0;
    for line in code.split_inclusive('\n') {
        let trimmed = line.trim_start();
        let trimmed = trimmed
            .strip_prefix("#[")
            .and_then(|t| t.find(']').map(|e| t[e + 1..].trim_start()))
            .unwrap_or(trimmed);
        let starts = trimmed.starts_with("use ")
            || trimmed.starts_with("pub use ")
            || (trimmed.starts_with("pub(") && trimmed.contains(") use "));
        if starts {
            let start = offset + (line.len() - trimmed.len());
            if let Some(end) = code[start..].find(';') {
                found.push(&code[start..start + end]);
            }
        }
        offset += line.len();
    }
    found
}

/// Every path of `code` outside `use` statements that starts with `crate::`, `super::`,
/// `self::` or one of `children` (the child modules of the module of `code`).
fn inline_paths(code: &str, children: &[String]) -> Vec<Vec<String>> {
    let mut code = code.to_string();
    for statement in statements(&code.clone()) {
        code = code.replacen(statement, "", 1);
    }
    let mut paths = Vec::new();
    let bytes = code.as_bytes();
    let starts = ["crate", "super", "self"]
        .into_iter()
        .map(str::to_string)
        .chain(children.iter().cloned())
        .map(|name| format!("{name}::"));
    for start in starts {
        for (at, _) in code.match_indices(&start) {
            let before = at.checked_sub(1).map(|b| bytes[b]);
            if before.is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b':') {
                continue;
            }
            let tail: String = code[at..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            paths.push(split_path(&tail));
        }
    }
    paths
}

/// Whether `code` defines an item (or declares a module) called `name`.
fn defines(code: &str, name: &str) -> bool {
    const KINDS: [&str; 10] = [
        "fn ",
        "struct ",
        "enum ",
        "trait ",
        "type ",
        "const ",
        "static ",
        "mod ",
        "union ",
        "macro_rules! ",
    ];
    KINDS.iter().any(|kind| {
        code.match_indices(kind).any(|(at, _)| {
            let before = at.checked_sub(1).map(|b| code.as_bytes()[b]);
            let tail = &code[at + kind.len()..];
            !before.is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_')
                && tail.starts_with(name)
                && !tail[name.len()..]
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_alphanumeric() || c == '_')
        })
    })
}

/// One module: its code and `use` items.
struct Module {
    code: String,
    uses: Vec<UseItem>,
}

/// The import graph of one crate: module path to the modules it imports.
pub type Graph = BTreeMap<String, BTreeSet<String>>;

/// The import graph of the crate whose `src/` files are `files` (path relative to `src/`,
/// contents).
pub fn import_graph(files: &[(String, String)]) -> Graph {
    let mut modules: BTreeMap<String, Module> = BTreeMap::new();
    let mut test_files: BTreeSet<String> = BTreeSet::new();
    for (path, source) in files {
        let Some(name) = module_of(path) else {
            continue;
        };
        for test in test_module_files(source) {
            test_files.insert(join(&name, &test));
        }
        let code = code_of(source);
        let uses = use_items(&code);
        modules.insert(name, Module { code, uses });
    }
    modules.retain(|name, _| !test_files.iter().any(|t| is_within(name, t)));

    let resolver = Resolver { modules: &modules };
    let mut graph = Graph::new();
    for (name, module) in &modules {
        let mut targets = BTreeSet::new();
        let mut paths: Vec<Vec<String>> = module
            .uses
            .iter()
            .filter(|item| !item.public)
            .flat_map(|item| item.paths.iter().map(|(path, _)| path.clone()))
            .collect();
        let children: Vec<String> = modules
            .keys()
            .filter_map(|other| {
                let child = if name.is_empty() {
                    other.as_str()
                } else {
                    other.strip_prefix(name.as_str())?.strip_prefix("::")?
                };
                (!other.is_empty() && !child.contains("::")).then(|| child.to_string())
            })
            .collect();
        paths.extend(inline_paths(&module.code, &children));
        for path in paths {
            if let Some(target) = resolver.resolve(name, &path, 0)
                && &target != name
            {
                targets.insert(target);
            }
        }
        graph.insert(name.clone(), targets);
    }
    graph
}

/// `parent::child`, or `child` under the root.
fn join(parent: &str, child: &str) -> String {
    if parent.is_empty() {
        child.to_string()
    } else {
        format!("{parent}::{child}")
    }
}

/// Whether module `name` is `ancestor` or inside it.
fn is_within(name: &str, ancestor: &str) -> bool {
    name == ancestor || name.starts_with(&format!("{ancestor}::"))
}

/// Resolves paths to the modules that define what they name.
struct Resolver<'a> {
    modules: &'a BTreeMap<String, Module>,
}

impl Resolver<'_> {
    /// The module that defines what `path`, written in module `from`, names; `None` for a path
    /// into another crate.
    fn resolve(&self, from: &str, path: &[String], depth: usize) -> Option<String> {
        let (first, rest) = path.split_first()?;
        let base = match first.as_str() {
            "crate" => String::new(),
            "self" => from.to_string(),
            "super" => {
                let mut base = parent(from);
                let mut rest = rest;
                while let Some((head, tail)) = rest.split_first() {
                    if head != "super" {
                        break;
                    }
                    base = parent(&base);
                    rest = tail;
                }
                return self.walk(base, rest, depth);
            }
            child if self.modules.contains_key(&join(from, child)) => join(from, child),
            // Another crate, or a name brought into scope by a `use`: inline paths are
            // followed from `crate`, `super` and `self` only.
            _ => return None,
        };
        self.walk(base, rest, depth)
    }

    /// Walks `rest` down from module `base` to the module that defines its item.
    fn walk(&self, mut base: String, rest: &[String], depth: usize) -> Option<String> {
        let mut rest = rest;
        while let Some((head, tail)) = rest.split_first() {
            let child = join(&base, head);
            if self.modules.contains_key(&child) {
                base = child;
                rest = tail;
            } else {
                break;
            }
        }
        let Some(item) = rest.first() else {
            return Some(base);
        };
        let module = self.modules.get(&base)?;
        if depth < MAX_REEXPORT_DEPTH && item != "*" {
            // A re-export (or a use) of the name: follow it, unless the module defines it.
            if !defines(&module.code, item) {
                for use_item in &module.uses {
                    for (path, name) in &use_item.paths {
                        if name == item {
                            return self.resolve(&base, path, depth + 1);
                        }
                    }
                }
                for use_item in module.uses.iter().filter(|u| u.public) {
                    for (path, name) in &use_item.paths {
                        if name == "*" {
                            let glob = &path[..path.len() - 1];
                            let mut through = glob.to_vec();
                            through.push(item.clone());
                            if let Some(target) = self.resolve(&base, &through, depth + 1)
                                && self.modules.get(&target).is_some_and(|m| {
                                    defines(&m.code, item)
                                        || m.uses
                                            .iter()
                                            .any(|u| u.paths.iter().any(|(_, n)| n == item))
                                })
                            {
                                return Some(target);
                            }
                        }
                    }
                }
            }
        }
        Some(base)
    }
}

/// The parent of module `name` (the root is its own parent).
fn parent(name: &str) -> String {
    name.rsplit_once("::")
        .map_or(String::new(), |(parent, _)| parent.to_string())
}

/// The circles of `graph`: each strongly connected set of two or more modules, as a closed
/// path through it (`a -> b -> a`), sorted.
pub fn circles(graph: &Graph) -> Vec<Vec<String>> {
    let names: Vec<&String> = graph.keys().collect();
    let index: BTreeMap<&String, usize> = names.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let edges: Vec<Vec<usize>> = names
        .iter()
        .map(|n| {
            graph[*n]
                .iter()
                .filter_map(|t| index.get(t).copied())
                .collect()
        })
        .collect();
    let mut found = Vec::new();
    for component in strongly_connected(&edges) {
        if component.len() < 2 {
            continue;
        }
        let members: BTreeSet<usize> = component.iter().copied().collect();
        let start = *members.iter().next().unwrap_or(&0);
        let cycle = shortest_cycle(&edges, &members, start);
        found.push(cycle.into_iter().map(|i| names[i].clone()).collect());
    }
    found.sort();
    found
}

/// The strongly connected components of the graph `edges` (Tarjan's algorithm, iterative).
fn strongly_connected(edges: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = edges.len();
    let mut index = vec![usize::MAX; n];
    let mut low = vec![0; n];
    let mut on_stack = vec![false; n];
    let mut stack = Vec::new();
    let mut components = Vec::new();
    let mut counter = 0;
    for root in 0..n {
        if index[root] != usize::MAX {
            continue;
        }
        let mut work = vec![(root, 0usize)];
        while let Some(&mut (v, ref mut next)) = work.last_mut() {
            if *next == 0 && index[v] == usize::MAX {
                index[v] = counter;
                low[v] = counter;
                counter += 1;
                stack.push(v);
                on_stack[v] = true;
            }
            if let Some(&w) = edges[v].get(*next) {
                *next += 1;
                if index[w] == usize::MAX {
                    work.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            work.pop();
            if let Some(&(parent, _)) = work.last() {
                low[parent] = low[parent].min(low[v]);
            }
            if low[v] == index[v] {
                let mut component = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                components.push(component);
            }
        }
    }
    components
}

/// The shortest closed path from `start` back to itself inside `members` (breadth first).
fn shortest_cycle(edges: &[Vec<usize>], members: &BTreeSet<usize>, start: usize) -> Vec<usize> {
    let mut previous: BTreeMap<usize, usize> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(v) = queue.pop_front() {
        for &w in &edges[v] {
            if !members.contains(&w) {
                continue;
            }
            if w == start {
                let mut path = vec![start];
                let mut at = v;
                while at != start {
                    path.push(at);
                    at = previous[&at];
                }
                path.push(start);
                let last = path.len() - 1;
                path[1..last].reverse();
                return path;
            }
            if let std::collections::btree_map::Entry::Vacant(entry) = previous.entry(w) {
                entry.insert(v);
                queue.push_back(w);
            }
        }
    }
    vec![start]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(list: &[(&str, &str)]) -> Vec<(String, String)> {
        list.iter()
            .map(|(p, s)| (p.to_string(), s.to_string()))
            .collect()
    }

    #[test]
    fn module_paths_follow_the_file_layout() {
        assert_eq!(module_of("lib.rs").as_deref(), Some(""));
        assert_eq!(module_of("main.rs").as_deref(), Some(""));
        assert_eq!(module_of("a.rs").as_deref(), Some("a"));
        assert_eq!(module_of("a/mod.rs").as_deref(), Some("a"));
        assert_eq!(module_of("a/b.rs").as_deref(), Some("a::b"));
        assert_eq!(module_of("bin/tool.rs"), None);
    }

    #[test]
    fn a_circle_through_a_facade_is_found() {
        let crate_files = files(&[
            (
                "lib.rs",
                "mod a;\nmod b;\npub use a::{A, helper as h};\npub use b::B;\n",
            ),
            (
                "a.rs",
                "use crate::B;\npub struct A(B);\npub fn helper() {}\n",
            ),
            ("b.rs", "pub struct B;\nfn f() { crate::h(); }\n"),
        ]);
        let graph = import_graph(&crate_files);
        assert_eq!(graph["a"], BTreeSet::from(["b".to_string()]));
        assert_eq!(graph["b"], BTreeSet::from(["a".to_string()]));
        assert!(graph[""].is_empty(), "re-exports import nothing");
        assert_eq!(circles(&graph), vec![vec!["a", "b", "a"]]);
    }

    #[test]
    fn a_three_module_circle_through_super_and_globs_is_found() {
        let crate_files = files(&[
            ("lib.rs", "pub mod m;\n"),
            (
                "m/mod.rs",
                "mod x;\nmod y;\npub use x::*;\npub fn top() { y::g(); }\n",
            ),
            ("m/x.rs", "pub fn f() { super::top(); }\n"),
            ("m/y.rs", "use super::f;\npub fn g() { f() }\n"),
        ]);
        let graph = import_graph(&crate_files);
        assert_eq!(graph["m::y"], BTreeSet::from(["m::x".to_string()]));
        assert_eq!(circles(&graph), vec![vec!["m", "m::y", "m::x", "m"]]);
    }

    #[test]
    fn comments_strings_and_tests_import_nothing() {
        let crate_files = files(&[
            ("lib.rs", "mod a;\nmod b;\n"),
            (
                "a.rs",
                "/// See [`f`](crate::b::f).\npub fn g() -> &'static str { \"crate::b::f\" }\n\
                 const C: char = '\"';\n/* crate::b::f */\n",
            ),
            (
                "b.rs",
                "use crate::a::g;\npub fn f() { g(); }\n#[cfg(test)]\nmod tests {\n    \
                 use crate::a::g;\n    #[test]\n    fn t() { crate::a::g(); }\n}\n",
            ),
        ]);
        let graph = import_graph(&crate_files);
        assert!(graph["a"].is_empty(), "{graph:?}");
        assert!(circles(&graph).is_empty());
    }

    #[test]
    fn a_test_module_in_its_own_file_is_left_out() {
        let crate_files = files(&[
            (
                "lib.rs",
                "mod a;\n#[cfg(test)]\nmod tests;\npub fn f() {}\n",
            ),
            ("a.rs", "pub fn g() {}\n"),
            ("tests.rs", "use crate::a::g;\n"),
        ]);
        let graph = import_graph(&crate_files);
        assert!(!graph.contains_key("tests"));
    }
}
