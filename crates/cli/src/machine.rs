//! Memory sizes: the memory this process may use, read from the machine and the process's
//! limits (every command's default `--max-memory`), and the parser of the sizes users give.

/// The memory this process may take, and what sets it: the least of the machine's memory
/// (Linux: /proc/meminfo), its control group's limit (cgroup v2 `memory.max`, v1
/// `memory.limit_in_bytes`) and its address-space and data-size limits (`ulimit -v`, `-d`);
/// 8 GiB where none can be read.
pub fn machine_memory() -> (u64, String) {
    let bytes = glint_io::format_bytes;
    let mut least: Option<(u64, String)> = None;
    let mut consider = |limit: Option<u64>, name: &dyn Fn(u64) -> String| {
        if let Some(limit) = limit {
            if least.as_ref().is_none_or(|(bytes, _)| limit < *bytes) {
                least = Some((limit, name(limit)));
            }
        }
    };
    consider(meminfo_total(), &|b| format!("the machine's {}", bytes(b)));
    consider(cgroup_limit(), &|b| {
        format!("the control group's {} limit", bytes(b))
    });
    for (row, what) in [
        ("Max address space", "address-space limit (ulimit -v)"),
        ("Max data size", "data-size limit (ulimit -d)"),
    ] {
        consider(process_limit(row), &|b| format!("the {} {what}", bytes(b)));
    }
    least.unwrap_or((8 << 30, "an assumed 8 GiB".to_owned()))
}

/// Half of `machine_memory`: room for what the estimate cannot see (the loader's parse trees
/// while they live, the allocator's slack, other programs).
pub fn default_max_memory() -> u64 {
    machine_memory().0 / 2
}

/// What sets the budget, for messages: the option, or the default's source.
pub fn max_memory_source(given: Option<u64>) -> String {
    match given {
        Some(_) => "set by --max-memory".to_owned(),
        None => format!("half of {}", machine_memory().1),
    }
}

fn meminfo_total() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|line| line.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// The memory limit of this process's control group, where it has one.
fn cgroup_limit() -> Option<u64> {
    let membership = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    // cgroup v2: one line `0::/path`.
    if let Some(path) = membership.lines().find_map(|line| line.strip_prefix("0::")) {
        let file = format!("/sys/fs/cgroup{}/memory.max", path.trim_end_matches('/'));
        if let Ok(text) = std::fs::read_to_string(file) {
            return text.trim().parse().ok();
        }
    }
    // cgroup v1; "no limit" reads as a huge number, which never wins.
    let text = std::fs::read_to_string("/sys/fs/cgroup/memory/memory.limit_in_bytes").ok()?;
    text.trim().parse().ok()
}

/// The soft limit of a row of /proc/self/limits given in bytes (`unlimited`: none).
fn process_limit(row: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = text.lines().find(|line| line.starts_with(row))?;
    line[row.len()..].split_whitespace().next()?.parse().ok()
}

/// Parses a byte count: `1048576`, `512K`, `64M`, `4G`, `1T` (binary units; a trailing `B`
/// or `iB` is allowed).
pub fn parse_size(text: &str) -> Result<u64, String> {
    let trimmed = text.trim();
    let upper = trimmed.to_ascii_uppercase();
    let without_b = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (number, shift) = match without_b.chars().last() {
        Some('K') => (&without_b[..without_b.len() - 1], 10),
        Some('M') => (&without_b[..without_b.len() - 1], 20),
        Some('G') => (&without_b[..without_b.len() - 1], 30),
        Some('T') => (&without_b[..without_b.len() - 1], 40),
        _ => (without_b, 0),
    };
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a size (e.g. 4G, 512M, 1048576)"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("'{text}' is not a usable size"));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_memory_this_process_may_use_is_read_and_named() {
        let (bytes, source) = machine_memory();
        assert!(bytes > 0);
        assert!(!source.is_empty());
        assert_eq!(default_max_memory(), bytes / 2);
        assert!(max_memory_source(None).starts_with("half of "));
    }
}
