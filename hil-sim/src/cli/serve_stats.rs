//! What `serve`'s loop measures and prints at its end: answer times as
//! histograms, and the slowest answers with what made them slow (issue 33
//! point 6: a strict master such as KickCAT waits 2 ms for each frame).
//!
//! Every frame's answer time (kernel receive → answer sent) splits into the
//! time it waited before the loop picked it up (the loop was busy keeping the
//! simulation at the wall clock, or the machine ran something else) and the
//! work on it: catching the simulation up to the frame's receive time and
//! processing it. The work is also measured as this thread's CPU time
//! (`CLOCK_THREAD_CPUTIME_ID`), which a busy machine does not inflate: a
//! slow answer with little CPU time was preempted, one with much CPU time is
//! the simulation's own cost.

use nanos::Nanos;

/// This thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`).
pub(super) fn thread_cpu() -> Nanos {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given, nothing else.
    #[allow(unsafe_code)]
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return Nanos::ZERO;
    }
    let s = u64::try_from(ts.tv_sec).unwrap_or(0);
    let ns = u64::try_from(ts.tv_nsec).unwrap_or(0);
    Nanos::from_ns(s.saturating_mul(1_000_000_000).saturating_add(ns))
}

/// What the loop saw.
#[derive(Debug, Default)]
pub(super) struct Stats {
    /// Frames without a kernel timestamp (processed at the time they were read).
    pub unstamped: u64,
    /// Frames whose receive time the simulation had passed by more than `LATE_NOTE`.
    pub late: u64,
    /// The most the simulation had passed a frame's receive time.
    pub worst_late: Nanos,
    /// From the kernel's receive timestamp to the answer sent (without `--delay-us`'s hold).
    pub answer: Histogram,
    /// Of that, catching the simulation up and processing the frame.
    pub work: Histogram,
    /// The CPU time of that work.
    pub work_cpu: Histogram,
    /// The CPU time of one idle step (keeping the simulation at the wall
    /// clock while no frame waits): a frame arriving meanwhile waits for it.
    pub idle_cpu: Histogram,
    /// The wall time of one idle step.
    pub idle_wall: Histogram,
    /// The slowest answers.
    pub slowest: Slowest,
}

/// Durations in 1 µs buckets up to 10 ms (longer ones in the last).
#[derive(Debug)]
pub(super) struct Histogram {
    counts: Vec<u32>,
    max: Nanos,
}

impl Default for Histogram {
    fn default() -> Self {
        Self {
            counts: vec![0; 10_001],
            max: Nanos::ZERO,
        }
    }
}

impl Histogram {
    pub fn add(&mut self, span: Nanos) {
        let i = usize::try_from(span.as_us())
            .unwrap_or(usize::MAX)
            .min(self.counts.len() - 1);
        if let Some(c) = self.counts.get_mut(i) {
            *c = c.saturating_add(1);
        }
        self.max = self.max.max(span);
    }

    /// The `p` quantile (0..=1), µs (bucket upper edge).
    fn quantile_us(&self, p: f64) -> u64 {
        let total: u64 = self.counts.iter().map(|&c| u64::from(c)).sum();
        let want = ((total as f64) * p).ceil().max(1.0) as u64;
        let mut seen = 0;
        for (i, &c) in self.counts.iter().enumerate() {
            seen += u64::from(c);
            if seen >= want {
                return i as u64 + 1;
            }
        }
        0
    }

    /// "p50 a, p99 b, max c µs".
    pub fn summary(&self) -> String {
        format!(
            "p50 {}, p99 {}, max {:.0} µs",
            self.quantile_us(0.5),
            self.quantile_us(0.99),
            self.max.as_ns() as f64 / 1e3
        )
    }
}

/// One answer and where its time went.
#[derive(Debug, Clone)]
pub(super) struct Answer {
    /// Frame number (from 1).
    pub n: u64,
    /// Simulated time of the frame's arrival.
    pub at: Nanos,
    /// Kernel receive → answer sent.
    pub answer: Nanos,
    /// Kernel receive → picked up by the loop.
    pub waited: Nanos,
    /// CPU time of catching up to the frame's receive time.
    pub catch_up_cpu: Nanos,
    /// CPU time of processing the frame.
    pub exchange_cpu: Nanos,
    /// The idle step before the frame: wall time, CPU time.
    pub idle_before: (Nanos, Nanos),
    /// Its datagrams, e.g. "FPWR 1001:1000 128".
    pub frame: String,
}

/// The [`Slowest::KEEP`] slowest answers.
#[derive(Debug, Default)]
pub(super) struct Slowest {
    kept: Vec<Answer>,
}

impl Slowest {
    /// How many are kept.
    const KEEP: usize = 8;

    /// Whether an answer this slow would be kept (describing the frame
    /// costs an allocation: only then).
    pub fn wants(&self, answer: Nanos) -> bool {
        self.kept.len() < Self::KEEP || self.kept.iter().any(|a| a.answer < answer)
    }

    pub fn add(&mut self, a: Answer) {
        self.kept.push(a);
        self.kept.sort_by_key(|a| std::cmp::Reverse(a.answer));
        self.kept.truncate(Self::KEEP);
    }

    /// One line per answer, slowest first.
    pub fn lines(&self) -> Vec<String> {
        let us = |t: Nanos| t.as_ns() as f64 / 1e3;
        self.kept
            .iter()
            .map(|a| {
                format!(
                    "  frame {} at {:.3} ms: answer {:.0} µs = waited {:.0} + {:.0} µs; CPU: catch-up {:.0} µs, \
                     frame {:.0} µs; the idle step before: {:.0} µs (CPU {:.0} µs); {}",
                    a.n,
                    a.at.as_ns() as f64 / 1e6,
                    us(a.answer),
                    us(a.waited),
                    us(a.answer.saturating_sub(a.waited)),
                    us(a.catch_up_cpu),
                    us(a.exchange_cpu),
                    us(a.idle_before.0),
                    us(a.idle_before.1),
                    a.frame
                )
            })
            .collect()
    }
}

/// The EtherCAT datagrams of a frame, shortly: command, ADP:ADO (or the
/// logical address), length; "not EtherCAT" for anything else.
pub(super) fn describe(frame: &[u8]) -> String {
    const NAMES: [&str; 15] = [
        "NOP", "APRD", "APWR", "APRW", "FPRD", "FPWR", "FPRW", "BRD", "BWR", "BRW", "LRD", "LWR", "LRW",
        "ARMW", "FRMW",
    ];
    let Some(body) = frame.get(16..) else {
        return "short frame".into();
    };
    if frame.get(12..14) != Some(&[0x88, 0xA4]) {
        return "not EtherCAT".into();
    }
    let mut out = Vec::new();
    let mut rest = body;
    while let Some(h) = rest.get(..10) {
        let cmd = h.first().copied().unwrap_or(0);
        let name = NAMES.get(usize::from(cmd)).copied().unwrap_or("?");
        let word = |i: usize| {
            u16::from_le_bytes([h.get(i).copied().unwrap_or(0), h.get(i + 1).copied().unwrap_or(0)])
        };
        let (adp, ado, len) = (word(2), word(4), word(6));
        let n = usize::from(len & 0x7FF);
        if (10..=12).contains(&cmd) {
            out.push(format!(
                "{name} {:08X} {n}",
                u32::from(adp) | u32::from(ado) << 16
            ));
        } else {
            out.push(format!("{name} {adp:04X}:{ado:04X} {n}"));
        }
        if len & 0x8000 == 0 || out.len() >= 6 {
            break;
        }
        rest = rest.get(10 + n + 2..).unwrap_or_default();
    }
    out.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn describe_names_each_datagram() {
        let mut f = vec![0u8; 14];
        f[12] = 0x88;
        f[13] = 0xA4;
        f.extend_from_slice(&[0, 0]);
        // FPWR 03E9:1000, 4 bytes, more follows
        f.extend_from_slice(&[5, 0, 0xE9, 0x03, 0x00, 0x10, 4, 0x80, 0, 0]);
        f.extend_from_slice(&[0; 4 + 2]);
        // LRW 0x00010000, 2 bytes
        f.extend_from_slice(&[12, 1, 0, 0, 1, 0, 2, 0, 0, 0]);
        f.extend_from_slice(&[0; 2 + 2]);
        assert_eq!(describe(&f), "FPWR 03E9:1000 4, LRW 00010000 2");
        assert_eq!(describe(&f[..10]), "short frame");
    }

    #[test]
    fn slowest_keeps_the_slowest_first() {
        let mut s = Slowest::default();
        for k in 0..20u64 {
            let answer = Nanos::from_us((k * 7) % 20);
            if s.wants(answer) {
                s.add(Answer {
                    n: k,
                    at: Nanos::ZERO,
                    answer,
                    waited: Nanos::ZERO,
                    catch_up_cpu: Nanos::ZERO,
                    exchange_cpu: Nanos::ZERO,
                    idle_before: (Nanos::ZERO, Nanos::ZERO),
                    frame: String::new(),
                });
            }
        }
        let kept: Vec<u64> = s.kept.iter().map(|a| a.answer.as_us()).collect();
        assert_eq!(kept, [19, 18, 17, 16, 15, 14, 13, 12]);
    }
}
