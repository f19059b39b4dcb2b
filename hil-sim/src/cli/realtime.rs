//! Real-time settings of `serve`, tried when permitted: SCHED_FIFO and a CPU
//! of its own. Refusal (no root or CAP_SYS_NICE, a CPU not in the allowed
//! set) is not an error: `serve` runs as an ordinary process and says so.

/// Asks for SCHED_FIFO at `priority` if given (`None`: `--busy-poll`, which
/// must not spin as a real-time process) and pins the process to `cpu` if
/// given; returns a line saying what was applied.
pub fn apply(priority: Option<i32>, cpu: Option<usize>) -> String {
    let fifo = match priority.map(set_fifo) {
        None => "no SCHED_FIFO (--busy-poll spins)".to_string(),
        Some(Ok(p)) => format!("SCHED_FIFO priority {p}"),
        Some(Err(e)) => format!("no SCHED_FIFO ({e})"),
    };
    let pin = match cpu.map(pin) {
        None => "not pinned (--cpu N pins)".to_string(),
        Some(Ok(c)) => format!("pinned to CPU {c}"),
        Some(Err(e)) => format!("not pinned ({e})"),
    };
    format!("real-time: {fifo}, {pin}")
}

/// [`apply`] as `serve` (both fieldbuses) asks for it: nothing with
/// `--no-rt`; no SCHED_FIFO with `--busy-poll` (a spinning SCHED_FIFO
/// process is throttled by the kernel (sched_rt_runtime_us) for tens of ms
/// every second and starves its CPU's softirqs); else SCHED_FIFO at
/// `--fifo-priority`. Returns the line to print.
pub fn apply_for_serve(args: &super::args::ServeArgs) -> String {
    if args.no_rt {
        "real-time: not asked for (--no-rt)".to_string()
    } else if args.busy_poll {
        apply(None, args.cpu)
    } else {
        apply(Some(args.fifo_priority), args.cpu)
    }
}

fn set_fifo(priority: i32) -> std::io::Result<i32> {
    let p = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: p is a valid sched_param; pid 0 is this process.
    #[allow(unsafe_code)]
    let r = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &p) };
    if r < 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(priority)
}

fn pin(cpu: usize) -> Result<usize, String> {
    // SAFETY: set is a valid cpu_set_t of the size passed; the CPU_* helpers
    // stay within it (indexes below CPU_SETSIZE).
    #[allow(unsafe_code)]
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        let size = std::mem::size_of::<libc::cpu_set_t>();
        if libc::sched_getaffinity(0, size, &mut set) < 0 {
            return Err(std::io::Error::last_os_error().to_string());
        }
        let max = libc::CPU_SETSIZE as usize;
        let allowed: Vec<usize> = (0..max).filter(|&c| libc::CPU_ISSET(c, &set)).collect();
        if !allowed.contains(&cpu) {
            return Err(format!("CPU {cpu} is not in the allowed set {allowed:?}"));
        }
        let mut one: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut one);
        if libc::sched_setaffinity(0, size, &one) < 0 {
            return Err(std::io::Error::last_os_error().to_string());
        }
        Ok(cpu)
    }
}
