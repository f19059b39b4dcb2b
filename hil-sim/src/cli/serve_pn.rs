//! `hil-sim serve --fieldbus profinet`: `--slaves N` (default 1) simulated
//! drives ([`hil_sim::pn::PnSim`]: the drive personality `drive_pn` with
//! both axes and their motors) answer as PROFINET IO devices on a raw
//! Ethernet interface, as if behind a switch, paced by the wall clock.
//!
//! The first device's interface MAC is the interface's own, the others'
//! are derived from it ([`hil_sim::pn::device_mac`]), their port MACs from
//! theirs ([`hil_sim::pn::port_macs`]); every device sees every frame and
//! takes what is addressed to it. Each starts as shipped: unnamed unless
//! `--name` gives the first one a name (stored in A271), no IP address,
//! I&M0 of the drive with serial numbers SIM0001, SIM0002, …
//!
//! `--control PATH` makes a FIFO there that takes the simulator's commands
//! ([`hil_sim::pn::Command`]: raise a drive event on an axis, acknowledge
//! its fault), one per line, from any process that writes to it (a test's
//! controller in another network namespace shares the file system); a line
//! starting `@K ` goes to drive K (1-based), any other to drive 1. Each
//! command's result, every change of a drive's diagnosis and of its alarm
//! channel's counters (sent, acknowledged) are printed.
//!
//! # Timing
//!
//! The device's time is `CLOCK_MONOTONIC` since the start. Each received
//! frame goes to `Device::receive` at the kernel's receive timestamp (never
//! before a time the device has already seen), and `Device::poll` runs at the
//! deadline it returned, or after frames arrived. Between the two `serve`
//! sleeps on the socket, never past the deadline and at most [`MAX_WAIT`].
//! Frames in both directions go to the `--pcap` recording at the device's
//! time.

use super::args::ServeArgs;
use super::serve::{stop_on_signals, STOP};
use hil_sim::pcap::Recording;
use hil_sim::pn::{self, Command, PnSim};
use hil_sim::raw::{monotonic, RawSocket};
use nanos::Nanos;
use profinet::dcp::NameOfStation;
use profinet::wire::MacAddr;
use std::ffi::CString;
use std::fs::File;
use std::io::{self, Read};
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// The longest sleep on the socket.
pub const MAX_WAIT: Nanos = Nanos::from_ms(1);

/// How often the pcap recording is flushed (a write error then ends `serve`).
const FLUSH_EVERY: Nanos = Nanos::from_secs(1);

/// The interface's MAC, from `/sys/class/net/IF/address`.
fn interface_mac(iface: &str) -> Result<MacAddr, String> {
    let path = format!("/sys/class/net/{iface}/address");
    let text =
        std::fs::read_to_string(&path).map_err(|e| format!("{iface}: cannot read its MAC ({path}: {e})"))?;
    pn::parse_mac(&text).ok_or_else(|| format!("{iface}: {path} holds no MAC: {}", text.trim()))
}

/// Refuses the options that only mean something on EtherCAT.
fn check_options(args: &ServeArgs) -> Result<(), String> {
    if args.slaves == 0 {
        return Err("--slaves 0: at least one drive".into());
    }
    if args.axes.is_some() {
        return Err("--axes is EtherCAT-only".into());
    }
    if args.delay_us.is_some() {
        return Err("--delay-us is EtherCAT-only".into());
    }
    Ok(())
}

/// The control channel: a FIFO read without blocking, line by line.
struct Control {
    path: PathBuf,
    file: File,
    pending: Vec<u8>,
}

impl Control {
    /// Makes the FIFO at `path` (an old one is replaced) and opens it for
    /// reading without blocking.
    fn create(path: &Path) -> Result<Control, String> {
        let _ = std::fs::remove_file(path);
        let c = CString::new(path.as_os_str().as_bytes())
            .map_err(|_| format!("--control {path:?}: a NUL in the path"))?;
        // SAFETY: `c` is a valid NUL-terminated path for the call's duration.
        #[allow(unsafe_code)]
        if unsafe { libc::mkfifo(c.as_ptr(), 0o622) } != 0 {
            return Err(format!(
                "--control {}: mkfifo: {}",
                path.display(),
                io::Error::last_os_error()
            ));
        }
        let file = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NONBLOCK)
            .open(path)
            .map_err(|e| format!("--control {}: {e}", path.display()))?;
        Ok(Control {
            path: path.to_path_buf(),
            file,
            pending: Vec::new(),
        })
    }

    /// The complete lines written since the last call.
    fn lines(&mut self) -> Vec<String> {
        let mut buf = [0u8; 512];
        loop {
            match self.file.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => self.pending.extend_from_slice(buf.get(..n).unwrap_or_default()),
                Err(_) => break,
            }
        }
        let mut out = Vec::new();
        while let Some(end) = self.pending.iter().position(|b| *b == b'\n') {
            let line: Vec<u8> = self.pending.drain(..=end).collect();
            out.push(String::from_utf8_lossy(&line).trim().to_string());
        }
        out
    }
}

impl Drop for Control {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// What the log reports when it changes: the drive's diagnosis and the
/// alarm channel's counters.
#[derive(Debug, Default, PartialEq, Eq)]
struct Watched {
    diagnosis: bool,
    alarms: Option<(u32, u32, u32)>,
}

impl Watched {
    fn of(drive: &PnSim) -> Watched {
        Watched {
            diagnosis: drive.device().diagnosis_present(),
            alarms: drive
                .device()
                .alarm_stats()
                .map(|a| (a.sent, a.acked, a.retransmitted)),
        }
    }
}

/// What the loop counted.
#[derive(Debug, Default)]
struct Stats {
    /// Frames received (not our own).
    received: u64,
    /// Received frames without a kernel timestamp (taken at the time they were read).
    unstamped: u64,
}

/// The frames' way out: the socket and the recording.
struct Out<'a> {
    sock: &'a RawSocket,
    pcap: Option<Recording>,
    sent: u64,
    error: Option<io::Error>,
}

impl Out<'_> {
    fn record(&mut self, t: Nanos, frame: &[u8]) {
        if let Some(r) = self.pcap.as_mut() {
            r.frame(t, frame);
        }
    }

    fn send(&mut self, t: Nanos, frame: &[u8]) {
        self.record(t, frame);
        self.sent += 1;
        if let Err(e) = self.sock.send(frame) {
            self.error.get_or_insert(e);
        }
    }

    /// A send or recording error ends `serve`.
    fn check(&mut self) -> Result<(), String> {
        if let Some(e) = self.error.take() {
            return Err(format!("send: {e}"));
        }
        match self.pcap.as_ref().and_then(|r| r.error()) {
            Some(e) => Err(format!("the pcap recording failed: {e}")),
            None => Ok(()),
        }
    }

    fn flush(&mut self, args: &ServeArgs) -> Result<(), String> {
        match (&args.pcap, self.pcap.as_mut().map(Recording::flush)) {
            (Some(p), Some(Err(e))) => Err(format!("the pcap file {} is incomplete: {e}", p.display())),
            _ => Ok(()),
        }
    }
}

/// Runs the PROFINET device until `--seconds` have passed, SIGINT or SIGTERM.
pub fn serve(args: &ServeArgs) -> Result<(), String> {
    check_options(args)?;
    let name = args.name.as_deref().unwrap_or_default();
    let name = NameOfStation::new(name.as_bytes()).map_err(|e| format!("--name {name:?}: {e:?}"))?;
    // the recording first: an unwritable path fails before anything else
    let pcap = match &args.pcap {
        Some(p) => Some(
            Recording::create(p).map_err(|e| format!("cannot write the pcap file {}: {e}", p.display()))?,
        ),
        None => None,
    };
    let iface = &args.iface;
    let mac = interface_mac(iface)?;
    // every EtherType (DCP, RT, ARP, IPv4, LLDP); our own frames are skipped
    let sock = RawSocket::open_sniffer(iface).map_err(|e| format!("{iface}: {e}"))?;
    // a boot time that differs after every start (the RPC server's)
    let boot_time = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs() as u32)
        .unwrap_or(1);
    let mut drives: Vec<PnSim> = (0..args.slaves)
        .map(|k| {
            let first_name = if k == 0 {
                name.clone()
            } else {
                NameOfStation::EMPTY
            };
            PnSim::named(
                pn::device_mac(mac, k),
                &pn::serial_number(k),
                &first_name,
                boot_time,
            )
        })
        .collect();
    // the motor model: the seed per drive k (from 0) as EtherCAT's serve
    let plant_motor = super::serve::plant_motor(args)?;
    for (k, d) in (0u64..).zip(drives.iter_mut()) {
        super::serve::set_up_plant(d, k, args)?;
        if let Some(apply) = &plant_motor {
            super::serve::apply_plant_motor(d, apply);
        }
    }
    let mut control = args.control.as_deref().map(Control::create).transpose()?;
    println!(
        "hil-sim serve: {} simulated drive(s) as PROFINET IO devices on {iface}",
        drives.len()
    );
    if args.plant == super::args::Plant::Electrical {
        println!(
            "plant: current loop ({} kHz) -> simulated PMSM and inverter on every axis",
            args.pwm_khz.hz() / 1000.0
        );
        if let Some(f) = args.plant_fault {
            println!("plant fault on axis A of every drive: {f:?}");
        }
    }
    for (k, d) in (0u16..).zip(&drives) {
        let m = pn::device_mac(mac, k);
        let ports = pn::port_macs(m);
        let dcp_name = d.device().dcp().name_of_station();
        println!(
            "drive {}: MAC {}, ports {} {}; name of station {}; IP unset; I&M0 serial {}; two axes at rest, control cycle {} us",
            k + 1,
            pn::mac_text(m),
            pn::mac_text(ports[0]),
            pn::mac_text(ports[1]),
            if dcp_name.is_empty() {
                "none".to_string()
            } else {
                format!("\"{}\"", dcp_name.as_str())
            },
            pn::serial_number(k),
            d.drive().control_period().as_us()
        );
    }
    println!(
        "each drive runs the PROFIdrive profile (the Example Function block's telegrams) on its cyclic data"
    );
    if let Some(c) = &control {
        println!(
            "control channel: {} ([@K] fault A|B EVENT CAUSE, reset A|B, status)",
            c.path.display()
        );
    }
    if let Some(p) = &args.pcap {
        println!("recording frames to {}", p.display());
    }
    println!("{}", super::realtime::apply_for_serve(args));
    stop_on_signals();
    let mut out = Out {
        sock: &sock,
        pcap,
        sent: 0,
        error: None,
    };
    let result = run(&mut drives, &sock, &mut out, control.as_mut(), args);
    let flushed = out.flush(args);
    let stats = result?;
    flushed?;
    summary(&drives, &stats, out.sent);
    Ok(())
}

/// The log's prefix of drive `k` (0-based): none with one drive.
fn who(k: usize, n: usize) -> String {
    if n > 1 {
        format!("drive {}: ", k + 1)
    } else {
        String::new()
    }
}

fn print_events(drives: &mut [PnSim], t: Nanos) {
    let n = drives.len();
    for (k, d) in drives.iter_mut().enumerate() {
        while let Some(e) = d.take_event() {
            println!(
                "[{:>10.3} s] {}{}",
                t.as_ns() as f64 / 1e9,
                who(k, n),
                pn::describe(&e)
            );
        }
    }
}

/// A control line: `@K command` for drive K (1-based), else drive 1.
fn control_line(drives: &mut [PnSim], line: &str) -> String {
    let (k, rest) = match line.strip_prefix('@') {
        Some(r) => {
            let (num, rest) = r.split_once(char::is_whitespace).unwrap_or((r, ""));
            match num.parse::<usize>() {
                Ok(k) if (1..=drives.len()).contains(&k) => (k - 1, rest),
                _ => return format!("control: {line:?}: no drive {num:?} (1…{})", drives.len()),
            }
        }
        None => (0, line),
    };
    let n = drives.len();
    match (Command::parse(rest), drives.get_mut(k)) {
        (Ok(cmd), Some(d)) => format!("{}{}", who(k, n), d.command(cmd)),
        (Err(e), _) => format!("control: {e}"),
        (Ok(_), None) => format!("control: no drive {}", k + 1),
    }
}

/// The serve loop (see the module's Timing section).
fn run(
    drives: &mut [PnSim],
    sock: &RawSocket,
    out: &mut Out<'_>,
    mut control: Option<&mut Control>,
    args: &ServeArgs,
) -> Result<Stats, String> {
    let start = monotonic();
    let since = |t: Nanos| t.saturating_sub(start);
    let end = args.seconds.map(|s| Nanos::from_ns((s.max(0.0) * 1e9) as u64));
    let mut stats = Stats::default();
    let mut buf = [0u8; 1600];
    // the latest time the device has seen: its clock never goes back
    let mut last = Nanos::ZERO;
    let mut deadline = Nanos::ZERO;
    let mut next_flush = FLUSH_EVERY;
    let mut watched: Vec<Watched> = drives.iter().map(Watched::of).collect();
    loop {
        let mut got = false;
        while let Some(rx) = sock.try_recv(&mut buf).map_err(|e| format!("receive: {e}"))? {
            if rx.outgoing {
                continue;
            }
            let t = match rx.rx {
                Some(t) => since(t),
                None => {
                    stats.unstamped += 1;
                    since(monotonic())
                }
            }
            .max(last);
            last = t;
            let frame = buf.get(..rx.len).unwrap_or_default();
            stats.received += 1;
            got = true;
            out.record(t, frame);
            for d in drives.iter_mut() {
                d.receive(t, frame, &mut |f: &[u8]| out.send(t, f));
            }
            print_events(drives, t);
            out.check()?;
        }
        let now = since(monotonic()).max(last);
        if got || now >= deadline {
            last = now;
            deadline = Nanos::MAX;
            for d in drives.iter_mut() {
                deadline = deadline.min(d.poll(now, &mut |f: &[u8]| out.send(now, f)));
            }
            print_events(drives, now);
            out.check()?;
        }
        if let Some(c) = control.as_deref_mut() {
            for line in c.lines().iter().filter(|l| !l.is_empty()) {
                let said = control_line(drives, line);
                println!("[{:>10.3} s] {said}", now.as_ns() as f64 / 1e9);
            }
        }
        let n = drives.len();
        for (k, (d, old)) in drives.iter().zip(watched.iter_mut()).enumerate() {
            let w = Watched::of(d);
            if w != *old {
                print_watched(now, old, &w, d, &who(k, n));
                *old = w;
            }
        }
        if now >= next_flush {
            next_flush = now + FLUSH_EVERY;
            out.flush(args)?;
        }
        if end.is_some_and(|e| now >= e) || STOP.load(Ordering::Relaxed) {
            return Ok(stats);
        }
        if !args.busy_poll {
            let wait = deadline.saturating_sub(since(monotonic())).min(MAX_WAIT);
            if wait > Nanos::ZERO {
                sock.wait(Duration::from_nanos(wait.as_ns()))
                    .map_err(|e| format!("wait: {e}"))?;
            }
        }
    }
}

fn print_watched(t: Nanos, old: &Watched, new: &Watched, drive: &PnSim, who: &str) {
    let at = t.as_ns() as f64 / 1e9;
    if old.diagnosis != new.diagnosis {
        println!(
            "[{at:>10.3} s] {who}diagnosis {}: {}",
            if new.diagnosis { "appears" } else { "disappears" },
            drive.status()
        );
    }
    if let (Some((sent, acked, again)), true) = (new.alarms, old.alarms != new.alarms) {
        println!("[{at:>10.3} s] {who}alarms: {sent} sent, {acked} acknowledged, {again} retransmitted");
    }
}

fn summary(drives: &[PnSim], stats: &Stats, sent: u64) {
    println!(
        "{} frames received, {} sent; {} without a kernel timestamp",
        stats.received, sent, stats.unstamped
    );
    let n = drives.len();
    for (k, drive) in drives.iter().enumerate() {
        let who = who(k, n);
        let d = drive.device();
        println!(
            "{who}drive: {} control cycles; {}",
            drive.cycles(),
            drive.status()
        );
        let c = d.counters();
        println!(
            "{who}device counters: runt {}, not for us {}, unknown FrameID {}, no AR {}, other EtherType {}, events lost {}",
            c.runt, c.not_for_us, c.unknown_frame_id, c.no_ar, c.other_ethertype, c.events_lost
        );
        println!("{who}ip counters: {:?}", d.ip().counters());
        println!("{who}rpc counters: {:?}", d.rpc().counters());
        let name = d.dcp().name_of_station();
        let ip = d.dcp().ip_suite();
        println!(
            "{who}name of station at the end: {}; IP {} mask {}",
            if name.is_empty() {
                "none".to_string()
            } else {
                format!("\"{}\"", name.as_str())
            },
            ip.ip,
            ip.mask
        );
    }
}
