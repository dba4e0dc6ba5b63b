//! Report files, written as a set: every file of a run to a temporary file beside its target,
//! then all renamed, so a reader never sees half a report nor a mix of two runs. A symlink is
//! followed (its target is replaced, not the link); a device or FIFO (`/dev/stdout`) is
//! written in place, never replaced by a file.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Why a report file cannot be written, with the file.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {why}", .path.display())]
pub struct WriteError {
    /// The report file as given.
    pub path: PathBuf,
    /// What the system said.
    pub why: std::io::Error,
}

/// Where one report goes.
enum Target {
    /// A regular file (or a new one): written beside it, then renamed over it.
    Replace(PathBuf),
    /// A device or FIFO: written in place.
    InPlace(PathBuf),
}

fn fail(path: &Path) -> impl Fn(std::io::Error) -> WriteError + '_ {
    move |why| WriteError {
        path: path.to_path_buf(),
        why,
    }
}

/// Where `path` leads: through symlinks to a regular file, a special file, or a new file.
fn target(path: &Path) -> Result<Target, WriteError> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(WriteError {
            path: path.to_path_buf(),
            why: std::io::Error::other("is a directory"),
        }),
        Ok(m) if m.is_file() => Ok(Target::Replace(
            std::fs::canonicalize(path).map_err(fail(path))?,
        )),
        Ok(_) => Ok(Target::InPlace(path.to_path_buf())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            // A dangling symlink names the file to create.
            match std::fs::read_link(path) {
                Ok(to) => Ok(Target::Replace(match path.parent() {
                    Some(dir) => dir.join(to),
                    None => to,
                })),
                Err(_) => Ok(Target::Replace(path.to_path_buf())),
            }
        }
        Err(e) => Err(fail(path)(e)),
    }
}

fn folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn temp_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "report".to_owned());
    folder(path).join(format!(".{name}.{}.tmp", std::process::id()))
}

/// Checks before a run that each of `paths` can be written: not a folder, its folder exists or
/// can be made, and a file can be created there.
pub fn check_writable(paths: &[PathBuf]) -> Result<(), WriteError> {
    for path in paths {
        if let Target::Replace(to) = target(path)? {
            let dir = folder(&to);
            std::fs::create_dir_all(&dir).map_err(fail(path))?;
            let probe = temp_beside(&to);
            std::fs::File::create(&probe).map_err(fail(path))?;
            let _ = std::fs::remove_file(&probe);
        }
    }
    Ok(())
}

/// Writes every `(path, text)` of a run as one set: all to temporary files first, then all
/// renamed; on any error no temporary file is left and no target has changed yet (special
/// files are written last, in place). Creates the folders.
pub fn write_set(files: &[(PathBuf, String)]) -> Result<(), WriteError> {
    let mut staged: Vec<(PathBuf, PathBuf, &Path)> = Vec::new();
    let mut in_place: Vec<(PathBuf, &str)> = Vec::new();
    let clean = |staged: &[(PathBuf, PathBuf, &Path)]| {
        for (tmp, _, _) in staged {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for (path, text) in files {
        let to = match target(path) {
            Ok(Target::Replace(to)) => to,
            Ok(Target::InPlace(p)) => {
                in_place.push((p, text));
                continue;
            }
            Err(e) => {
                clean(&staged);
                return Err(e);
            }
        };
        let tmp = temp_beside(&to);
        let written = (|| {
            std::fs::create_dir_all(folder(&to))?;
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(text.as_bytes())?;
            f.sync_all()
        })();
        staged.push((tmp, to, path));
        if let Err(e) = written {
            clean(&staged);
            return Err(fail(path)(e));
        }
    }
    for (i, (tmp, to, path)) in staged.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, to) {
            clean(staged.get(i..).unwrap_or(&[]));
            return Err(fail(path)(e));
        }
    }
    for (path, text) in in_place {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(fail(&path))?;
        f.write_all(text.as_bytes()).map_err(fail(&path))?;
    }
    Ok(())
}

/// Writes one file as a set of one ([`write_set`]).
pub fn write_atomic(path: &Path, text: &str) -> Result<(), WriteError> {
    write_set(&[(path.to_path_buf(), text.to_owned())])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("drivespec-report-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(dir)
            .map(|r| {
                r.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        n.sort();
        n
    }

    #[test]
    fn a_set_replaces_every_file_and_leaves_no_temp() {
        let d = dir("set");
        let (a, b) = (d.join("r.json"), d.join("r.xml"));
        write_set(&[(a.clone(), "one".into()), (b.clone(), "one".into())]).unwrap_or(());
        write_set(&[(a.clone(), "two".into()), (b.clone(), "two".into())]).unwrap_or(());
        assert_eq!(std::fs::read_to_string(&a).ok().as_deref(), Some("two"));
        assert_eq!(std::fs::read_to_string(&b).ok().as_deref(), Some("two"));
        assert_eq!(names(&d), ["r.json", "r.xml"]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_failing_member_changes_nothing() {
        let d = dir("fail");
        let a = d.join("r.json");
        write_atomic(&a, "old").unwrap_or(());
        let sub = d.join("sub");
        std::fs::create_dir_all(&sub).unwrap_or(());
        let err = write_set(&[(a.clone(), "new".into()), (sub.clone(), "x".into())]);
        assert!(err.is_err());
        assert_eq!(std::fs::read_to_string(&a).ok().as_deref(), Some("old"));
        assert_eq!(names(&d), ["r.json", "sub"]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_followed_and_a_device_written_in_place() {
        let d = dir("link");
        std::fs::create_dir_all(&d).unwrap_or(());
        let real = d.join("real.json");
        let link = d.join("link.json");
        std::fs::write(&real, "old").unwrap_or(());
        std::os::unix::fs::symlink(&real, &link).unwrap_or(());
        write_atomic(&link, "new").unwrap_or(());
        assert!(std::fs::symlink_metadata(&link).is_ok_and(|m| m.file_type().is_symlink()));
        assert_eq!(std::fs::read_to_string(&real).ok().as_deref(), Some("new"));
        let _ = std::fs::remove_dir_all(&d);
        write_atomic(Path::new("/dev/null"), "x").unwrap_or(());
        assert!(std::fs::metadata("/dev/null").is_ok_and(|m| !m.is_file()));
    }
}
