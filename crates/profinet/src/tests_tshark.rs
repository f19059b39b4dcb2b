//! Frames through tshark's dissectors (tests only): a pcap of the frames,
//! `tshark -V` over it, and the check that none of the frames the filter
//! selects is malformed or carries an expert warning or error.

use std::string::String;
use std::vec::Vec;

/// A pcap file (Ethernet link type) of `frames`, one a second.
pub(crate) fn pcap(frames: &[Vec<u8>]) -> Vec<u8> {
    let mut p = Vec::new();
    p.extend_from_slice(&0xa1b2_c3d4u32.to_le_bytes());
    p.extend_from_slice(&2u16.to_le_bytes());
    p.extend_from_slice(&4u16.to_le_bytes());
    for v in [0u32, 0, 65535, 1] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    for (i, f) in frames.iter().enumerate() {
        let len = u32::try_from(f.len()).unwrap_or(0);
        for v in [u32::try_from(i).unwrap_or(0), 0, len, len] {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p.extend_from_slice(f);
    }
    p
}

/// Dissects `frames` with `filter`; the text, or `None` (printed) when
/// tshark is not installed. Fails the test on a malformed frame or an expert
/// warning or error among the selected frames, or when none is selected.
pub(crate) fn dissect(frames: &[Vec<u8>], filter: &str) -> Option<String> {
    dissect_with(frames, filter, false)
}

/// [`dissect`] of the device's DCE/RPC frames (the rigs' device is at
/// 192.168.0.50).
pub(crate) fn device_rpc(frames: &[Vec<u8>]) -> Option<String> {
    dissect(frames, "dcerpc && ip.src == 192.168.0.50")
}

/// [`dissect`], where `undecoded` lets record data the dissector does not
/// know pass (its one "Undecoded" warning per frame).
pub(crate) fn dissect_with(frames: &[Vec<u8>], filter: &str, undecoded: bool) -> Option<String> {
    // one file per call: tests run in parallel (the frame count alone collided)
    static CALLS: core::sync::atomic::AtomicUsize = core::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
    let path = std::env::temp_dir().join(std::format!(
        "profinet-tshark-{}-{}-{call}.pcap",
        std::process::id(),
        frames.len()
    ));
    std::fs::write(&path, pcap(frames)).ok()?;
    let Ok(out) = std::process::Command::new("tshark")
        .args(["-r", &path.to_string_lossy(), "-Y", filter, "-V"])
        .output()
    else {
        std::eprintln!("tshark not installed: pcap left at {}", path.display());
        return None;
    };
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let mut after_undecoded = false;
    let bad: Vec<&str> = text
        .lines()
        .filter(|l| {
            if l.contains("(Warning/Undecoded)") {
                after_undecoded = undecoded;
            }
            if after_undecoded && l.contains("[Severity level: Warning") {
                after_undecoded = false;
                return false;
            }
            l.contains("Malformed")
                || l.contains("[Severity level: Warning")
                || l.contains("[Severity level: Error")
        })
        .collect();
    assert!(out.status.success(), "tshark failed");
    assert!(
        text.lines().any(|l| l.starts_with("Frame ")),
        "no frame selected by {filter}: {}",
        path.display()
    );
    assert!(bad.is_empty(), "{}: {bad:?}", path.display());
    if std::env::var_os("PN_KEEP_PCAP").is_none() {
        let _ = std::fs::remove_file(&path);
    }
    Some(text)
}
