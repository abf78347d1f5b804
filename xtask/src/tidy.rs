//! `cargo xtask tidy`: the rules of the repository that a reviewer would otherwise have to
//! remember, checked by machine. `cargo xtask ci` runs it before the tests.
//!
//! - Every test that `docs/bad-input.md` names exists: each `` `crate/path.rs::name` `` (also
//!   `::module::name`, `::{a, b}`, and `::tests::*` for every test of a file) points at a file
//!   that defines `fn name`.
//! - Every crate's README is its crate documentation (`#![doc = include_str!("../README.md")]`
//!   in `src/lib.rs` or `src/main.rs`), so its Rust blocks are doctests.
//! - No README cites a file outside the repository: a relative link or a quoted path
//!   (`` `docs/theory.md` ``) resolves to a file of the repository (from the README's folder or
//!   the root), a link into the repository's URL names a file that exists, a crate README (which
//!   crates.io and docs.rs show without the rest of the repository) has no relative link leaving
//!   its crate, and no README names an absolute path.
//! - Invariants of `docs/architecture.md`: every crate takes its lints from `[workspace.lints]`;
//!   every public error enum of a library crate is `#[non_exhaustive]`; no library code (every
//!   crate but [`FRONT_ENDS`], tests aside) names `Result<_, String>`, and no error enum has a
//!   message-only variant (its one field a `String`, unnamed or named `message`, `reason` or
//!   `error`); `lane-math` depends on none of the other crates, `fuzzy-sugeno` on none but `lane-math`, and no library crate depends on the command line;
//!   `unsafe` code appears only in the library files [`UNSAFE_FILES`] lists, each block under a
//!   `// SAFETY:` comment.
//! - `sim-core` depends on none of [`LOOP_FORBIDS`].
//! - No import circles among the modules of a crate ([`crate::imports`]).
//! - The command line writes through its `console` module only: no `print!`, `println!`,
//!   `eprint!` or `eprintln!` elsewhere in `hrm-cli` (they panic when the reader has gone away).
//! - `cargo doc --workspace --no-deps` with `RUSTDOCFLAGS=-D warnings`.
//!
//! Each check is a function of file contents (the file system is read in [`run`] only), with a
//! unit test that feeds it a bad input.

use std::path::{Component, Path, PathBuf};

/// The repository's address; links into it must name files that exist.
const REPOSITORY: &str = "https://github.com/hrm-toolkit/hrm";

/// The only library source files allowed `unsafe` code (docs/architecture.md, "Unsafe code"),
/// each block under a `// SAFETY:` comment.
const UNSAFE_FILES: [&str; 1] = ["crates/fuzzy-sugeno/src/kernel.rs"];

/// The crates under `crates/` that are front ends, not libraries: the string rules do not apply.
const FRONT_ENDS: [&str; 3] = ["hrm-cli", "hrm-py", "test-support"];

/// What the closed loop (`sim-core`) must not depend on: files, hashes and threads belong to
/// the studies above it.
const LOOP_FORBIDS: [&str; 4] = ["serde_json", "sha2", "rayon", "toml"];

/// The workspace's library crates (published, usable alone).
const LIBRARIES: [&str; 11] = [
    "lane-math",
    "backbone-kin",
    "manip-dyn",
    "robot-desc",
    "clearance",
    "modal-reduce",
    "fuzzy-sugeno",
    "optimal-ctl",
    "sim-core",
    "sim-study",
    "hrm",
];

/// Runs every check against the repository at `root` (then `cargo doc` through `doc`) and
/// returns the problems found, one line each.
pub fn run(root: &Path, doc: impl FnOnce() -> Result<(), String>) -> Vec<String> {
    let mut problems = Vec::new();
    let read = |path: &Path| std::fs::read_to_string(root.join(path));

    match read(Path::new("docs/bad-input.md")) {
        Ok(text) => {
            for reference in test_references(&text) {
                let path = Path::new("crates").join(&reference.file);
                let source = read(&path).unwrap_or_default();
                for name in reference.names {
                    if !defines_fn(&source, &name) {
                        problems.push(format!(
                            "docs/bad-input.md names {}::{name}, but {} defines no `fn {name}` and no refusal-table row \"{name}\"",
                            reference.file,
                            path.display()
                        ));
                    }
                }
            }
        }
        Err(e) => problems.push(format!("docs/bad-input.md: {e}")),
    }

    let crates = list_dir(&root.join("crates"));
    for krate in &crates {
        let dir = Path::new("crates").join(krate);
        let roots = ["src/lib.rs", "src/main.rs"].map(|file| read(&dir.join(file)).ok());
        if !roots.iter().flatten().any(|source| includes_readme(source)) {
            problems.push(format!(
                "{}: the crate root does not include README.md as its documentation \
                 (#![doc = include_str!(\"../README.md\")])",
                dir.display()
            ));
        }
        match read(&dir.join("Cargo.toml")) {
            Ok(manifest) => {
                if !uses_workspace_lints(&manifest) {
                    problems.push(format!(
                        "{}/Cargo.toml: no `[lints] workspace = true`",
                        dir.display()
                    ));
                }
                // The bottom crates may use only the listed crates of ours; every library is
                // kept off the command line.
                let allowed: Option<&[&str]> = match krate.as_str() {
                    "lane-math" => Some(&[]),
                    "fuzzy-sugeno" => Some(&["lane-math"]),
                    _ => None,
                };
                let forbidden: Vec<&str> = match allowed {
                    Some(allowed) => LIBRARIES
                        .iter()
                        .chain(&["hrm-cli"])
                        .copied()
                        .filter(|other| *other != krate.as_str() && !allowed.contains(other))
                        .collect(),
                    None if LIBRARIES.contains(&krate.as_str()) => vec!["hrm-cli"],
                    None => Vec::new(),
                };
                for dependency in dependencies(&manifest) {
                    if krate == "sim-core" && LOOP_FORBIDS.contains(&dependency.as_str()) {
                        problems.push(format!(
                            "{}/Cargo.toml: the loop crate must not depend on {dependency} \
                             (docs/architecture.md, \"Invariants\")",
                            dir.display()
                        ));
                    }
                    if forbidden.contains(&dependency.as_str()) {
                        problems.push(format!(
                            "{}/Cargo.toml: {krate} must not depend on {dependency} \
                             (docs/architecture.md, \"Library crates are usable alone\")",
                            dir.display()
                        ));
                    }
                }
            }
            Err(e) => problems.push(format!("{}/Cargo.toml: {e}", dir.display())),
        }
        problems.extend(import_circles(root, &dir));
        if LIBRARIES.contains(&krate.as_str()) {
            for file in rust_files(&root.join(&dir).join("src")) {
                let source = std::fs::read_to_string(&file).unwrap_or_default();
                let relative = file.strip_prefix(root).unwrap_or(&file);
                for name in exhaustive_error_enums(&source) {
                    problems.push(format!(
                        "{}: the public error enum {name} is not #[non_exhaustive]",
                        relative.display()
                    ));
                }
                let allowed = UNSAFE_FILES.iter().any(|f| Path::new(f) == relative);
                for (line, problem) in unsafe_problems(&source, allowed) {
                    problems.push(format!("{}:{line}: {problem}", relative.display()));
                }
            }
        }
    }

    for krate in crates.iter().filter(|k| !FRONT_ENDS.contains(&k.as_str())) {
        let dir = Path::new("crates").join(krate);
        for file in rust_files(&root.join(&dir).join("src")) {
            let source = std::fs::read_to_string(&file).unwrap_or_default();
            let relative = file.strip_prefix(root).unwrap_or(&file);
            problems.extend(string_problems(&relative.display().to_string(), &source));
        }
    }

    let cli = Path::new("crates/hrm-cli/src");
    for file in rust_files(&root.join(cli)) {
        let relative = file.strip_prefix(root).unwrap_or(&file);
        if relative == cli.join("console.rs") {
            continue;
        }
        let source = std::fs::read_to_string(&file).unwrap_or_default();
        for line in print_macros(&source) {
            problems.push(format!(
                "{}:{line}: prints with a std macro, not through `console` (a broken pipe panics)",
                relative.display()
            ));
        }
    }

    let mut readmes: Vec<(PathBuf, bool)> = vec![(PathBuf::from("README.md"), false)];
    readmes.extend(
        crates
            .iter()
            .map(|krate| (Path::new("crates").join(krate).join("README.md"), true)),
    );
    readmes.push((PathBuf::from("fuzz/README.md"), false));
    for (readme, is_crate) in readmes {
        match read(&readme) {
            Ok(text) => {
                let exists = |path: &Path| root.join(path).exists();
                problems.extend(
                    citation_problems(&readme, &text, is_crate, exists)
                        .into_iter()
                        .map(|problem| format!("{}: {problem}", readme.display())),
                );
            }
            Err(e) => problems.push(format!("{}: {e}", readme.display())),
        }
    }

    if let Err(e) = doc() {
        problems.push(e);
    }
    problems
}

/// The import circles among the modules of the crate in `dir` ([`crate::imports`]), one line
/// each.
fn import_circles(root: &Path, dir: &Path) -> Vec<String> {
    let src = root.join(dir).join("src");
    let files: Vec<(String, String)> = rust_files(&src)
        .into_iter()
        .filter_map(|file| {
            let relative = file
                .strip_prefix(&src)
                .ok()?
                .to_string_lossy()
                .replace('\\', "/");
            Some((relative, std::fs::read_to_string(&file).ok()?))
        })
        .collect();
    crate::imports::circles(&crate::imports::import_graph(&files))
        .into_iter()
        .map(|circle| {
            let named: Vec<String> = circle
                .iter()
                .map(|m| {
                    if m.is_empty() {
                        "crate".to_string()
                    } else {
                        m.clone()
                    }
                })
                .collect();
            format!(
                "{}/src: import circle {} (docs/architecture.md, \"No import circles\")",
                dir.display(),
                named.join(" -> ")
            )
        })
        .collect()
}

/// Tests named by a row of `docs/bad-input.md`: a file under `crates/` and the functions in it.
#[derive(Debug, PartialEq)]
pub struct TestReference {
    /// `crate/path.rs`, relative to `crates/`.
    pub file: String,
    /// The test functions (the last segment of each path).
    pub names: Vec<String>,
}

/// Every `` `crate/path.rs::name` `` in `text`; `::module::name` names `name`, `::{a, b}` names
/// both.
pub fn test_references(text: &str) -> Vec<TestReference> {
    let mut references = Vec::new();
    for span in text.split('`').skip(1).step_by(2) {
        let Some((file, item)) = span.split_once("::") else {
            continue;
        };
        let is_path = file.ends_with(".rs")
            && file.contains('/')
            && file
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_/.".contains(c));
        if !is_path {
            continue;
        }
        let item = item.trim();
        // `path::{a, b}`: the names in the braces (after any module path such as `tests::`).
        let braces = item.find('{').map_or(item, |at| &item[at..]);
        let names = match braces.strip_prefix('{').and_then(|i| i.strip_suffix('}')) {
            Some(list) => list.split(',').map(str::trim).collect(),
            None => vec![item],
        };
        let names = names
            .into_iter()
            .map(|name| name.rsplit("::").next().unwrap_or(name).to_string())
            .collect();
        references.push(TestReference {
            file: file.to_string(),
            names,
        });
    }
    references
}

/// Whether `source` defines the test `name`: a function `fn name(` or `fn name<`, or a row of a
/// refusal table named by the string literal `"name"` (the tables of `test_support::refusal`);
/// the name `*` (every test of a module) asks for at least one `#[test]`.
pub fn defines_fn(source: &str, name: &str) -> bool {
    if name == "*" {
        return source.contains("#[test]");
    }
    if source.contains(&format!("\"{name}\"")) {
        return true;
    }
    source.match_indices("fn ").any(|(at, _)| {
        let rest = source[at + 3..].trim_start();
        rest.strip_prefix(name)
            .is_some_and(|after| after.trim_start().starts_with(['(', '<']))
            && source[..at]
                .chars()
                .last()
                .is_none_or(|c| !(c.is_alphanumeric() || c == '_'))
    })
}

/// Whether a crate root takes its documentation from the crate's README.
pub fn includes_readme(source: &str) -> bool {
    source
        .lines()
        .any(|line| line.trim() == "#![doc = include_str!(\"../README.md\")]")
}

/// Whether a manifest takes its lints from the workspace.
pub fn uses_workspace_lints(manifest: &str) -> bool {
    let mut in_lints = false;
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            in_lints = line == "[lints]";
        } else if in_lints && line.replace(' ', "") == "workspace=true" {
            return true;
        }
    }
    manifest
        .lines()
        .any(|line| line.replace(' ', "") == "lints.workspace=true")
}

/// The names of a manifest's normal dependencies (not dev- or build-dependencies).
pub fn dependencies(manifest: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut in_dependencies = false;
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            in_dependencies = line == "[dependencies]";
        } else if in_dependencies
            && let Some(name) = line.split(['=', '.', ' ']).next()
            && !name.is_empty()
            && !name.starts_with('#')
        {
            names.push(name.to_string());
        }
    }
    names
}

/// The public error enums (`pub enum ...Error`) of `source` that lack `#[non_exhaustive]` among
/// the attributes above them.
pub fn exhaustive_error_enums(source: &str) -> Vec<String> {
    let lines: Vec<&str> = source.lines().collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some(rest) = line.trim().strip_prefix("pub enum ") else {
            continue;
        };
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !name.ends_with("Error") {
            continue;
        }
        let attributes = lines[..i]
            .iter()
            .rev()
            .map(|l| l.trim())
            .take_while(|l| l.starts_with("#[") || l.starts_with("///") || l.starts_with(')'));
        if !attributes.into_iter().any(|l| l == "#[non_exhaustive]") {
            found.push(name);
        }
    }
    found
}

/// The string-error problems of the library file `path`: each `Result<_, String>` and
/// message-only error variant.
pub fn string_problems(path: &str, source: &str) -> Vec<String> {
    let results = string_results(source);
    let variants = message_only_variants(source);
    let policy = "(docs/architecture.md, \"One error policy\")";
    let results = results.into_iter().map(|line| {
        format!(
            "{path}:{line}: `Result<_, String>` in a library crate: return a typed error {policy}"
        )
    });
    let variants = variants.into_iter().map(|(line, variant)| {
        format!(
            "{path}:{line}: the error variant {variant} carries only a message: give it the \
             structured facts {policy}"
        )
    });
    results.chain(variants).collect()
}

/// `source` without its unit tests: everything from a `#[cfg(test)]` line followed by a `mod`
/// line on (a file's test module comes last), and with line comments blanked, so that the
/// rules below read code only. Lines keep their numbers.
fn library_code(source: &str) -> Vec<&str> {
    let lines: Vec<&str> = source.lines().collect();
    let end = (0..lines.len())
        .find(|&i| {
            lines[i].trim() == "#[cfg(test)]"
                && lines
                    .get(i + 1)
                    .is_some_and(|next| next.trim_start().starts_with("mod "))
        })
        .unwrap_or(lines.len());
    lines[..end]
        .iter()
        .map(|line| match line.find("//") {
            Some(at) => &line[..at],
            None => line,
        })
        .collect()
}

/// The lines (1-based) of `source`'s library code that name a `Result` whose error type is
/// `String` (`Result<T, String>`, also spread over several lines); unit tests are exempt.
pub fn string_results(source: &str) -> Vec<usize> {
    let lines = library_code(source);
    let text = lines.join("\n");
    let mut found = Vec::new();
    for (start, _) in text.match_indices("Result<") {
        let preceded = text[..start]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_');
        if preceded {
            continue;
        }
        // The generic arguments, up to the matching `>`; the last one at depth 1 is the error.
        let (mut depth, mut last) = (0usize, start + "Result<".len());
        for (i, c) in text[start..].char_indices().map(|(i, c)| (start + i, c)) {
            match c {
                '<' | '(' | '[' => depth += 1,
                '>' | ')' | ']' => {
                    depth -= 1;
                    if depth == 0 {
                        let error = text[last..i].trim();
                        let two_arguments = last > start + "Result<".len();
                        if two_arguments && (error == "String" || error == "std::string::String") {
                            found.push(text[..start].matches('\n').count() + 1);
                        }
                        break;
                    }
                }
                ',' if depth == 1 => last = i + 1,
                _ => {}
            }
        }
    }
    found
}

/// The lines (1-based) of `source`'s code (tests aside) that use `print!`, `println!`,
/// `eprint!` or `eprintln!`.
pub fn print_macros(source: &str) -> Vec<usize> {
    let is_print = |line: &str| {
        line.match_indices("print").any(|(at, _)| {
            let before = line[..at].strip_suffix('e').unwrap_or(&line[..at]);
            let after = line[at + "print".len()..]
                .strip_prefix("ln")
                .unwrap_or(&line[at + 5..]);
            after.starts_with('!')
                && !before
                    .chars()
                    .next_back()
                    .is_some_and(|c| c.is_alphanumeric() || c == '_')
        })
    };
    library_code(source)
        .iter()
        .enumerate()
        .filter(|(_, line)| is_print(line))
        .map(|(i, _)| i + 1)
        .collect()
}

/// The variants of `source`'s error enums (public or not, named `...Error`) that carry only a
/// message: one field, a `String`, unnamed (`Xml(String)`) or named `message`, `reason` or
/// `error`; with their lines (1-based).
pub fn message_only_variants(source: &str) -> Vec<(usize, String)> {
    let lines = library_code(source);
    let mut found = Vec::new();
    let mut in_error_enum = false;
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim();
        if let Some(rest) = line
            .strip_prefix("pub enum ")
            .or_else(|| line.strip_prefix("pub(crate) enum "))
            .or_else(|| line.strip_prefix("enum "))
        {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            in_error_enum = name.ends_with("Error");
        } else if line == "}" {
            in_error_enum = false;
        } else if in_error_enum {
            let variant: String = line
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let starts_variant = variant.starts_with(|c: char| c.is_ascii_uppercase());
            if starts_variant && line[variant.len()..].trim_start().starts_with("(String)") {
                found.push((i + 1, variant));
            } else if starts_variant && line.contains('{') {
                // The fields up to the closing brace, doc comments and attributes aside.
                let mut fields = Vec::new();
                let mut j = i;
                let mut body = line.split_once('{').map_or("", |(_, body)| body);
                loop {
                    let (inside, closed) = match body.split_once('}') {
                        Some((inside, _)) => (inside, true),
                        None => (body, false),
                    };
                    fields.extend(
                        inside
                            .split(',')
                            .map(str::trim)
                            .filter(|f| !(f.is_empty() || f.starts_with('#'))),
                    );
                    if closed || j + 1 >= lines.len() {
                        break;
                    }
                    j += 1;
                    body = lines[j].trim();
                }
                let message_only = matches!(
                    fields.as_slice(),
                    [field] if ["message", "reason", "error"]
                        .iter()
                        .any(|name| field.replace(' ', "") == format!("{name}:String"))
                );
                if message_only {
                    found.push((i + 1, variant));
                }
                i = j;
            }
        }
        i += 1;
    }
    found
}

/// The lines (1-based) of `source` with `unsafe` code that break the rule: any, unless the
/// file is `allowed`; then each needs a `// SAFETY:` line in the comment right above it.
pub fn unsafe_problems(source: &str, allowed: bool) -> Vec<(usize, &'static str)> {
    let lines: Vec<&str> = source.lines().collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let code = line.split("//").next().unwrap_or_default();
        let is_unsafe = ["unsafe {", "unsafe fn", "unsafe impl", "unsafe extern"]
            .iter()
            .any(|pattern| code.contains(pattern));
        if !is_unsafe {
            continue;
        }
        if !allowed {
            found.push((
                i + 1,
                "unsafe code outside the files docs/architecture.md allows",
            ));
            continue;
        }
        let mut comment = lines[..i]
            .iter()
            .rev()
            .map(|l| l.trim())
            .take_while(|l| l.starts_with("//"));
        if !comment.any(|l| l.starts_with("// SAFETY:")) {
            found.push((
                i + 1,
                "an unsafe block without a `// SAFETY:` comment above it",
            ));
        }
    }
    found
}

/// What is wrong with the files a README cites: `readme` is its path from the root, `exists`
/// answers for paths from the root, and `is_crate` marks a crate's README (published alone).
pub fn citation_problems(
    readme: &Path,
    text: &str,
    is_crate: bool,
    exists: impl Fn(&Path) -> bool,
) -> Vec<String> {
    let dir = readme.parent().unwrap_or(Path::new(""));
    let text = &without_code_blocks(text);
    let mut problems = Vec::new();
    for target in link_targets(text) {
        let target = target.split('#').next().unwrap_or_default();
        if target.is_empty() || target.starts_with("mailto:") {
            continue;
        }
        if let Some(rest) = target.strip_prefix(REPOSITORY) {
            let path = ["/blob/main/", "/tree/main/"]
                .iter()
                .find_map(|prefix| rest.strip_prefix(prefix));
            match path {
                Some(path) if !exists(Path::new(path)) => problems.push(format!(
                    "the link {target} names {path}, which is not in the repository"
                )),
                None if !rest.is_empty() => problems.push(format!(
                    "the link {target} is not a file of the repository's main branch"
                )),
                _ => {}
            }
            continue;
        }
        if target.contains("://") {
            continue;
        }
        if target.starts_with('/') || target.starts_with('~') {
            problems.push(format!("the link {target} is an absolute path"));
            continue;
        }
        match normalise(&dir.join(target)) {
            None => problems.push(format!("the link {target} leaves the repository")),
            Some(path) if !exists(&path) => problems.push(format!(
                "the link {target} names {}, which does not exist",
                path.display()
            )),
            Some(path) if is_crate && !path.starts_with(dir) => problems.push(format!(
                "the link {target} leaves the crate, whose README is also its crates.io page: \
                 link {REPOSITORY}/blob/main/{} instead",
                path.display()
            )),
            Some(_) => {}
        }
    }
    for span in text.split('`').skip(1).step_by(2) {
        let looks_like_file = span.contains('/')
            && !span.contains(char::is_whitespace)
            && !span.contains("::")
            && [".md", ".rs", ".toml", ".fis", ".fcl", ".py", ".csv"]
                .iter()
                .any(|ext| span.ends_with(ext));
        if !looks_like_file {
            continue;
        }
        if span.starts_with('/') || span.starts_with('~') {
            problems.push(format!("`{span}` is an absolute path"));
            continue;
        }
        let found = [dir.join(span), PathBuf::from(span)]
            .iter()
            .any(|path| normalise(path).is_some_and(|path| exists(&path)));
        if !found {
            problems.push(format!("`{span}` is not a file of the repository"));
        }
    }
    problems
}

/// `text` without its fenced code blocks (whose backticks and brackets are code, not Markdown).
fn without_code_blocks(text: &str) -> String {
    let mut inside = false;
    let mut kept = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            inside = !inside;
        } else if !inside {
            kept.push_str(line);
            kept.push('\n');
        }
    }
    kept
}

/// The targets of the Markdown links `[text](target)` of `text`.
fn link_targets(text: &str) -> Vec<&str> {
    text.match_indices("](")
        .filter_map(|(at, _)| {
            let rest = &text[at + 2..];
            rest.find(')').map(|end| rest[..end].trim())
        })
        .collect()
}

/// `path` with `.` and `..` resolved, or `None` if it climbs above its start.
fn normalise(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::Normal(part) => out.push(part),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out)
}

/// The names of the folders in `dir`, sorted.
fn list_dir(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|entry| entry.path().is_dir())
        .map(|entry| entry.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let path = entry.path();
        if path.is_dir() {
            files.extend(rust_files(&path));
        } else if path.extension().is_some_and(|ext| ext == "rs") {
            files.push(path);
        }
    }
    files.sort();
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn test_references_are_parsed_in_every_form() {
        let doc = "| a | b | `manip-dyn/tests/bad_input.rs::non_finite_gravity` |\n\
                   | c | `fuzzy-sugeno/src/learn/genfis.rs::tests::bad_requests` |\n\
                   `hrm-cli/tests/eval_stream.rs::{one, two_three}` and \
                   `sim-core/src/a.rs::tests::{four, five}` and `<crate>/tests/<file>.rs::<test>` \
                   and `Scenario::build` and `docs/sweep.md`";
        assert_eq!(
            test_references(doc),
            [
                TestReference {
                    file: "manip-dyn/tests/bad_input.rs".into(),
                    names: vec!["non_finite_gravity".into()],
                },
                TestReference {
                    file: "fuzzy-sugeno/src/learn/genfis.rs".into(),
                    names: vec!["bad_requests".into()],
                },
                TestReference {
                    file: "hrm-cli/tests/eval_stream.rs".into(),
                    names: vec!["one".into(), "two_three".into()],
                },
                TestReference {
                    file: "sim-core/src/a.rs".into(),
                    names: vec!["four".into(), "five".into()],
                },
            ]
        );
    }

    #[test]
    fn a_missing_test_function_is_found() {
        let source = "#[test]\nfn present() {}\nfn generic<T>() {}\nfn present_too_long() {}";
        assert!(defines_fn(source, "present"));
        assert!(defines_fn(source, "generic"));
        assert!(!defines_fn(source, "absent"));
        assert!(!defines_fn(source, "present_too"));
        assert!(!defines_fn("fn unpresent() {}", "present"));
        assert!(defines_fn(source, "*"));
        assert!(!defines_fn("fn helper() {}", "*"));
        let table = "row(\n    \"zero_links\",\n    err,\n)";
        assert!(defines_fn(table, "zero_links"));
        assert!(!defines_fn(table, "zero"));
    }

    #[test]
    fn a_crate_root_without_its_readme_is_found() {
        assert!(includes_readme(
            "#![doc = include_str!(\"../README.md\")]\n\nmod a;"
        ));
        assert!(!includes_readme(
            "//! Docs.\n#[doc = include_str!(\"../README.md\")]\n#[cfg(doctest)]\npub struct R;"
        ));
    }

    #[test]
    fn a_manifest_without_workspace_lints_is_found() {
        assert!(uses_workspace_lints(
            "[package]\nname = \"a\"\n\n[lints]\nworkspace = true\n"
        ));
        assert!(uses_workspace_lints("[package]\nlints.workspace = true\n"));
        assert!(!uses_workspace_lints(
            "[package]\nname = \"a\"\n[lints.rust]\nmissing_docs = \"deny\"\n"
        ));
    }

    #[test]
    fn only_normal_dependencies_are_listed() {
        let manifest = "[package]\nname = \"x\"\n[dependencies]\nthiserror.workspace = true\n\
                        # a comment\nsim-core = { workspace = true }\n[dev-dependencies]\n\
                        manip-dyn.workspace = true\n";
        assert_eq!(dependencies(manifest), ["thiserror", "sim-core"]);
    }

    #[test]
    fn an_exhaustive_error_enum_is_found() {
        let source = "/// Doc.\n#[derive(Debug)]\n#[non_exhaustive]\npub enum GoodError {\n}\n\
                      /// Doc.\n#[derive(Debug)]\npub enum BadError {\n}\n\
                      pub enum Kind {}\npub(crate) enum PrivateError {}\n";
        assert_eq!(exhaustive_error_enums(source), ["BadError"]);
    }

    #[test]
    fn unsafe_code_is_found_outside_its_files_and_without_its_comment() {
        let source = "fn f(v: &[f64]) -> f64 {\n    // SAFETY: in bounds.\n    \
                      unsafe { *v.get_unchecked(0) }\n}\n// unsafe { in a comment }\n\
                      fn g(v: &[f64]) -> f64 {\n    unsafe { *v.get_unchecked(0) }\n}\n";
        assert_eq!(unsafe_problems(source, true).len(), 1);
        assert_eq!(unsafe_problems(source, true)[0].0, 7);
        assert_eq!(
            unsafe_problems(source, false)
                .iter()
                .map(|p| p.0)
                .collect::<Vec<_>>(),
            [3, 7]
        );
    }

    #[test]
    fn citations_outside_the_repository_are_found() {
        let files = [
            "docs/theory.md",
            "crates/a/README.md",
            "crates/a/src/lib.rs",
        ];
        let exists = |path: &Path| files.iter().any(|f| Path::new(f) == path);
        let readme = Path::new("crates/a/README.md");
        let good = "[theory](https://github.com/hrm-toolkit/hrm/blob/main/docs/theory.md), \
                    [home](https://github.com/hrm-toolkit/hrm), [lib](src/lib.rs#L3), \
                    [rust](https://www.rust-lang.org/x.md), `docs/theory.md`, `src/lib.rs`, \
                    `hrm::prelude`, `timeseries.csv`";
        assert_eq!(
            citation_problems(readme, good, true, exists),
            Vec::<String>::new()
        );
        let bad = "[a](../../docs/theory.md) [b](../../../outside.md) [c](/work/shared/notes.md) \
                   [d](https://github.com/hrm-toolkit/hrm/blob/main/docs/gone.md) [e](src/gone.rs) \
                   `/work/shared/seed/paper.md` `docs/gone.md`\n\
                   ```rust\nlet odd = '`'; let link = v[0](x);\n```\n";
        let problems = citation_problems(readme, bad, true, exists);
        assert_eq!(problems.len(), 7, "{problems:#?}");
        assert!(problems[0].contains("leaves the crate"), "{}", problems[0]);
        assert!(
            problems[1].contains("leaves the repository"),
            "{}",
            problems[1]
        );
        assert!(problems[2].contains("absolute"), "{}", problems[2]);
        // The root README may link into the crates.
        assert_eq!(
            citation_problems(Path::new("README.md"), "[t](docs/theory.md)", false, exists),
            Vec::<String>::new()
        );
    }

    #[test]
    fn string_errors_in_library_code_are_found() {
        let source = "/// Never `Result<(), String>` in a doc comment.\n\
                      pub fn a() -> Result<(), String> {}\n\
                      fn b(f: impl Fn() -> Result<Vec<(u8, u8)>,\n    String>) {}\n\
                      fn c() -> Result<String, Error> {}\n\
                      fn d() -> io::Result<String> {}\n\
                      fn e() -> MyResult<(), String> {}\n\
                      // fn f() -> Result<(), String>\n\
                      type G = std::result::Result<u8, std::string::String>;\n\
                      #[cfg(test)]\n\
                      mod tests {\n    fn h() -> Result<(), String> {}\n}\n";
        assert_eq!(string_results(source), [2, 3, 9]);
    }

    #[test]
    fn print_macros_are_found() {
        let source = "fn a() {\n    println!(\"x\");\n    eprint!(\"y\");\n\
                      console::print(\"z\");\n    writeln!(out, \"w\");\n\
                      // println!(\"comment\")\n    print!(\"v\");\n    eprintln!(\"u\");\n}\n\
                      #[cfg(test)]\nmod tests {\n    fn t() { println!(\"t\") }\n}\n";
        assert_eq!(print_macros(source), [2, 3, 7, 8]);
    }

    #[test]
    fn message_only_error_variants_are_found() {
        let source = "pub enum ParseError {\n\
                      \x20   /// Only a message.\n\
                      \x20   Fis {\n\
                      \x20       /// The text.\n\
                      \x20       message: String,\n\
                      \x20   },\n\
                      \x20   Line {\n        line: usize,\n        message: String,\n    },\n\
                      \x20   #[error(\"{0}\")]\n    Xml(String),\n\
                      \x20   Io(std::io::Error),\n\
                      \x20   Named { name: String },\n\
                      \x20   Short { error: String },\n\
                      \x20   Why {\n        reason: String,\n    },\n\
                      }\n\
                      pub enum Shape {\n    Text { message: String },\n}\n";
        assert_eq!(
            message_only_variants(source),
            [
                (3, "Fis".to_string()),
                (12, "Xml".into()),
                (15, "Short".into()),
                (16, "Why".into())
            ]
        );
    }

    #[test]
    fn string_errors_are_refused_by_line() {
        let stringly = "pub fn a() -> Result<(), String> {}\n";
        let typed = "pub fn a() -> Result<(), Error> {}\n";
        let problems = string_problems("a.rs", stringly);
        assert_eq!(problems.len(), 1);
        assert!(
            problems[0].starts_with("a.rs:1: `Result<_, String>`"),
            "{problems:?}"
        );
        assert!(string_problems("a.rs", typed).is_empty());
    }
}
