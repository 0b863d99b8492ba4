//! Outputs appear atomically (temporary file, fsync, rename) and are never half-written: readers see
//! the old file or the complete new one. Temporary files are short-named, registered while in
//! flight (so a process that must exit at once can remove them), locked by their writer, and those
//! that no writer holds any more are cleaned up by the next run.

use crate::error::shown_path;
use std::fs::{self, File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Temporary files are named `.lumiere-<pid>-<n>.tmp`: short whatever the output's name (a
/// 250-byte file name must still get a temporary), and telling which process made them.
const TEMP_PREFIX: &str = ".lumiere-";
const TEMP_SUFFIX: &str = ".tmp";

/// Temporary files being written now, by any thread of this process.
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Names tried for a temporary file before giving up: a name is taken only by a temporary that a
/// killed process left behind under a pid this process now has (containers reuse theirs).
const TEMP_ATTEMPTS: usize = 10_000;

/// How long a temporary file must have gone unwritten before a run that finds it unlocked removes
/// it: longer than the moments its writer holds it unlocked (between creating and locking it,
/// between closing and renaming it), with room for the clocks of a network file system.
const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(10);

/// Writes `bytes` to `path` atomically. Refuses a `path` that exists and is not a regular file (a
/// device, a FIFO): renaming over it would replace the node itself, `/dev/null` included.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let resolved = resolve_link(path)?;
    let path = resolved.as_deref().unwrap_or(path);
    check_target(path)?;
    // Created separately so that a failure here (missing directory, no permission) leaves nothing to
    // clean up, and so we never remove a file we did not create.
    let (file, temp) = create_temp(path)?;
    register(&temp);
    let result = fill_and_rename(file, &temp, path, bytes).map_err(|e| {
        // Best effort: the error worth reporting is the one that made us give up.
        let _ = fs::remove_file(&temp);
        Error::io(path, e)
    });
    unregister(&temp);
    result
}

/// Checks that a file can be created at `path` (any extension) without touching `path` itself.
pub fn check_writable(path: &Path) -> Result<()> {
    let resolved = resolve_link(path)?;
    let path = resolved.as_deref().unwrap_or(path);
    check_target(path)?;
    let (_, probe) = create_temp(path)?;
    fs::remove_file(&probe).map_err(|e| Error::io(&probe, e))
}

/// A new temporary file next to `path`, locked (see [`lock`]), and its name: the first name of
/// [`temp_path`]'s that no file has.
fn create_temp(path: &Path) -> Result<(File, PathBuf)> {
    for _ in 0..TEMP_ATTEMPTS {
        let temp = temp_path(path)?;
        match create_new(&temp) {
            Ok(file) => {
                lock(&file);
                return Ok((file, temp));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            // Only for NotFound: a folder that cannot be searched also fails `exists`.
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(missing_folder(path).unwrap_or_else(|| Error::io(path, e)));
            }
            Err(e) => return Err(Error::io(path, e)),
        }
    }
    Err(Error::invalid(format!(
        "{}: {TEMP_ATTEMPTS} names for a temporary file beside it are all taken; remove the .lumiere-*.tmp files there",
        shown_path(path)
    )))
}

/// The error for an output whose folder does not exist, if that is why a file cannot be created
/// beside it: still an I/O error of kind `NotFound`, but where the OS said "x.png: No such file or
/// directory" of the file the user meant to create, it names the folder that is missing.
fn missing_folder(path: &Path) -> Option<Error> {
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty())?;
    (!folder.exists()).then(|| {
        let reason = format!("cannot be created: the folder {} does not exist", shown_path(folder));
        Error::io(path, std::io::Error::new(std::io::ErrorKind::NotFound, reason))
    })
}

/// Removes every temporary file this process is writing now. For a process about to exit at once
/// (a second Ctrl-C): it leaves no half-written file behind.
pub fn remove_in_flight() {
    let in_flight = IN_FLIGHT.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    for temp in in_flight.iter() {
        let _ = fs::remove_file(temp);
    }
}

/// Removes the temporary files that writers left in `dir` (killed with SIGKILL in the middle of a
/// write); returns how many. A writer holds a lock on its temporary file until it is renamed, so a
/// file no process holds, unwritten for [`STALE_AFTER`], is abandoned, whatever its name's pid:
/// pids say nothing across containers that share a folder, and a process may have the pid of the
/// one that left the file. Where files cannot be locked (not Unix), nothing is removed.
pub fn remove_stale_temporaries(dir: &Path) -> usize {
    let Ok(entries) = fs::read_dir(if dir.as_os_str().is_empty() { Path::new(".") } else { dir }) else { return 0 };
    let mut removed = 0;
    for entry in entries.flatten() {
        let is_temp = entry.file_name().to_str().is_some_and(is_temp_name);
        if is_temp && entry.file_type().is_ok_and(|t| t.is_file()) && remove_if_abandoned(&entry.path()) {
            removed += 1;
        }
    }
    removed
}

/// Whether `name` is a temporary file's, `.lumiere-<pid>-<n>.tmp`.
fn is_temp_name(name: &str) -> bool {
    let Some(middle) = name.strip_prefix(TEMP_PREFIX).and_then(|m| m.strip_suffix(TEMP_SUFFIX)) else { return false };
    middle.split_once('-').is_some_and(|(pid, n)| pid.parse::<u32>().is_ok() && n.parse::<u64>().is_ok())
}

/// Removes the temporary file `path` if no process holds its lock and it has gone unwritten for
/// [`STALE_AFTER`]. A live writer holds the lock from the file's creation to its rename, so
/// taking it means the writer is gone.
#[cfg(unix)]
fn remove_if_abandoned(path: &Path) -> bool {
    use std::os::unix::fs::OpenOptionsExt;
    use std::os::unix::io::AsRawFd;
    let Ok(file) = OpenOptions::new().read(true).custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK).open(path) else {
        return false;
    };
    // SAFETY: flock on a descriptor this function owns; the lock goes with the descriptor.
    if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
        return false;
    }
    let Ok(metadata) = file.metadata() else { return false };
    let idle = metadata.modified().ok().and_then(|t| t.elapsed().ok());
    // The name must still be the file locked: removed and made again meanwhile (names repeat
    // across containers), it would be another writer's live file.
    use std::os::unix::fs::MetadataExt;
    let same_file =
        fs::symlink_metadata(path).is_ok_and(|now| (now.dev(), now.ino()) == (metadata.dev(), metadata.ino()));
    idle.is_some_and(|idle| idle >= STALE_AFTER) && same_file && fs::remove_file(path).is_ok()
}

#[cfg(not(unix))]
fn remove_if_abandoned(_: &Path) -> bool {
    false
}

/// Takes the lock that tells [`remove_stale_temporaries`] a temporary file is being written; it
/// lasts as long as `file` is open. Best effort: on a file system without locks the cleaner cannot
/// take one either, and removes nothing there.
#[cfg(unix)]
fn lock(file: &File) {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock on a descriptor `file` owns for as long as the call.
    unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
}

#[cfg(not(unix))]
fn lock(_: &File) {}

/// Where a symbolic link points: the file to replace is its target, never the link itself (a
/// rename over `/dev/stdout` would replace the link). `None` when `path` is not a link; an error
/// when it leads nowhere that can be named (a dangling link, or a pipe behind `/dev/stdout`).
fn resolve_link(path: &Path) -> Result<Option<PathBuf>> {
    let is_link = fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return Ok(None);
    }
    match fs::canonicalize(path) {
        Ok(target) => Ok(Some(target)),
        Err(_) => Err(Error::invalid(format!(
            "{}: is a link to nothing lumiere can replace (dangling, or a pipe or device); give a file name",
            shown_path(path)
        ))),
    }
}

/// Refuses a target that exists and is not a regular file (or a link to one), and a directory.
fn check_target(path: &Path) -> Result<()> {
    let Ok(metadata) = fs::metadata(path) else { return Ok(()) };
    if metadata.is_dir() {
        return Err(Error::invalid(format!("{}: is a directory, expected a file name", shown_path(path))));
    }
    if let Err(kind) = crate::util::read::refuse_special(&metadata) {
        return Err(Error::invalid(format!(
            "{}: exists and {kind}; lumiere writes only regular files",
            shown_path(path)
        )));
    }
    // The rename would replace a file its owner made read-only, where writing into it would fail
    // (as `cp` fails): refuse, as any other writer would.
    if !may_write(path) {
        return Err(Error::invalid(format!(
            "{}: exists and is read-only (no write permission); lumiere does not replace it",
            shown_path(path)
        )));
    }
    Ok(())
}

/// Whether this process may write into the existing file `path`, as `access(2)` says (root may
/// write into any regular file on a writable file system).
#[cfg(unix)]
fn may_write(path: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(name) = std::ffi::CString::new(path.as_os_str().as_bytes()) else { return true };
    // SAFETY: `name` is a NUL-terminated string that outlives the call.
    unsafe { libc::access(name.as_ptr(), libc::W_OK) == 0 }
}

#[cfg(not(unix))]
fn may_write(path: &Path) -> bool {
    fs::metadata(path).is_ok_and(|metadata| !metadata.permissions().readonly())
}

/// `.lumiere-<pid>-<n>.tmp` next to `path`: the same directory keeps the final rename atomic (no
/// cross-device copy), the pid separates processes and the counter separates threads of this one.
fn temp_path(path: &Path) -> Result<PathBuf> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    if path.file_name().is_none() {
        return Err(Error::invalid(format!("{}: output path has no file name", shown_path(path))));
    }
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    Ok(path.with_file_name(format!("{TEMP_PREFIX}{}-{n}{TEMP_SUFFIX}", std::process::id())))
}

fn register(temp: &Path) {
    IN_FLIGHT.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).push(temp.to_path_buf());
}

fn unregister(temp: &Path) {
    IN_FLIGHT.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).retain(|t| t != temp);
}

/// `create_new` so that a stale file with the same name (a pid reused after a crash) is never
/// clobbered: [`create_temp`] tries the next name instead.
fn create_new(path: &Path) -> std::io::Result<File> {
    OpenOptions::new().write(true).create_new(true).open(path)
}

/// Gives the temporary `file` the permissions of the file `target` it will replace, if there is
/// one, and its owner where this process may (root): the rename publishes a new file, which would
/// otherwise take the umask's permissions and this process's owner, where writing into the old
/// file, as `cp` does, keeps both. A read-only image re-rendered by root stays read-only, and one
/// re-rendered for another user stays theirs.
fn take_identity_of(file: &File, target: &Path) -> std::io::Result<()> {
    let Ok(metadata) = fs::metadata(target) else { return Ok(()) };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        // Before the permissions: a change of owner clears set-id bits. Only root may give a file
        // away; anyone else's replacement is theirs, as a new file of theirs would be.
        let _ = std::os::unix::fs::fchown(file, Some(metadata.uid()), Some(metadata.gid()));
    }
    // Only where they differ: a file system that refuses `fchmod` (some network and FUSE mounts)
    // then still takes a replacement whose permissions are already right.
    if file.metadata()?.permissions() == metadata.permissions() {
        return Ok(());
    }
    file.set_permissions(metadata.permissions())
}

/// Writes and fsyncs before renaming, so that the rename cannot publish a file whose data is still only
/// in the page cache. On Unix the file stays open, its lock held, until it is renamed: a cleaner
/// that found it unlocked after a slow fsync would take it for abandoned. Windows requires the
/// handle closed before the rename (and has no cleaner).
fn fill_and_rename(mut file: File, temp: &Path, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    file.write_all(bytes)?;
    take_identity_of(&file, path)?;
    file.sync_all()?;
    #[cfg(not(unix))]
    drop(file);
    fs::rename(temp, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A temporary file left registered after its rename would be removed by a later
    /// [`remove_in_flight`], by then perhaps another process's file of the same name (a pid reused
    /// in a container sharing the folder).
    #[test]
    fn a_finished_write_leaves_no_temporary_registered() {
        let dir = std::env::temp_dir().join(format!("lumiere-write-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("image.png");
        write_atomically(&path, b"bytes").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"bytes");
        // Other tests of this process may be writing elsewhere: only this folder's entries count.
        let in_flight = IN_FLIGHT.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let ours: Vec<_> = in_flight.iter().filter(|temp| temp.starts_with(&dir)).collect();
        assert!(ours.is_empty(), "still registered after the write: {ours:?}");
        drop(in_flight);
        fs::remove_dir_all(&dir).unwrap();
    }
}
