//! How much memory this process can still take, so that work sized by the
//! user (a grid's nodes) is refused with a message instead of ending in
//! an allocation failure, which aborts the process (a Python kernel dies
//! with it).
//!
//! On Linux: the smaller of the system's available memory
//! (`MemAvailable` of `/proc/meminfo`) and what the address-space limit
//! (`ulimit -v`, `RLIMIT_AS`: `/proc/self/limits`) leaves above the
//! process's present size (`VmSize` of `/proc/self/status`). Elsewhere,
//! or when none of these can be read: unknown (`None`), and nothing is
//! refused.

/// Bytes as the messages about memory write them: GB with one decimal, or
/// MB below a GB (`1.6 GB`, `320 MB`).
pub fn size_text(bytes: u64) -> String {
    if bytes >= 1_000_000_000 {
        format!("{:.1} GB", bytes as f64 / 1e9)
    } else {
        format!("{:.0} MB", bytes as f64 / 1e6)
    }
}

/// The bytes this process can still allocate, as far as the system says
/// (module docs); `None` when unknown.
pub fn available_bytes() -> Option<u64> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let system = read("/proc/meminfo").and_then(|t| kib_field(&t, "MemAvailable:"));
    let limit = read("/proc/self/limits").and_then(|t| address_space_limit(&t));
    let size = read("/proc/self/status").and_then(|t| kib_field(&t, "VmSize:"));
    let under_limit = limit.map(|l| l.saturating_sub(size.unwrap_or(0)));
    match (system, under_limit) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The value of a `NAME:   1234 kB` line of `/proc/meminfo` or
/// `/proc/self/status`, in bytes.
fn kib_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let mut words = line[name.len()..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then(|| value.saturating_mul(1024))
}

/// The soft address-space limit of `/proc/self/limits`, bytes; `None`
/// when unlimited.
fn address_space_limit(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("Max address space"))?;
    line.split_whitespace().nth(3)?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_proc_files_are_read_as_the_kernel_writes_them() {
        let meminfo = "MemTotal:       24576000 kB\nMemFree:         1000000 kB\nMemAvailable:   20000000 kB\n";
        assert_eq!(kib_field(meminfo, "MemAvailable:"), Some(20_000_000 * 1024));
        assert_eq!(kib_field(meminfo, "SwapTotal:"), None);
        let limits = "Limit                     Soft Limit           Hard Limit           Units\n\
                      Max cpu time              unlimited            unlimited            seconds\n\
                      Max address space         6442450944           unlimited            bytes\n";
        assert_eq!(address_space_limit(limits), Some(6_442_450_944));
        let unlimited = limits.replace("6442450944", "unlimited");
        assert_eq!(address_space_limit(&unlimited), None);
    }

    #[test]
    fn this_machine_says_something_plausible() {
        if let Some(b) = available_bytes() {
            assert!(b > 0, "{b}");
        }
    }
}
