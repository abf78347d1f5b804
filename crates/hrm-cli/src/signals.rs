//! Cleanup on SIGINT and SIGTERM: a command interrupted mid-run removes the staging folders and
//! temporary files it was writing (the output it would have replaced stays as it was), then
//! exits with the signal's status (`128 + signal`).
//!
//! [`install`] blocks both signals in the main thread before any other thread exists, so every
//! thread (rayon's pool, the progress bar) inherits the mask, and one thread waits for them with
//! `sigwait`: the cleanup runs in an ordinary thread, not in a signal handler, so it may take
//! locks and allocate. The paths being written are [`register`]ed while they exist.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The staging folders and temporary files being written.
static STAGED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Blocks SIGINT and SIGTERM in this thread (and the threads it starts) and starts the thread
/// that cleans up and exits when one arrives. Call first in `main`.
pub fn install() {
    // SAFETY: `set` is a valid, initialised signal set; the calls only read and write it and
    // this thread's signal mask.
    let set = unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, libc::SIGINT);
        libc::sigaddset(&mut set, libc::SIGTERM);
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        set
    };
    let spawned = std::thread::Builder::new()
        .name("hrm-signals".into())
        .spawn(move || {
            let mut signal = 0;
            // SAFETY: `set` is the initialised set above and `signal` a valid out-pointer.
            if unsafe { libc::sigwait(&set, &mut signal) } == 0 {
                clean_up();
                std::process::exit(128 + signal);
            }
        });
    if spawned.is_err() {
        // Without the waiting thread, let the signals act as they would have.
        // SAFETY: as above.
        unsafe {
            libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut());
        }
    }
}

/// Folders created for an output, with the name of the marker file put in each: removed on a
/// signal (or by [`remove_bare_folder`]) while the marker is all they hold.
static CREATED: Mutex<Vec<(PathBuf, String)>> = Mutex::new(Vec::new());

/// Records `dir` as created by this command, holding only the file `marker` so far.
pub fn register_folder(dir: &Path, marker: &str) {
    if let Ok(mut created) = CREATED.lock() {
        created.push((dir.to_path_buf(), marker.to_string()));
    }
}

/// Removes `dir` if this command created it ([`register_folder`]) and it still holds nothing
/// but its marker: a failed command leaves no empty output folder behind. A folder another
/// process has written into meanwhile (shards sharing a folder) stays.
pub fn remove_bare_folder(dir: &Path) {
    let marker = match CREATED.lock() {
        Ok(created) => created
            .iter()
            .find(|(created, _)| created == dir)
            .map(|(_, marker)| marker.clone()),
        Err(_) => None,
    };
    if let Some(marker) = marker {
        remove_if_only(dir, &marker);
    }
}

/// Removes `dir` and its file `marker` when that file is all it holds.
fn remove_if_only(dir: &Path, marker: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let names: Vec<_> = entries.flatten().take(2).map(|e| e.file_name()).collect();
    if names.len() == 1 && names[0] == marker {
        let _ = std::fs::remove_file(dir.join(marker));
        // Fails, and keeps the folder, if a file arrived since.
        let _ = std::fs::remove_dir(dir);
    }
}

/// Records `path` (a staging folder or temporary file) as being written.
pub fn register(path: &Path) {
    if let Ok(mut staged) = STAGED.lock() {
        staged.push(path.to_path_buf());
    }
}

/// Forgets `path`: it was put in place or removed.
pub fn unregister(path: &Path) {
    if let Ok(mut staged) = STAGED.lock() {
        staged.retain(|p| p != path);
    }
}

/// Removes every registered path.
fn clean_up() {
    let staged = match STAGED.lock() {
        Ok(staged) => staged.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    for path in staged {
        let _ = if path.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
    }
    let created = match CREATED.lock() {
        Ok(created) => created.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    for (dir, marker) in created {
        remove_if_only(&dir, &marker);
    }
}
