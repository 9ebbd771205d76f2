//! The memory limit: the largest single buffer that a size derived from a user's argument may
//! ask for ([`crate::alloc`] checks requests against it). By default the machine's physical
//! memory, read once from the operating system; the environment variable `WSCG_MAX_MEMORY`
//! (bytes, read on first use) or [`set_limit`] change it for the whole process.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// The environment variable that sets the memory limit in bytes (read once, on first use).
pub const ENV_VAR: &str = "WSCG_MAX_MEMORY";

/// The limit set by [`set_limit`]; 0 when none was set (the default applies).
static LIMIT: AtomicU64 = AtomicU64::new(0);

/// The machine's physical memory in bytes, read once (`MemTotal` of `/proc/meminfo` on
/// Linux); `None` where the operating system does not tell.
pub fn physical_memory() -> Option<u64> {
    static MEM: OnceLock<Option<u64>> = OnceLock::new();
    *MEM.get_or_init(read_physical_memory)
}

#[cfg(target_os = "linux")]
fn read_physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

#[cfg(not(target_os = "linux"))]
fn read_physical_memory() -> Option<u64> {
    None
}

/// The limit before any [`set_limit`]: `WSCG_MAX_MEMORY` when it holds a byte count > 0, else
/// the physical memory, else no limit (`u64::MAX`).
pub fn default_limit() -> u64 {
    static DEFAULT: OnceLock<u64> = OnceLock::new();
    *DEFAULT.get_or_init(|| {
        std::env::var(ENV_VAR)
            .ok()
            .and_then(|v| v.trim().parse::<u64>().ok())
            .filter(|&v| v > 0)
            .or_else(physical_memory)
            .unwrap_or(u64::MAX)
    })
}

/// The largest single allocation, in bytes, that [`ensure_bytes`] accepts.
pub fn limit() -> u64 {
    match LIMIT.load(Ordering::Relaxed) {
        0 => default_limit(),
        n => n,
    }
}

/// Sets the limit for the whole process (`None` or `Some(0)` restores [`default_limit`]).
/// Raising it above the physical memory lets a machine with swap or a generous overcommit
/// policy take larger requests.
pub fn set_limit(bytes: Option<u64>) {
    LIMIT.store(bytes.unwrap_or(0), Ordering::Relaxed);
}

/// Formats a byte count for a message: `8.0 TB (8000000000000 bytes)`.
pub fn describe_bytes(bytes: Option<u128>) -> String {
    match bytes {
        None => "a size beyond the address space".to_string(),
        Some(b) => {
            let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
            let mut v = b as f64;
            let mut u = 0;
            while v >= 1000.0 && u + 1 < units.len() {
                v /= 1000.0;
                u += 1;
            }
            if u == 0 {
                format!("{b} bytes")
            } else if v < 1e6 {
                format!("{v:.1} {} ({b} bytes)", units[u])
            } else {
                format!("{b} bytes")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_read_well() {
        assert_eq!(describe_bytes(Some(12)), "12 bytes");
        assert_eq!(
            describe_bytes(Some(8_000_000_000_000)),
            "8.0 TB (8000000000000 bytes)"
        );
        assert!(describe_bytes(None).contains("address space"));
    }
}
