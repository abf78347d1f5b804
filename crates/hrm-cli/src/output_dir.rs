//! Output folders written whole: a command writes into a fresh staging folder beside its
//! output folder and renames it into place only when everything is written. A command that
//! fails leaves an existing output folder exactly as it was; one that succeeds replaces it
//! whole, so no file of an earlier run is left beside the new ones.
//!
//! Every output folder holds a marker file, [`MARKER`], naming the command that wrote it and
//! listing every entry it wrote. An existing folder is replaced only if it is empty, carries the
//! marker and holds nothing the marker does not list (besides pages and GIFs of `hrm view`), or
//! holds nothing but marked folders (the parent of nested outputs, such as `hrm-output` after
//! `hrm simulate`), so `--out .`, a typo or a note the user saved into an output never deletes
//! a user's files. Marked folders nested in a replaced folder (`hrm-output/simulate` inside the
//! main job's `hrm-output`) are the outputs of other commands: they are carried into the new
//! folder unless it has an entry of the same name.

use std::ffi::OsString;
use std::io::Write;
use std::path::{Component, Path, PathBuf};

/// The marker file of an output folder; it names the command that wrote the folder.
pub const MARKER: &str = ".hrm-output";

/// An output folder being written: write into [`OutputDir::path`], then [`OutputDir::commit`].
/// Dropped without a commit, the staging folder is removed and the output left as it was.
#[derive(Debug)]
pub struct OutputDir {
    /// The folder as the user named it (for messages).
    shown: PathBuf,
    /// The folder's absolute path.
    target: PathBuf,
    /// The staging folder, a sibling of `target`.
    staging: PathBuf,
    /// The command writing the folder, as its [`MARKER`] names it.
    command: String,
    /// Whether the staging folder became the output.
    committed: bool,
    /// The parent folders `create` made, removed after the staging folder when the output is
    /// not committed (declared last: dropped after [`OutputDir`]'s own drop).
    new_parents: NewParents,
}

/// The missing ancestors of a folder about to be created, deepest first (each named without a
/// trailing `..` or `.`, so that none names a folder that existed): unless kept, removed again
/// when dropped, each only while empty, so that a failing command leaves no folders behind.
#[derive(Debug, Default)]
struct NewParents(Vec<PathBuf>);

impl NewParents {
    /// The ancestors of `dir` (itself included) that do not exist yet.
    fn of(dir: &Path) -> Self {
        Self(
            dir.ancestors()
                .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
                .filter(|a| matches!(a.components().next_back(), Some(Component::Normal(_))))
                .map(Path::to_path_buf)
                .collect(),
        )
    }

    /// Removes at once (while empty) the folders made only to pass through, which `parent`
    /// (canonical) does not lie in: `a/x` of `--out a/x/../q`.
    fn remove_detours(&mut self, parent: &Path) {
        self.0.retain(|dir| match std::fs::canonicalize(dir) {
            Ok(resolved) if !parent.starts_with(&resolved) => std::fs::remove_dir(dir).is_err(),
            _ => true,
        });
    }

    /// Keeps the folders: the output they hold is in place.
    fn keep(&mut self) {
        self.0.clear();
    }
}

impl Drop for NewParents {
    fn drop(&mut self) {
        for dir in &self.0 {
            if std::fs::remove_dir(dir).is_err() {
                break;
            }
        }
    }
}

impl OutputDir {
    /// Checks that `target` may be replaced, creates its parent folders and an empty staging
    /// folder beside it (holding the [`MARKER`] that names `command`).
    pub fn create(target: &Path, command: &str) -> Result<Self, String> {
        let shown = target.to_path_buf();
        let fail = |what: &str, e: std::io::Error| format!("{what} {}: {e}", shown.display());
        let absolute = std::path::absolute(target).map_err(|e| fail("output folder", e))?;
        let (Some(parent), Some(name)) = (absolute.parent(), absolute.file_name()) else {
            return Err(format!(
                "output folder {}: name it by a path that ends in its own name (not `/` or `..`)",
                shown.display()
            ));
        };
        if let Some(file) = parent
            .ancestors()
            .find(|a| a.exists())
            .filter(|a| !a.is_dir())
        {
            return Err(format!(
                "output folder {}: {} is a file, not a folder",
                shown.display(),
                file.display()
            ));
        }
        check_name_length(&shown, name.len(), "staging")?;
        // From here a failure removes the parent folders made for the output.
        let mut new_parents = NewParents::of(parent);
        std::fs::create_dir_all(parent).map_err(|e| fail("cannot create the parent of", e))?;
        // `..` and symbolic links are resolved, so that the staging folder is a true sibling.
        let parent = std::fs::canonicalize(parent).map_err(|e| fail("output folder", e))?;
        new_parents.remove_detours(&parent);
        let target = parent.join(name);
        match std::fs::symlink_metadata(&target) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(fail("output folder", e)),
            // The link would be replaced by a folder, not the folder it points to written.
            Ok(meta) if meta.file_type().is_symlink() => {
                return Err(format!(
                    "output folder {}: is a symbolic link; give the folder it points to",
                    shown.display()
                ));
            }
            Ok(meta) if !meta.is_dir() => {
                return Err(format!(
                    "output folder {}: exists and is not a folder",
                    shown.display()
                ));
            }
            Ok(_) if !replaceable(&target) => {
                return Err(format!(
                    "output folder {}: exists and holds files that hrm did not write (no {MARKER} \
                     marker of hrm's); choose a new folder or empty this one",
                    shown.display()
                ));
            }
            Ok(_) => {
                if let Some(other) = marker_command(&target)
                    && kind(&other) != kind(command)
                {
                    return Err(format!(
                        "output folder {}: holds the output of `hrm {other}`, which `hrm \
                         {command}` would replace; choose another folder (or remove this one)",
                        shown.display()
                    ));
                }
                if let Some(entry) = unlisted_entry(&target)? {
                    return Err(format!(
                        "output folder {}: holds {entry}, which hrm did not write; move it out \
                         of the folder or choose another --out",
                        shown.display()
                    ));
                }
            }
        }
        remove_abandoned(&target, "staging");
        if target.is_dir() {
            // With the output in place, the old copies of killed commands are not its only copy.
            remove_abandoned(&target, "old");
        }
        let staging = sibling(&target, "staging");
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(|e| fail("cannot clear staging for", e))?;
        }
        // Registered first: an interruption between the two would leave the folder behind.
        crate::signals::register(&staging);
        if let Err(e) = std::fs::create_dir(&staging) {
            crate::signals::unregister(&staging);
            return Err(fail("cannot create staging for", e));
        }
        let dir = OutputDir {
            shown: shown.clone(),
            target,
            staging,
            command: command.to_string(),
            committed: false,
            new_parents,
        };
        std::fs::write(
            dir.staging.join(MARKER),
            format!("written by `hrm {command}`\n"),
        )
        .map_err(|e| fail("cannot write the marker of", e))?;
        Ok(dir)
    }

    /// Checks that the entry `name` of the new output will not replace the output of another
    /// command nested in the old one (`hrm simulate --out hrm-output/paper-tracking` before the
    /// main job writes `hrm-output/paper-tracking`): call it for the entries a command is about
    /// to write, before the work, so that the refusal comes first.
    pub fn claim(&self, name: &str) -> Result<(), String> {
        let nested = self.target.join(name);
        match marker_command(&nested) {
            Some(other) if self.target.is_dir() && !is_output_of_parent(&nested) => Err(format!(
                "output folder {}: holds the output of `hrm {other}`, which this command \
                     would replace; move it or choose another --out",
                self.shown.join(name).display()
            )),
            _ => Ok(()),
        }
    }

    /// The folder to write into (the staging folder until [`OutputDir::commit`]).
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// `message` (a failure to write into [`path`](Self::path)) with the staging folder, which
    /// the failure removes, named as the output folder the user gave.
    pub fn named(&self, message: String) -> String {
        message.replace(
            &self.staging.display().to_string(),
            &self.shown.display().to_string(),
        )
    }

    /// Puts the staging folder in place of the output folder: the old folder is moved aside,
    /// the nested outputs of other commands are carried over, the new one takes its name and
    /// the old one is deleted. On failure the old folder is put back.
    pub fn commit(mut self) -> Result<(), String> {
        let fail = |what: &str, e: std::io::Error| format!("{what} {}: {e}", self.shown.display());
        // The list of what the command wrote, while an interruption still removes the staging
        // folder.
        write_manifest(&self.staging, &self.command)
            .map_err(|e| fail("cannot write the marker of", e))?;
        // From here an interruption leaves the staging folder to the next command's cleanup
        // rather than removing it between the two renames.
        crate::signals::unregister(&self.staging);
        let old = sibling(&self.target, "old");
        let had_old = self.target.exists();
        if had_old {
            if old.exists() {
                std::fs::remove_dir_all(&old)
                    .map_err(|e| fail("cannot clear the previous copy of", e))?;
            }
            std::fs::rename(&self.target, &old)
                .map_err(|e| fail("cannot move aside the previous", e))?;
        }
        let carried = if had_old {
            carry_nested(&old, &self.staging, &self.shown)
        } else {
            Ok(Vec::new())
        };
        let result = carried.and_then(|moved| {
            std::fs::rename(&self.staging, &self.target).inspect_err(|_| {
                for name in &moved {
                    let _ = std::fs::rename(self.staging.join(name), old.join(name));
                }
            })
        });
        if let Err(e) = result {
            if had_old {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(fail("cannot put in place the output folder", e));
        }
        self.committed = true;
        self.new_parents.keep();
        if had_old && let Err(e) = remove_tree(&old) {
            // The new output is in place; the old copy (read-only, say) is only in the way: say
            // where it is rather than leave it unnoticed.
            crate::console::to_stderr(&crate::console::error_line(&format!(
                "warning: wrote {}, but its previous copy, moved to {}, cannot be removed \
                     ({e}); remove it by hand",
                self.shown.display(),
                old.display()
            )));
        }
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
            crate::signals::unregister(&self.staging);
        }
    }
}

/// Refuses, before any work, an output file that is one of the command's inputs (`fis train
/// --out data.csv --data data.csv` would overwrite the training data): `out` names the same
/// file as an input (the same device and inode, whatever the path).
pub fn refuse_input_as_output(out: &Path, inputs: &[(&str, &Path)]) -> Result<(), String> {
    if std::fs::metadata(out).is_err() {
        return Ok(());
    }
    for (option, input) in inputs {
        if same_file(out, input) {
            return Err(format!(
                "--out {} is the {option} file {}: writing it would overwrite an input; choose \
                 another --out",
                out.display(),
                input.display()
            ));
        }
    }
    Ok(())
}

/// Refuses, before any work, an output folder that holds one of the command's input files
/// (`hrm simulate --scenario S/my.toml --out S`): replacing the folder would delete it.
/// `inputs` are `(what, path)`; paths that do not exist are not inputs yet.
pub fn refuse_inputs_inside(out: &Path, inputs: &[(&str, &Path)]) -> Result<(), String> {
    let Ok(folder) = std::fs::canonicalize(out) else {
        return Ok(());
    };
    for (what, input) in inputs {
        if std::fs::canonicalize(input).is_ok_and(|file| file.starts_with(&folder)) {
            return Err(format!(
                "--out {}: holds the {what} {}, which replacing the folder would delete; choose \
                 another --out or move the file out of it",
                out.display(),
                input.display()
            ));
        }
    }
    Ok(())
}

/// Refuses, before any work, two outputs of one command that name the same file (`hrm view
/// DIR --gif DIR/view.html`): each would replace the other. `outputs` are `(option, path)`.
pub fn refuse_shared_outputs(outputs: &[(&str, &Path)]) -> Result<(), String> {
    for (k, (option, path)) in outputs.iter().enumerate() {
        if let Some((other, _)) = outputs[..k].iter().find(|(_, p)| same_file(p, path)) {
            return Err(format!(
                "{option} {} is the {other} file: the one would replace the other; choose another \
                 {option}",
                path.display()
            ));
        }
    }
    Ok(())
}

/// Whether `a` and `b` name one file: the same device and inode where both exist, otherwise the
/// same name in the same resolved folder.
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        return (x.dev(), x.ino()) == (y.dev(), y.ino());
    }
    let resolved = |path: &Path| {
        let dir = path
            .parent()
            .filter(|dir| !dir.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        match (std::fs::canonicalize(dir), path.file_name()) {
            (Ok(dir), Some(name)) => dir.join(name),
            _ => path.to_path_buf(),
        }
    };
    resolved(a) == resolved(b)
}

/// Refuses, before any work, to replace existing files in a folder `hrm {command}` did not
/// create (one without its [`MARKER`]) unless `written_by_hrm` recognises the file's first
/// `within` bytes as hrm's: `fis export --out DIR` into a folder of the user's never overwrites
/// the user's own `hrm_fis.c`, and replaces its own export.
pub fn refuse_foreign_files(
    paths: &[PathBuf],
    command: &str,
    (within, written_by_hrm): (usize, impl Fn(&[u8]) -> bool),
) -> Result<(), String> {
    for path in paths {
        let dir = path.parent().unwrap_or(Path::new("."));
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if std::fs::symlink_metadata(path).is_ok()
            && marker_command(dir).is_none_or(|other| other != command)
            && !file_written_by_hrm(path, within, &written_by_hrm)
        {
            return Err(format!(
                "{} exists in a folder that `hrm {command}` did not create (no {MARKER} marker \
                 naming it): remove the file or choose another --out",
                path.display()
            ));
        }
    }
    Ok(())
}

/// Refuses, before any work, to write a file of `hrm {command}` into `dir` when it is the output
/// folder of another command ([`MARKER`]): that command replaces its folder whole, so the file
/// would be lost (`hrm sweep --shard 1/2 --out S` after `hrm simulate --out S`). `what` names
/// the file.
pub fn refuse_marked_folder(dir: &Path, command: &str, what: &str) -> Result<(), String> {
    match marker_command(dir) {
        Some(other) if other != command => Err(format!(
            "--out {}: holds the output of `hrm {other}`, which replaces its folder whole; \
             write {what} into a folder of its own",
            dir.display()
        )),
        _ => Ok(()),
    }
}

/// Whether the regular file `path` holds a text `written_by_hrm` recognises, from its first
/// `within` bytes (a folder, a FIFO, which opening would wait on, or an unreadable file is not
/// hrm's).
fn file_written_by_hrm(path: &Path, within: usize, written_by_hrm: impl Fn(&[u8]) -> bool) -> bool {
    regular_file_start(path, within).is_some_and(|start| written_by_hrm(&start))
}

/// The first `within` bytes of `path` if it is a readable regular file (a folder, a FIFO, which
/// opening would wait on, or a device such as `/dev/zero` is not read).
fn regular_file_start(path: &Path, within: usize) -> Option<Vec<u8>> {
    use std::io::Read;
    if !std::fs::metadata(path).is_ok_and(|meta| meta.is_file()) {
        return None;
    }
    let mut start = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(within as u64)
        .read_to_end(&mut start)
        .ok()?;
    Some(start)
}

/// Refuses, before any work, to replace an existing `path` that hrm did not write: a folder, or
/// a file whose first `within` bytes `written_by_hrm` does not recognise (`hrm view`'s pages by
/// their signature, `hrm fis train`'s systems by their whole text).
pub fn refuse_foreign_file(
    path: &Path,
    within: usize,
    written_by_hrm: impl Fn(&[u8]) -> bool,
) -> Result<(), String> {
    // Nothing there (or a dangling link, which the new file replaces): nothing to keep.
    if std::fs::metadata(path).is_err() {
        return Ok(());
    }
    if path.is_dir() {
        return Err(format!("{}: is a folder", path.display()));
    }
    if file_written_by_hrm(path, within, written_by_hrm) {
        Ok(())
    } else {
        Err(format!(
            "{}: exists and hrm did not write it; choose another file or remove this one",
            path.display()
        ))
    }
}

/// Writes the file `path` whole with the contents `text`, as [`write_file_with`] does.
pub fn write_file(path: &Path, text: &str, command: &str) -> Result<(), String> {
    write_file_with(path, command, |out| {
        out.write_all(text.as_bytes()).map_err(|e| e.to_string())
    })
}

/// Writes the file `path` whole with `write`, which may write it piece by piece: into a
/// temporary sibling (buffered), renamed over `path` only when `write` succeeded. A folder
/// created for it gets the [`MARKER`] naming `command`.
pub fn write_file_with(
    path: &Path,
    command: &str,
    write: impl FnOnce(&mut dyn Write) -> Result<(), String>,
) -> Result<(), String> {
    let temporary = stage_file(path, command, write)?;
    put_in_place(&temporary, path)
}

/// Writes several files whole, all or none: each `(path, text)` goes to a temporary sibling
/// first, and only when every one is written are they renamed over their paths. A failure
/// before the renames leaves every existing file as it was, and so do two paths that name one
/// file ([`refuse_shared_outputs`]). Folders are created as by [`write_file_with`].
pub fn write_files(files: &[(PathBuf, impl AsRef<[u8]>)], command: &str) -> Result<(), String> {
    let outputs: Vec<(&str, &Path)> = files.iter().map(|(path, _)| ("output", &**path)).collect();
    refuse_shared_outputs(&outputs)?;
    let mut staged = Vec::with_capacity(files.len());
    for (path, contents) in files {
        match stage_file(path, command, |out| {
            out.write_all(contents.as_ref()).map_err(|e| e.to_string())
        }) {
            Ok(temporary) => staged.push(temporary),
            Err(e) => {
                for temporary in &staged {
                    let _ = std::fs::remove_file(temporary);
                    crate::signals::unregister(temporary);
                }
                for (path, _) in files {
                    crate::signals::remove_bare_folder(path.parent().unwrap_or(Path::new("")));
                }
                return Err(e);
            }
        }
    }
    let mut result = Ok(());
    for ((path, _), temporary) in files.iter().zip(&staged) {
        if result.is_ok() {
            result = put_in_place(temporary, path);
        } else {
            let _ = std::fs::remove_file(temporary);
            crate::signals::unregister(temporary);
        }
    }
    result
}

/// Writes `path`'s contents with `write` into its temporary sibling (after removing the
/// temporaries of killed commands) and returns the sibling's path; on failure nothing is left,
/// not even the folder it created for `path`.
fn stage_file(
    path: &Path,
    command: &str,
    write: impl FnOnce(&mut dyn Write) -> Result<(), String>,
) -> Result<PathBuf, String> {
    stage_file_in_folder(path, command, write).inspect_err(|_| {
        crate::signals::remove_bare_folder(path.parent().unwrap_or(Path::new("")));
    })
}

/// [`stage_file`], creating `path`'s folder (with its [`MARKER`]) when it does not exist.
fn stage_file_in_folder(
    path: &Path,
    command: &str,
    write: impl FnOnce(&mut dyn Write) -> Result<(), String>,
) -> Result<PathBuf, String> {
    let fail = |what: &str, e: &dyn std::fmt::Display| format!("{what} {}: {e}", path.display());
    let Some(name) = path.file_name() else {
        return Err(format!("{}: not a file name", path.display()));
    };
    let dir = path.parent().unwrap_or(Path::new(""));
    if !dir.as_os_str().is_empty() && !dir.exists() {
        std::fs::create_dir_all(dir).map_err(|e| fail("cannot create the folder of", &e))?;
        std::fs::write(dir.join(MARKER), format!("written by `hrm {command}`\n"))
            .map_err(|e| fail("cannot create the folder of", &e))?;
        crate::signals::register_folder(dir, MARKER);
    }
    if !dir.as_os_str().is_empty() && !dir.is_dir() {
        return Err(format!(
            "output folder {}: exists and is not a folder",
            dir.display()
        ));
    }
    check_name_length(path, name.len(), "partial")?;
    let path = dir.join(name);
    if path.is_dir() {
        return Err(format!("cannot write {}: it is a folder", path.display()));
    }
    remove_abandoned(&path, "partial");
    let temporary = sibling(&path, "partial");
    crate::signals::register(&temporary);
    let written = std::fs::File::create(&temporary)
        .map_err(|e| fail("cannot write", &e))
        .and_then(|file| {
            let mut out = std::io::BufWriter::new(file);
            write(&mut out)?;
            out.flush().map_err(|e| fail("cannot write", &e))
        });
    match written {
        Ok(()) => Ok(temporary),
        Err(e) => {
            let _ = std::fs::remove_file(&temporary);
            crate::signals::unregister(&temporary);
            Err(e)
        }
    }
}

/// Renames the staged `temporary` over `path`; on failure the temporary is removed.
fn put_in_place(temporary: &Path, path: &Path) -> Result<(), String> {
    let renamed = std::fs::rename(temporary, path).map_err(|e| {
        let _ = std::fs::remove_file(temporary);
        crate::signals::remove_bare_folder(path.parent().unwrap_or(Path::new("")));
        format!("cannot write {}: {e}", path.display())
    });
    crate::signals::unregister(temporary);
    renamed
}

/// The longest file name most file systems take (`NAME_MAX`, bytes).
const NAME_MAX: usize = 255;

/// Checks, before any work, that the sibling `.<name>.hrm-<what>-<pid>` of an output of
/// `name_bytes` bytes fits in [`NAME_MAX`] (the moved-aside `old` copy is shorter).
fn check_name_length(shown: &Path, name_bytes: usize, what: &str) -> Result<(), String> {
    let suffix = format!(".hrm-{what}-{}", u32::MAX).len() + 1;
    if name_bytes + suffix > NAME_MAX {
        return Err(format!(
            "output {}: its name is {name_bytes} bytes long, at most {} are allowed (the \
             temporary sibling it is written through adds {suffix} to the {NAME_MAX} a name may \
             have)",
            shown.display(),
            NAME_MAX - suffix
        ));
    }
    Ok(())
}

/// The command named by the [`MARKER`] of `dir` (`simulate`, `sweep --shard`), if it has one.
/// Only a regular file's first [`MARKER_BYTES`] are read (a FIFO, `/dev/zero` linked in, or a
/// gigabyte of zeros is no marker).
fn marker_command(dir: &Path) -> Option<String> {
    let start = regular_file_start(&dir.join(MARKER), MARKER_BYTES)?;
    let text = std::str::from_utf8(&start).ok()?;
    let command = text.lines().next()?.strip_prefix("written by `hrm ")?;
    Some(command.strip_suffix('`')?.to_string())
}

/// The most bytes of a [`MARKER`] read: its line names one command.
const MARKER_BYTES: usize = 256;

/// The kind of output a command writes: `sweep` and `sweep merge` write the same.
fn kind(command: &str) -> &str {
    match command {
        "sweep merge" => "sweep",
        other => other,
    }
}

/// Whether the marked folder `nested` belongs to its parent's output (the parent is an
/// output of the same command), rather than being another command's output nested in it.
fn is_output_of_parent(nested: &Path) -> bool {
    let parent = nested.parent().and_then(marker_command);
    parent.is_some() && parent == marker_command(nested)
}

/// `.<name>.hrm-<what>-<pid>` beside `path`.
fn sibling(path: &Path, what: &str) -> PathBuf {
    let mut name = OsString::from(".");
    name.push(path.file_name().unwrap_or_default());
    name.push(format!(".hrm-{what}-{}", std::process::id()));
    path.with_file_name(name)
}

/// Removes the siblings `.<name>.hrm-<what>-<pid>` of `target` (staging folders, partial
/// files) left by commands that were killed (their process is gone), where the system lists its
/// processes in `/proc`. Moved-aside old copies (`what = "old"`) are removed only while the
/// output itself is in place: after a crash between the two renames of a commit, one may be the
/// only copy of an output.
fn remove_abandoned(target: &Path, what: &str) {
    let (Some(dir), Some(name)) = (target.parent(), target.file_name()) else {
        return;
    };
    let prefix = format!(".{}.hrm-{what}-", name.to_string_lossy());
    if !Path::new("/proc/self").is_dir() {
        return;
    }
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(pid) = file_name
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let path = entry.path();
            // A staging folder carries the marker from its first moment on (or is empty, killed
            // before it), an old copy was a replaceable output: a folder of the user's that
            // merely has such a name is left alone.
            let _ = if !path.is_dir() {
                std::fs::remove_file(&path)
            } else if replaceable(&path) {
                remove_tree(&path)
            } else {
                Ok(())
            };
        }
    }
}

/// Removes the folder `path` and its contents, making its read-only folders writable first if
/// a plain removal fails (an output the user made read-only, moved aside by a commit).
fn remove_tree(path: &Path) -> std::io::Result<()> {
    if std::fs::remove_dir_all(path).is_ok() {
        return Ok(());
    }
    make_writable(path);
    std::fs::remove_dir_all(path)
}

/// Gives the owner write permission on the folder `dir` and the folders under it (symbolic
/// links are not followed).
fn make_writable(dir: &Path) {
    use std::os::unix::fs::PermissionsExt;
    let Ok(meta) = std::fs::symlink_metadata(dir) else {
        return;
    };
    if !meta.is_dir() {
        return;
    }
    let mut permissions = meta.permissions();
    permissions.set_mode(permissions.mode() | 0o700);
    let _ = std::fs::set_permissions(dir, permissions);
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            make_writable(&entry.path());
        }
    }
}

/// The line of a [`MARKER`] after which the entries of the output are listed, one a line, as
/// paths relative to the folder with `/` between names and after a folder's name.
const MANIFEST_HEADER: &str = "# every entry of this folder that hrm wrote, one a line:";

/// The most entries an output folder's check walks (and a manifest lists): far beyond the main
/// job's few hundred files, and a bound on the work of the check.
const MAX_MANIFEST_ENTRIES: usize = 1 << 20;

/// The most bytes of a [`MARKER`] read with its manifest (`MAX_MANIFEST_ENTRIES` paths of 64
/// bytes).
const MAX_MANIFEST_BYTES: usize = 64 << 20;

/// Rewrites the [`MARKER`] of the staging folder `dir` with the list of every entry in it
/// ([`MANIFEST_HEADER`]), so that a later command can tell them from files the user adds.
fn write_manifest(dir: &Path, command: &str) -> std::io::Result<()> {
    let mut entries = Vec::new();
    walk(dir, &mut |_, relative, is_dir| {
        if relative != MARKER {
            entries.push(relative.to_string());
        }
        Ok(is_dir)
    })?;
    entries.sort_unstable();
    let mut text = format!("written by `hrm {command}`\n{MANIFEST_HEADER}\n");
    for entry in entries {
        text.push_str(&entry);
        text.push('\n');
    }
    std::fs::write(dir.join(MARKER), text)
}

/// The first entry (in [`walk`]'s order) of the marked output folder `dir` that its [`MARKER`]
/// does not list, as a path relative to `dir`: a file or folder the user put there; `None` when
/// there is none. A marker without the list ([`MANIFEST_HEADER`]) lists nothing. The outputs of
/// other commands directly inside `dir`, which a commit carries over, and the pages and GIFs of
/// `hrm view` ([`run_view::written_by_hrm`]) are hrm's.
///
/// # Errors
/// A folder holding more than [`MAX_MANIFEST_ENTRIES`] entries, or one that cannot be read.
fn unlisted_entry(dir: &Path) -> Result<Option<String>, String> {
    let marker = regular_file_start(&dir.join(MARKER), MAX_MANIFEST_BYTES).unwrap_or_default();
    let marker = String::from_utf8_lossy(&marker);
    let mut lines = marker.lines().skip(1);
    let listed: std::collections::HashSet<&str> = if lines.next() == Some(MANIFEST_HEADER) {
        lines.collect()
    } else {
        std::collections::HashSet::new()
    };
    let mut unlisted = None;
    let walked = walk(dir, &mut |path, relative, is_dir| {
        if relative == MARKER || listed.contains(relative) {
            return Ok(is_dir);
        }
        let carried = is_dir && !relative.trim_end_matches('/').contains('/') && is_output(path);
        let page = !is_dir
            && regular_file_start(path, run_view::SIGNATURE_WITHIN)
                .is_some_and(|start| run_view::written_by_hrm(&start));
        if carried || page {
            return Ok(false);
        }
        unlisted = Some(relative.trim_end_matches('/').to_string());
        Err(std::io::Error::other("stopped at an unlisted entry"))
    });
    match (unlisted, walked) {
        (Some(entry), _) => Ok(Some(entry)),
        (None, Ok(())) => Ok(None),
        (None, Err(e)) => Err(format!("output folder {}: {e}", dir.display())),
    }
}

/// Visits every entry under `root` (symbolic links not followed), each folder's in sorted order,
/// with its path, its path relative to `root` (`/` between names, and after a folder's name) and
/// whether it is a folder; `visit` says whether to go into a folder, and may stop the walk by
/// returning an error. At most [`MAX_MANIFEST_ENTRIES`] entries are visited; names that are not
/// UTF-8 are read lossily (so no manifest lists them).
fn walk(
    root: &Path,
    visit: &mut dyn FnMut(&Path, &str, bool) -> std::io::Result<bool>,
) -> std::io::Result<()> {
    let mut count = 0;
    let mut pending = vec![(root.to_path_buf(), String::new())];
    while let Some((dir, prefix)) = pending.pop() {
        let mut entries: Vec<_> = std::fs::read_dir(&dir)?.collect::<Result<_, _>>()?;
        entries.sort_by_key(|entry| entry.file_name());
        for entry in entries {
            count += 1;
            if count > MAX_MANIFEST_ENTRIES {
                return Err(std::io::Error::other(format!(
                    "holds more than {MAX_MANIFEST_ENTRIES} entries"
                )));
            }
            let is_dir = entry.file_type()?.is_dir();
            let name = entry.file_name().to_string_lossy().into_owned();
            let relative = if is_dir {
                format!("{prefix}{name}/")
            } else {
                format!("{prefix}{name}")
            };
            if visit(&entry.path(), &relative, is_dir)? && is_dir {
                pending.push((entry.path(), relative));
            }
        }
    }
    Ok(())
}

/// Whether `dir` holds a [`MARKER`] naming a command.
fn is_output(dir: &Path) -> bool {
    marker_command(dir).is_some()
}

/// Whether the folder `dir` may be replaced: it is an output folder, or holds only output
/// folders (or nothing).
fn replaceable(dir: &Path) -> bool {
    if is_output(dir) {
        return true;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    entries
        .into_iter()
        .all(|entry| entry.is_ok_and(|e| e.path().is_dir() && is_output(&e.path())))
}

/// Moves the output folders nested in `old` into `new`; returns the names moved. Where `new`
/// has an entry of the same name, the nested output is refused (it would be lost), as
/// [`OutputDir::claim`] refuses it before the work. On failure, what was moved goes back.
fn carry_nested(old: &Path, new: &Path, shown: &Path) -> std::io::Result<Vec<OsString>> {
    let mut moved = Vec::new();
    for entry in std::fs::read_dir(old)? {
        let entry = entry?;
        let (path, name) = (entry.path(), entry.file_name());
        if !path.is_dir() || !is_output(&path) {
            continue;
        }
        if new.join(&name).exists() {
            if is_output_of_parent(&path) {
                continue;
            }
            for name in &moved {
                let _ = std::fs::rename(new.join(name), old.join(name));
            }
            return Err(std::io::Error::other(format!(
                "{} holds the output of another command, which this one would replace",
                shown.join(&name).display()
            )));
        }
        if let Err(e) = std::fs::rename(&path, new.join(&name)) {
            for name in &moved {
                let _ = std::fs::rename(new.join(name), old.join(name));
            }
            return Err(e);
        }
        moved.push(name);
    }
    Ok(moved)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("hrm-output-dir-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn the_parent_folders_made_for_an_output_go_with_a_failure() {
        let root = scratch("new-parents");
        // Dropped without a commit (the command failed): the folders it made are gone.
        let failed = OutputDir::create(&root.join("a/b/out"), "run").unwrap();
        assert!(root.join("a/b").is_dir());
        drop(failed);
        assert!(names(&root).is_empty(), "{:?}", names(&root));
        // A parent that holds something else by then stays.
        let failed = OutputDir::create(&root.join("a/b/out"), "run").unwrap();
        std::fs::write(root.join("a/note.txt"), "mine").unwrap();
        drop(failed);
        assert_eq!(names(&root.join("a")), ["note.txt"]);
        std::fs::remove_dir_all(root.join("a")).unwrap();
        // Committed, they stay; a folder made only to pass through (`x` of `x/../q`) does not.
        let done = OutputDir::create(&root.join("x/../q/out"), "run").unwrap();
        done.commit().unwrap();
        assert_eq!(names(&root), ["q"]);
        assert_eq!(names(&root.join("q/out")), [MARKER]);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn only_a_small_regular_marker_naming_a_command_marks_a_folder() {
        // A FIFO (reading it waited for ever), `/dev/zero` linked in (read without end) and a
        // marker of zeros are no markers: the folder is the user's, and is not replaced.
        let root = scratch("marker-kinds");
        let fifo = root.join("fifo");
        std::fs::create_dir_all(&fifo).unwrap();
        let made = std::process::Command::new("mkfifo")
            .arg(fifo.join(MARKER))
            .status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo");
        let zero = root.join("zero");
        std::fs::create_dir_all(&zero).unwrap();
        std::os::unix::fs::symlink("/dev/zero", zero.join(MARKER)).unwrap();
        let zeros = root.join("zeros");
        std::fs::create_dir_all(&zeros).unwrap();
        std::fs::write(zeros.join(MARKER), vec![0u8; 1 << 20]).unwrap();
        for dir in [&fifo, &zero, &zeros] {
            assert_eq!(marker_command(dir), None, "{}", dir.display());
            assert!(!replaceable(dir), "{}", dir.display());
            assert!(refuse_marked_folder(dir, "sweep --shard", "a file").is_ok());
        }
        let marked = root.join("marked");
        std::fs::create_dir_all(&marked).unwrap();
        std::fs::write(marked.join(MARKER), "written by `hrm sweep --shard`\n").unwrap();
        assert_eq!(marker_command(&marked).as_deref(), Some("sweep --shard"));
        assert!(refuse_marked_folder(&marked, "simulate", "a file").is_err());
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_commit_replaces_the_folder_whole_and_a_drop_leaves_it_alone() {
        let root = scratch("replace");
        let out = root.join("a/out");
        let dir = OutputDir::create(&out, "test").unwrap();
        std::fs::write(dir.path().join("one.txt"), "1").unwrap();
        assert!(!out.exists(), "nothing appears before the commit");
        dir.commit().unwrap();
        assert_eq!(names(&out), [MARKER, "one.txt"]);
        // A second run that fails: the first run's output stays exactly as it was.
        let dir = OutputDir::create(&out, "test").unwrap();
        std::fs::write(dir.path().join("two.txt"), "2").unwrap();
        drop(dir);
        assert_eq!(names(&out), [MARKER, "one.txt"]);
        // A second run that succeeds: no stale file; no staging or old copy is left behind.
        let dir = OutputDir::create(&out, "test").unwrap();
        std::fs::write(dir.path().join("two.txt"), "2").unwrap();
        dir.commit().unwrap();
        assert_eq!(names(&out), [MARKER, "two.txt"]);
        assert_eq!(names(&root.join("a")), ["out"]);
        // The staging folder of a killed command (no such process) is cleared by the next one.
        if Path::new("/proc/self").is_dir() {
            let abandoned = root.join("a/.out.hrm-staging-4294967295");
            std::fs::create_dir_all(&abandoned).unwrap();
            OutputDir::create(&out, "test").unwrap().commit().unwrap();
            assert_eq!(names(&root.join("a")), ["out"]);
        }
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn files_the_user_adds_to_an_output_are_never_replaced() {
        let root = scratch("added");
        let out = root.join("out");
        let write = |command: &str| {
            let dir = OutputDir::create(&out, command)?;
            std::fs::create_dir_all(dir.path().join("figures/svg")).unwrap();
            std::fs::write(dir.path().join("summary.json"), "{}").unwrap();
            std::fs::write(dir.path().join("figures/svg/a.svg"), "<svg/>").unwrap();
            dir.commit()
        };
        write("run").unwrap();
        let marker = std::fs::read_to_string(out.join(MARKER)).unwrap();
        assert_eq!(
            marker,
            format!(
                "written by `hrm run`\n{MANIFEST_HEADER}\nfigures/\nfigures/svg/\n\
                 figures/svg/a.svg\nsummary.json\n"
            )
        );
        // hrm's own files, edited, and a page of `hrm view` beside them: replaced.
        std::fs::write(out.join("summary.json"), "edited").unwrap();
        let page = format!("<!DOCTYPE html><html>{}</html>", run_view::head());
        std::fs::write(out.join("view.html"), page).unwrap();
        write("run").unwrap();
        assert_eq!(names(&out), [MARKER, "figures", "summary.json"]);
        // Anything else the user put there, at any depth, is named and kept, the output as it was.
        for added in ["notes.txt", "figures/svg/mine.svg", "figures/mine/"] {
            let path = out.join(added);
            if added.ends_with('/') {
                std::fs::create_dir_all(&path).unwrap();
            } else {
                std::fs::write(&path, "mine").unwrap();
            }
            let before = std::fs::read_to_string(out.join(MARKER)).unwrap();
            let err = write("run").unwrap_err();
            let shown = added.trim_end_matches('/');
            assert_eq!(
                err,
                format!(
                    "output folder {}: holds {shown}, which hrm did not write; move it out of \
                     the folder or choose another --out",
                    out.display()
                )
            );
            assert!(path.exists());
            assert_eq!(std::fs::read_to_string(out.join(MARKER)).unwrap(), before);
            if added.ends_with('/') {
                std::fs::remove_dir(&path).unwrap();
            } else {
                std::fs::remove_file(&path).unwrap();
            }
        }
        write("run").unwrap();
        // A marker naming its command alone, or whose list lost its header, lists nothing: the
        // first entry in the order of names is named.
        std::fs::write(out.join("notes.txt"), "x").unwrap();
        for marker in [
            "written by `hrm run`\n".to_string(),
            format!("written by `hrm run`\n{MANIFEST_HEADER} \nnotes.txt\n"),
        ] {
            std::fs::write(out.join(MARKER), marker).unwrap();
            let err = write("run").unwrap_err();
            assert!(
                err.contains(": holds figures, which hrm did not write"),
                "{err}"
            );
        }
        // A note that mentions hrm is no page of `hrm view`; a folder of the user's named as a
        // killed command's staging folder is no staging folder.
        std::fs::remove_dir_all(&out).unwrap();
        write("run").unwrap();
        std::fs::write(out.join("a.txt"), "these files were written by hrm").unwrap();
        let err = write("run").unwrap_err();
        assert!(err.contains(": holds a.txt, which hrm"), "{err}");
        std::fs::remove_file(out.join("a.txt")).unwrap();
        let lookalike = root.join(".out.hrm-staging-4294967295");
        std::fs::create_dir_all(&lookalike).unwrap();
        std::fs::write(lookalike.join("thesis.tex"), "x").unwrap();
        write("run").unwrap();
        assert!(lookalike.join("thesis.tex").is_file());
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn nested_outputs_are_carried_over_and_foreign_folders_are_refused() {
        let root = scratch("nested");
        let (outer, inner) = (root.join("out"), root.join("out/simulate"));
        // `hrm simulate` first: `out` holds only an output folder, so it may be replaced.
        let dir = OutputDir::create(&inner, "simulate").unwrap();
        std::fs::write(dir.path().join("timeseries.csv"), "t").unwrap();
        dir.commit().unwrap();
        let dir = OutputDir::create(&outer, "run").unwrap();
        std::fs::write(dir.path().join("report.html"), "r").unwrap();
        dir.commit().unwrap();
        assert_eq!(names(&outer), [MARKER, "report.html", "simulate"]);
        assert_eq!(names(&inner), [MARKER, "timeseries.csv"]);
        // A folder of the user's is never replaced.
        let foreign = root.join("mine");
        std::fs::create_dir_all(&foreign).unwrap();
        std::fs::write(foreign.join("thesis.tex"), "x").unwrap();
        let err = OutputDir::create(&foreign, "run").unwrap_err();
        assert!(err.contains("hrm did not write"), "{err}");
        let file = root.join("file");
        std::fs::write(&file, "x").unwrap();
        let err = OutputDir::create(&file, "run").unwrap_err();
        assert!(err.contains("not a folder"), "{err}");
        let err = OutputDir::create(Path::new("/"), "run").unwrap_err();
        assert!(err.contains("ends in its own name"), "{err}");
        assert_eq!(names(&root), ["file", "mine", "out"]);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn only_an_output_of_the_same_kind_is_replaced() {
        let root = scratch("kinds");
        let shards = root.join("shards");
        write_file(&shards.join("shard-1-of-3.json"), "{}", "sweep --shard").unwrap();
        for command in ["sweep", "simulate", "run", "sweep merge"] {
            let err = OutputDir::create(&shards, command).unwrap_err();
            assert!(
                err.contains("holds the output of `hrm sweep --shard`"),
                "{err}"
            );
        }
        assert_eq!(names(&shards), [MARKER, "shard-1-of-3.json"]);
        // `sweep` and `sweep merge` write the same kind of folder.
        let merged = root.join("merged");
        OutputDir::create(&merged, "sweep merge")
            .unwrap()
            .commit()
            .unwrap();
        OutputDir::create(&merged, "sweep")
            .unwrap()
            .commit()
            .unwrap();
        // The main job refuses, before its work, to write over `hrm simulate`'s output nested
        // under one of its own entries; the commit refuses it too.
        let (outer, inner) = (root.join("out"), root.join("out/paper-tracking"));
        OutputDir::create(&inner, "simulate")
            .unwrap()
            .commit()
            .unwrap();
        OutputDir::create(&outer, "run").unwrap().commit().unwrap();
        let dir = OutputDir::create(&outer, "run").unwrap();
        let err = dir.claim("paper-tracking").unwrap_err();
        assert!(err.contains("holds the output of `hrm simulate`"), "{err}");
        dir.claim("paper-responses-step").unwrap();
        std::fs::create_dir(dir.path().join("paper-tracking")).unwrap();
        let err = dir.commit().unwrap_err();
        assert!(err.contains("holds the output of another command"), "{err}");
        assert_eq!(names(&outer), [MARKER, "paper-tracking"]);
        assert_eq!(names(&inner), [MARKER]);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn an_output_name_too_long_is_refused_before_anything_is_written() {
        let root = scratch("long");
        let out = root.join("x".repeat(250));
        let err = OutputDir::create(&out, "simulate").unwrap_err();
        assert!(
            err.contains("its name is 250 bytes long, at most 231"),
            "{err}"
        );
        let err = write_file(&out, "x", "fis train").unwrap_err();
        assert!(
            err.contains("its name is 250 bytes long, at most 231"),
            "{err}"
        );
        assert!(names(&root).is_empty());
        // The longest name allowed goes through.
        OutputDir::create(&root.join("x".repeat(231)), "simulate")
            .unwrap()
            .commit()
            .unwrap();
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_read_only_old_output_is_removed_all_the_same() {
        use std::os::unix::fs::PermissionsExt;
        let root = scratch("read-only");
        let out = root.join("out");
        let dir = OutputDir::create(&out, "simulate").unwrap();
        std::fs::create_dir(dir.path().join("data")).unwrap();
        std::fs::write(dir.path().join("data/big.csv"), "t").unwrap();
        dir.commit().unwrap();
        for folder in [out.join("data"), out.clone()] {
            std::fs::set_permissions(&folder, std::fs::Permissions::from_mode(0o555)).unwrap();
        }
        OutputDir::create(&out, "simulate")
            .unwrap()
            .commit()
            .unwrap();
        assert_eq!(names(&root), ["out"], "no old copy left behind");
        assert_eq!(names(&out), [MARKER]);
        // An old copy a killed command left is removed by the next command.
        let dead = root.join(format!(".out.hrm-old-{}", u32::MAX));
        std::fs::create_dir_all(dead.join("sub")).unwrap();
        std::fs::write(dead.join(MARKER), "written by `hrm simulate`\n").unwrap();
        std::fs::set_permissions(dead.join("sub"), std::fs::Permissions::from_mode(0o555)).unwrap();
        OutputDir::create(&out, "simulate")
            .unwrap()
            .commit()
            .unwrap();
        assert_eq!(names(&root), ["out"]);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn user_files_and_inputs_are_not_overwritten() {
        let root = scratch("user-files");
        let mine = root.join("mine/hrm_fis.c");
        std::fs::create_dir_all(root.join("mine")).unwrap();
        std::fs::write(&mine, "my code").unwrap();
        let err = refuse_foreign_files(
            std::slice::from_ref(&mine),
            "fis export",
            (0, |_: &[u8]| false),
        )
        .unwrap_err();
        assert!(err.contains("did not create"), "{err}");
        // A folder `fis export` created may be written again.
        let ours = root.join("ours/hrm_fis.c");
        write_files(&[(ours.clone(), String::from("v1"))], "fis export").unwrap();
        refuse_foreign_files(
            std::slice::from_ref(&ours),
            "fis export",
            (0, |_: &[u8]| false),
        )
        .unwrap();
        refuse_foreign_files(
            &[root.join("mine/new.c")],
            "fis export",
            (0, |_: &[u8]| false),
        )
        .unwrap();
        // The same file by another path is an input.
        let data = root.join("mine/data.csv");
        std::fs::write(&data, "1,2\n").unwrap();
        let other_path = root.join("mine/../mine/data.csv");
        let err = refuse_input_as_output(&other_path, &[("--data", &data)]).unwrap_err();
        assert!(err.contains("is the --data file"), "{err}");
        refuse_input_as_output(&root.join("mine/out.fis"), &[("--data", &data)]).unwrap();
        assert_eq!(std::fs::read_to_string(&mine).unwrap(), "my code");
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn a_symbolic_link_for_the_folder_is_named_as_such() {
        let root = scratch("link");
        std::fs::create_dir(root.join("real")).unwrap();
        std::os::unix::fs::symlink(root.join("real"), root.join("link")).unwrap();
        let err = OutputDir::create(&root.join("link"), "run").err().unwrap();
        assert!(
            err.ends_with("link: is a symbolic link; give the folder it points to"),
            "{err}"
        );
        assert!(root.join("link").is_symlink() && names(&root.join("real")).is_empty());
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn files_are_written_whole() {
        let root = scratch("file");
        let path = root.join("shards/shard-1-of-2.json");
        write_file(&path, "{}", "sweep").unwrap();
        write_file(&path, "{\"a\":1}", "sweep").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{\"a\":1}");
        assert_eq!(names(&root.join("shards")), [MARKER, "shard-1-of-2.json"]);
        let err = write_file(&root.join("shards"), "x", "sweep").unwrap_err();
        assert!(err.contains("cannot write"), "{err}");
        // A writer that fails half-way leaves the earlier file as it was, and no partial file.
        let err = write_file_with(&path, "sweep", |out| {
            out.write_all(b"{\"b\"").map_err(|e| e.to_string())?;
            Err("the runs stopped".into())
        })
        .unwrap_err();
        assert_eq!(err, "the runs stopped");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{\"a\":1}");
        assert_eq!(names(&root.join("shards")), [MARKER, "shard-1-of-2.json"]);
        // A writer that fails into a folder it created leaves no folder; into a folder holding
        // another file (a shard another task wrote meanwhile), the folder stays.
        let fresh = root.join("fresh/shard-1-of-2.json");
        let fail = |out: &mut dyn Write| {
            out.write_all(b"{").map_err(|e| e.to_string())?;
            Err("the runs stopped".to_string())
        };
        assert!(write_file_with(&fresh, "sweep --shard", fail).is_err());
        assert!(!root.join("fresh").exists());
        let shared = root.join("shared/shard-1-of-2.json");
        assert!(
            write_file_with(&shared, "sweep --shard", |out| {
                std::fs::write(root.join("shared/shard-2-of-2.json"), "{}").unwrap();
                fail(out)
            })
            .is_err()
        );
        assert_eq!(names(&root.join("shared")), [MARKER, "shard-2-of-2.json"]);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn several_files_are_written_all_or_none() {
        let root = scratch("files");
        let (header, source) = (root.join("out/a.h"), root.join("out/a.c"));
        let files = |h: &str, c: &str| {
            vec![
                (header.clone(), h.to_string()),
                (source.clone(), c.to_string()),
            ]
        };
        write_files(&files("h1", "c1"), "fis export").unwrap();
        assert_eq!(names(&root.join("out")), [MARKER, "a.c", "a.h"]);
        // The second file cannot be written (its path is a folder): neither file changes.
        std::fs::remove_file(&source).unwrap();
        std::fs::create_dir(&source).unwrap();
        let err = write_files(&files("h2", "c2"), "fis export").unwrap_err();
        assert!(err.contains("it is a folder"), "{err}");
        assert_eq!(std::fs::read_to_string(&header).unwrap(), "h1");
        assert_eq!(names(&root.join("out")), [MARKER, "a.c", "a.h"]);
        std::fs::remove_dir(&source).unwrap();
        write_files(&files("h3", "c3"), "fis export").unwrap();
        assert_eq!(std::fs::read_to_string(&header).unwrap(), "h3");
        assert_eq!(std::fs::read_to_string(&source).unwrap(), "c3");
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn partial_files_of_killed_commands_are_removed() {
        let root = scratch("abandoned");
        std::fs::create_dir_all(&root).unwrap();
        let path = root.join("shard-1-of-2.json");
        // No process has the largest pid; this command's own partial file is left alone.
        let dead = root.join(format!(".shard-1-of-2.json.hrm-partial-{}", u32::MAX));
        std::fs::write(&dead, "half a shard").unwrap();
        write_file(&path, "{}", "sweep").unwrap();
        assert_eq!(names(&root), ["shard-1-of-2.json"]);
        std::fs::remove_dir_all(&root).unwrap();
    }
}
