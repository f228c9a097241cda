//! Memory checks before large allocations: a size the user asked for (a
//! synthesis, a resampled grid) is compared with the memory the system can
//! give now, so that an impossible request is refused up front with the
//! numbers instead of ending in the out-of-memory killer.

use crate::io::IoError;

/// Bytes the system can give without swapping (`MemAvailable` of
/// `/proc/meminfo`), `None` where that is not known.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Refuses `needed` bytes for `what` when more than the available memory.
/// Passes where the available memory is unknown (the allocation then fails
/// or succeeds on its own).
pub fn check_memory(what: &str, needed: u64) -> Result<(), IoError> {
    match available_memory() {
        Some(avail) if needed > avail => Err(IoError::Memory {
            what: what.to_string(),
            needed_mib: needed.div_ceil(1 << 20),
            available_mib: avail >> 20,
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_requests_are_refused_with_numbers() {
        if available_memory().is_none() {
            eprintln!("skipped: /proc/meminfo has no MemAvailable here");
            return;
        }
        let e = check_memory("a 30000x30000 synthesis", u64::MAX / 2).unwrap_err();
        let t = e.to_string();
        assert!(t.contains("30000x30000") && t.contains("MiB"), "{t}");
        check_memory("one byte", 1).unwrap();
    }
}
