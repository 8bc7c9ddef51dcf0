//! Where results came from: the machine and the code, recorded in every CSV row so a number can
//! be trusted (or questioned) without asking who ran it.

/// `CPU model name (N threads)` from /proc/cpuinfo, else the target architecture and OS. The
/// name loses its trademark marks and a closing "Processor" or "CPU" ("Intel(R) Xeon(R)
/// Processor" is written "Intel Xeon"): the same information, and every CSV row carries it.
pub fn machine() -> String {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cpu = std::fs::read_to_string("/proc/cpuinfo").ok().and_then(|info| {
        info.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split_once(':')).map(|(_, name)| {
            let name = name.replace("(R)", "").replace("(TM)", "").replace("(tm)", "");
            let mut words: Vec<&str> = name.split_whitespace().collect();
            if words.len() > 1 && matches!(words.last(), Some(&("Processor" | "CPU"))) {
                words.pop();
            }
            words.join(" ")
        })
    });
    let cpu = cpu.unwrap_or_else(|| format!("{} {}", std::env::consts::ARCH, std::env::consts::OS));
    format!("{cpu} ({threads} threads)")
}

/// `git rev-parse --short HEAD` of the working directory, `-dirty` when anything but the
/// experiment outputs (results/, paper-figures/) differs from it, `unknown` outside git (or
/// before the first commit). Outputs are excluded so that regenerating one figure does not mark
/// the next one of the same run as built from modified code.
pub fn commit() -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short", "HEAD"]) {
        None => "unknown".into(),
        Some(hash) => match git(&["status", "--porcelain", "--", ".", ":!results", ":!paper-figures"]) {
            Some(changes) if !changes.is_empty() => format!("{hash}-dirty"),
            _ => hash,
        },
    }
}
