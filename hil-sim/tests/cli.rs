//! The command line as a newcomer meets it (issue 14): `--help` for every
//! subcommand, unknown flags refused, and an output file that cannot be
//! written refused up front with a non-zero exit and a message naming it,
//! never a claim that a plot or a recording exists.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;
use std::process::{Command, Output};

fn hil_sim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hil-sim"))
        .args(args)
        .output()
        .expect("run hil-sim")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// What `hil-sim args` printed on stdout; it must succeed.
fn stdout_of(args: &[&str]) -> String {
    let o = hil_sim(args);
    assert!(o.status.success(), "{o:?}");
    text(&o.stdout)
}

/// `hil-sim args` refused with a message naming `path`; its stdout.
fn refused_naming(args: &[&str], path: &str) -> String {
    let o = hil_sim(args);
    assert!(!o.status.success(), "{o:?}");
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(err.contains(path), "the message names the path: {err}");
    out
}

/// Each of `wants` must stand in `out`.
fn assert_lists(out: &str, wants: &[&str]) {
    for want in wants {
        assert!(out.contains(want), "`{want}` missing in:\n{out}");
    }
}

/// A directory of this test's own, removed at the end.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let d = std::env::temp_dir().join(format!("hil-sim-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Self(d)
    }
    /// A path below a regular file: no one, not even root, can create it.
    fn unwritable(&self, file: &str) -> PathBuf {
        let blocker = self.0.join("not-a-directory");
        std::fs::write(&blocker, b"a file").unwrap();
        blocker.join(file)
    }
}

/// `hil-sim demo <args> --pcap run.pcap --plot run.svg` in a scratch
/// directory `name`: it succeeds, names the plot it writes, the plot is a
/// whole SVG and the recording a pcap; its stdout, the SVG, the pcap's bytes
/// and its path.
fn demo_recorded(name: &str, args: &[&str]) -> (String, String, Vec<u8>, String) {
    let s = Scratch::new(name);
    let (pcap, plot) = (s.0.join("run.pcap"), s.0.join("run.svg"));
    let mut all = vec!["demo"];
    all.extend_from_slice(args);
    all.extend(["--pcap", pcap.to_str().unwrap(), "--plot", plot.to_str().unwrap()]);
    let o = hil_sim(&all);
    assert!(o.status.success(), "{o:?}");
    let out = text(&o.stdout);
    assert!(out.contains(&format!("plot: {}", plot.display())), "{out}");
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.contains("<svg") && svg.trim_end().ends_with("</svg>"),
        "a whole SVG"
    );
    let p = std::fs::read(&pcap).unwrap();
    assert_eq!(p.get(..4), Some(&0xA1B2_3C4Du32.to_le_bytes()[..]), "pcap magic");
    (out, svg, p, pcap.display().to_string())
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn help_lists_the_subcommands() {
    let out = stdout_of(&["--help"]);
    assert_lists(&out, &["demo", "serve", "Usage: hil-sim"]);
    assert!(out.ends_with('\n'), "help ends with a newline");
}

#[test]
fn demo_help_lists_its_options() {
    let out = stdout_of(&["demo", "--help"]);
    assert_lists(
        &out,
        &["--pcap <FILE>", "--plot <FILE.svg>", "target/hil-sim-demo.svg"],
    );
}

#[test]
fn serve_help_lists_its_options_not_the_test_ones() {
    let out = stdout_of(&["serve", "--help"]);
    assert_lists(
        &out,
        &[
            "--iface <IF>",
            "--slaves <N>",
            "--axes <1|2>",
            "--pcap <FILE>",
            "--seconds <S>",
            "--plant <MODEL>",
            "--plant-fault <FAULT>",
            "--pwm-khz <KHZ>",
        ],
    );
    assert!(
        !out.contains("--delay-us"),
        "test-only options stay hidden:\n{out}"
    );
}

#[test]
fn an_unknown_flag_is_refused() {
    for args in [
        &["demo", "--bogus"][..],
        &["serve", "--iface", "lo", "--bogus"],
        &["bogus"],
    ] {
        let o = hil_sim(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {o:?}");
        let err = text(&o.stderr);
        assert!(
            err.contains("bogus"),
            "{args:?}: the message names the argument: {err}"
        );
        assert!(o.stdout.is_empty(), "{args:?}: nothing ran: {}", text(&o.stdout));
    }
}

#[test]
fn serve_plant_fault_needs_the_electrical_plant_and_an_unknown_plant_is_refused() {
    for bus in ["ethercat", "profinet"] {
        let o = hil_sim(&[
            "serve",
            "--iface",
            "lo",
            "--fieldbus",
            bus,
            "--plant",
            "rigid",
            "--plant-fault",
            "short",
        ]);
        assert!(!o.status.success(), "{bus}: {o:?}");
        assert!(
            text(&o.stderr).contains("--plant-fault needs --plant electrical"),
            "{bus}: {}",
            text(&o.stderr)
        );
    }
    let o = hil_sim(&["serve", "--iface", "lo", "--plant", "bogus"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(text(&o.stderr).contains("--plant"), "{}", text(&o.stderr));
    // the current loop runs at 16 or 8 kHz, nothing else
    let o = hil_sim(&["serve", "--iface", "lo", "--pwm-khz", "12"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = text(&o.stderr);
    assert!(
        err.contains("12") && err.contains("16") && err.contains('8'),
        "{err}"
    );
}

/// Issue 35: `--plant-fault` offers the faults the motor actions (A75) find,
/// besides the trips' ones, each described in `--help`; a brake fault with
/// `--flywheel` (which has no brake) is refused before anything runs.
#[test]
fn serve_plant_fault_offers_the_motor_actions_faults() {
    let out = stdout_of(&["serve", "--help"]);
    for want in [
        "short",
        "encoder",
        "swapped-phases",
        "open-phase",
        "unbalanced-winding",
        "reversed-encoder",
        "slipping-brake",
        "stuck-brake",
    ] {
        assert!(
            out.contains(&format!("{want}:")),
            "`{want}` not described in:\n{out}"
        );
    }
    for fault in ["slipping-brake", "stuck-brake"] {
        let o = hil_sim(&[
            "serve",
            "--iface",
            "lo",
            "--flywheel",
            "0.01",
            "--plant-fault",
            fault,
        ]);
        assert!(!o.status.success(), "{fault}: {o:?}");
        assert!(
            text(&o.stderr).contains("--flywheel has no holding brake"),
            "{fault}: {}",
            text(&o.stderr)
        );
        assert!(o.stdout.is_empty(), "{fault}: nothing ran: {}", text(&o.stdout));
    }
}

#[test]
fn an_out_of_range_value_is_refused() {
    let o = hil_sim(&["serve", "--iface", "lo", "--slaves", "129"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(text(&o.stderr).contains("--slaves"));
}

#[test]
fn demo_refuses_an_unwritable_plot_before_the_run() {
    let s = Scratch::new("plot");
    let plot = s.unwritable("x.svg");
    let plot = plot.to_str().unwrap();
    let out = refused_naming(&["demo", "--plot", plot], plot);
    assert!(!out.contains("plot:"), "no plot claimed: {out}");
    assert!(!out.contains("found"), "refused before the run: {out}");
}

#[test]
fn demo_refuses_an_unwritable_pcap_before_the_run() {
    let s = Scratch::new("demo-pcap");
    let pcap = s.unwritable("a.pcap");
    let pcap = pcap.to_str().unwrap();
    let plot = s.0.join("x.svg");
    let out = refused_naming(&["demo", "--pcap", pcap, "--plot", plot.to_str().unwrap()], pcap);
    assert!(!out.contains("recording"), "no recording claimed: {out}");
    assert!(!plot.exists(), "nothing ran, no plot");
}

#[test]
fn demo_refuses_a_pcap_that_takes_no_data() {
    // /dev/full opens but every write fails: the header is flushed at once
    let o = hil_sim(&["demo", "--pcap", "/dev/full"]);
    assert!(!o.status.success(), "{o:?}");
    assert!(text(&o.stderr).contains("/dev/full"), "{}", text(&o.stderr));
    assert!(!text(&o.stdout).contains("recording"));
}

#[test]
fn serve_refuses_an_unwritable_pcap_before_opening_the_interface() {
    let s = Scratch::new("serve-pcap");
    let pcap = s.unwritable("a.pcap");
    let pcap = pcap.to_str().unwrap();
    // the interface does not exist either: the pcap is checked first
    let out = refused_naming(
        &[
            "serve",
            "--iface",
            "nonexistent0",
            "--pcap",
            pcap,
            "--seconds",
            "1",
        ],
        pcap,
    );
    assert!(!out.contains("recording"), "no recording claimed: {out}");
}

#[test]
fn serve_needs_an_interface() {
    let o = hil_sim(&["serve"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(text(&o.stderr).contains("--iface"));
}

#[test]
fn demo_writes_the_plot_and_the_pcap_it_names() {
    let (out, _, p, pcap) = demo_recorded("demo", &[]);
    assert!(out.contains(&format!("recording frames to {pcap}")), "{out}");
    assert!(p.len() > 100_000, "frames recorded: {} bytes", p.len());
}

#[test]
fn no_subcommand_runs_the_demo_with_the_default_plot() {
    let s = Scratch::new("default");
    let o = Command::new(env!("CARGO_BIN_EXE_hil-sim"))
        .current_dir(&s.0)
        .output()
        .expect("run hil-sim");
    assert!(o.status.success(), "{o:?}");
    assert!(text(&o.stdout).contains("plot: target/hil-sim-demo.svg"));
    let svg = std::fs::read_to_string(s.0.join("target/hil-sim-demo.svg")).unwrap();
    assert!(svg.contains("<svg"));
}

#[test]
fn demo_help_documents_the_fieldbus_and_its_plot() {
    let out = stdout_of(&["demo", "--help"]);
    assert_lists(
        &out,
        &[
            "--fieldbus <BUS>",
            "ethercat",
            "profinet",
            "target/hil-sim-demo-pn.svg",
        ],
    );
}

#[test]
fn demo_refuses_an_unknown_fieldbus() {
    let o = hil_sim(&["demo", "--fieldbus", "canopen"]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert!(text(&o.stderr).contains("canopen"), "{}", text(&o.stderr));
    assert!(o.stdout.is_empty(), "nothing ran: {}", text(&o.stdout));
}

#[test]
fn demo_profinet_refuses_an_unwritable_plot_before_the_run() {
    let s = Scratch::new("pn-plot");
    let plot = s.unwritable("x.svg");
    let plot = plot.to_str().unwrap();
    let out = refused_naming(&["demo", "--fieldbus", "profinet", "--plot", plot], plot);
    assert!(!out.contains("plot:"), "no plot claimed: {out}");
    assert!(!out.contains("AR "), "refused before the run: {out}");
}

/// The self-tuning options are PROFINET's (the EtherCAT figures are the
/// selftune bench's); a factor out of range is refused before the run.
#[test]
fn demo_self_tune_options_are_profinet_only_and_checked() {
    let o = hil_sim(&["demo", "--self-tune"]);
    assert!(!o.status.success(), "{o:?}");
    assert!(text(&o.stderr).contains("PROFINET-only"), "{}", text(&o.stderr));
    let o = hil_sim(&["demo", "--fieldbus", "profinet", "--plant-j-factor", "0"]);
    assert!(!o.status.success(), "{o:?}");
    assert!(
        text(&o.stderr).contains("--plant-j-factor 0"),
        "{}",
        text(&o.stderr)
    );
    assert!(!text(&o.stdout).contains("AR "), "refused before the run");
}

/// P-219…P-227 through the binary: the FB's sequence prints its state
/// changes and a summary, writes the plot (with the ZSW1 state panel) and
/// records the PROFINET frames.
#[test]
fn p219_p227_demo_profinet_writes_the_plot_and_the_pcap_it_names() {
    let (out, svg, p, _) = demo_recorded("demo-pn", &["--fieldbus", "profinet"]);
    assert_lists(
        &out,
        &[
            "state SOI -> RTSO",
            "drive_is_enabled 0->1",
            "home_valid 0->1",
            "target_reached 0->1",
            "operation_mode_actual 0x10 -> 0x08",
            "jog_pos: moved",
            "PKW write 6065h.0: 20000",
            "state OP -> fault",
            "summary:",
            "following error max",
        ],
    );
    assert!(svg.contains("ZSW1 state"), "the state panel");
    assert!(p.len() > 1_000_000, "both directions every ms: {} bytes", p.len());
}

/// C-035 (csp follows 607Ah every cycle) on the electrical plant, through the fieldbus (ethercrab in
/// the process): the demo's profile, 10 revolutions in a cosine S-curve of
/// T = 1.5 s each way, reaches the peak speed v = π·d/(2T) = 10.5 rev/s
/// (11.0·10⁶ inc/s). A sampled position loop with velocity feedforward lags
/// the set-point by less than the travel of one 1 ms control cycle at that
/// speed (the set-point of a cycle acts through the current loop within
/// the next); the bound is v·1 ms ≈ 10,980 inc, from the profile and the
/// cycle, not from a run.
#[test]
fn c035_demo_csp_on_the_electrical_plant_lags_less_than_one_cycle_of_travel() {
    let s = Scratch::new("demo-electrical");
    let plot = s.0.join("run.svg");
    let out = stdout_of(&["demo", "--plant", "electrical", "--plot", plot.to_str().unwrap()]);
    let max: f64 = out
        .split("following error max ")
        .nth(1)
        .and_then(|r| r.split(" inc").next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no following error in:\n{out}"));
    let inc_per_rev = f64::from(1u32 << 20);
    let v_peak = std::f64::consts::PI * 10.0 * inc_per_rev / (2.0 * 1.5);
    let bound = v_peak * 1.0e-3;
    assert!(
        max > 0.0 && max < bound,
        "following error max {max} inc, bound {bound:.0} inc"
    );
    assert!(out.contains("current loop"), "the electrical plant ran:\n{out}");
}
