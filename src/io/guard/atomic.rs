//! Atomic file output: write a temporary file beside the target, flush it to
//! disk, then rename it over the target. A crash or error midway leaves the
//! old file (or nothing) in place, never a truncated one.

use crate::io::IoError;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(
        ".{name}.{}.{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        IoError::os(path, e)
    })
}

/// Removes the temporary files [`write_atomic`] left beside `path` when a
/// process died midway (killed during a save: `.NAME.PID.N.tmp`, as big as
/// the file), and returns how many. Only those of processes that are no
/// longer running go: another process may be writing its own right now.
/// Where that cannot be known (no `/proc`), nothing is removed.
pub fn remove_orphans(path: &Path) -> usize {
    let proc = Path::new("/proc");
    let (Some(name), true) = (path.file_name(), proc.is_dir()) else {
        return 0;
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let prefix = format!(".{}.", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .filter_map(Result::ok)
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            let Some(rest) = n.strip_prefix(&prefix).and_then(|r| r.strip_suffix(".tmp")) else {
                return false;
            };
            match rest.split_once('.') {
                Some((pid, k))
                    if !pid.is_empty()
                        && pid.bytes().all(|b| b.is_ascii_digit())
                        && k.bytes().all(|b| b.is_ascii_digit()) =>
                {
                    !proc.join(pid).exists()
                }
                _ => false,
            }
        })
        .filter(|e| std::fs::remove_file(e.path()).is_ok())
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_target_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn failure_names_the_file_and_keeps_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing-dir").join("a.bin");
        let err = write_atomic(&p, b"x").unwrap_err();
        assert!(err.to_string().contains("a.bin"), "{err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn orphans_of_dead_processes_go_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("design.json");
        let me = std::process::id();
        // PIDs never exceed 2^22 on Linux: 99999999 is no process.
        let names = [
            ".design.json.99999999.0.tmp".to_string(),
            ".design.json.99999999.17.tmp".to_string(),
            format!(".design.json.{me}.3.tmp"),
            ".design.json.99999999.x.tmp".to_string(),
            ".other.json.99999999.0.tmp".to_string(),
            "design.json".to_string(),
        ];
        for n in &names {
            std::fs::write(dir.path().join(n), b"x").unwrap();
        }
        let removed = remove_orphans(&p);
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        if Path::new("/proc").is_dir() {
            assert_eq!(removed, 2);
            let mut want = names[2..].to_vec();
            want.sort();
            assert_eq!(left, want);
        } else {
            assert_eq!(removed, 0);
        }
    }
}
