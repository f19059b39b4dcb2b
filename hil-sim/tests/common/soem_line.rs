//! Two private network namespaces joined by a veth pair, `hil-sim serve` in
//! one and SOEM's scripts (`hil-sim/tests/soem/*.py`, through pysoem) in the
//! other: the line `tests/soem.rs` and `benches/soak.rs` drive. Everything
//! is removed on drop. Needs root and a python with pysoem
//! ([`pysoem_python`]).

use super::{ip, netns_add, netns_del, stop_server, watch_script};
use hil_sim::matrix::Row;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Mutex, MutexGuard};
use std::time::Duration;

/// One SOEM run at a time in a test binary: each needs the cores for its
/// 1 ms cycle.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// The peer of the SOEM rows of the fault matrix (`scripts/fault-matrix`
/// lets them be missing when no SOEM test ran, and checks them when one did).
pub const SOEM_PEER: &str = "SOEM (pysoem) over veth";

/// A row of the fault matrix run by SOEM.
pub fn soem_row<'a>(order: &'a str, case: &'a str, spec: &'a str, expected: &'a str) -> Row<'a> {
    Row {
        order,
        case,
        spec,
        peer: SOEM_PEER,
        expected,
    }
}

/// The python with pysoem ([`pysoem_python`]) and the test's turn (one SOEM
/// run at a time), or `None` after saying why the test `what` does not run.
pub fn pysoem_turn(what: &str) -> Option<(PathBuf, MutexGuard<'static, ()>)> {
    let python = super::or_skip(pysoem_python(), what)?;
    Some((python, ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())))
}

/// A script that has not finished after this long has hung ([`Line::run`]).
pub const SCRIPT_LIMIT: Duration = Duration::from_secs(240);

/// The python with pysoem ([`super::peer_python`], `PYSOEM_PYTHON`), or why
/// the test cannot run (not root, or `PYSOEM_PYTHON` not set). A
/// `PYSOEM_PYTHON` that cannot import pysoem is a failure, not a skip:
/// whoever set it wants the test to run.
pub fn pysoem_python() -> Result<PathBuf, String> {
    super::peer_python(
        "PYSOEM_PYTHON",
        "pysoem",
        "import pysoem; print(pysoem.__version__)",
        "pysoem-venv",
    )
}

/// SCHED_FIFO priority of `serve`: the simulated drives stand for hardware
/// (an ESC and an MCU of their own), so `serve` gets the CPU before the
/// compile jobs of a shared machine do (a descheduled `serve` still sees
/// each frame at its kernel receive time, but answers it late). The master
/// runs at SCHED_FIFO 40 as SOEM's samples do (the script sets it).
pub const SERVE_PRIORITY: &str = "50";

/// Two private namespaces joined by a veth pair, `hil-sim serve` in one.
pub struct Line {
    master_ns: String,
    sim_ns: String,
    master_if: String,
    server: Option<Child>,
    /// serve's output (state changes of every drive, with AL codes; its summary).
    pub serve_log: PathBuf,
}

impl Line {
    /// The line named after `tag` and this process' id, `serve --slaves
    /// slaves --seconds seconds` started in it with its output in `dir`.
    pub fn new(tag: &str, slaves: usize, seconds: u32, dir: &Path) -> Self {
        Self::with_serve_args(tag, slaves, seconds, dir, &[])
    }

    /// [`Line::new`] with more arguments for `serve` (e.g. `--cpu N`).
    pub fn with_serve_args(tag: &str, slaves: usize, seconds: u32, dir: &Path, more: &[&str]) -> Self {
        let id = std::process::id() % 100_000;
        let master_ns = format!("soem{tag}{id}m");
        let sim_ns = format!("soem{tag}{id}s");
        let master_if = format!("so{tag}{id}m");
        let sim_if = format!("so{tag}{id}s");
        netns_del(&[&master_ns, &sim_ns]);
        netns_add(&[&master_ns, &sim_ns]);
        ip(&[
            "link", "add", &master_if, "netns", &master_ns, "type", "veth", "peer", "name", &sim_if, "netns",
            &sim_ns,
        ]);
        ip(&["-n", &master_ns, "link", "set", &master_if, "up"]);
        ip(&["-n", &sim_ns, "link", "set", &sim_if, "up"]);
        let serve_log = dir.join(format!("serve-{tag}.log"));
        // SOEM_PCAP=1: serve records every frame (for a failure's evidence)
        let pcap = std::env::var_os("SOEM_PCAP").map(|_| dir.join(format!("serve-{tag}.pcap")));
        let log = std::fs::File::create(&serve_log).expect("serve log");
        let server = Command::new("ip")
            .args(["netns", "exec", &sim_ns, env!("CARGO_BIN_EXE_hil-sim"), "serve"])
            .args(["--fifo-priority", SERVE_PRIORITY])
            .args(["--iface", &sim_if, "--slaves", &slaves.to_string()])
            .args(["--seconds", &seconds.to_string()])
            .args(more)
            .args(
                pcap.iter()
                    .flat_map(|p| [std::ffi::OsStr::new("--pcap"), p.as_os_str()]),
            )
            .stdout(log.try_clone().expect("log"))
            .stderr(log)
            .spawn()
            .expect("spawn hil-sim serve");
        // serve opens its socket at once; the script's scan retries as well
        std::thread::sleep(Duration::from_millis(300));
        Self {
            master_ns,
            sim_ns,
            master_if,
            server: Some(server),
            serve_log,
        }
    }

    /// Starts `python -u script --iface <the master's end> args` in the
    /// master's namespace (`script` in `hil-sim/tests/soem/`), its stdout
    /// and stderr piped.
    pub fn spawn(&self, python: &Path, script: &str, args: &[&str]) -> (Child, PathBuf) {
        let script = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/soem")
            .join(script);
        let child = Command::new("ip")
            .args(["netns", "exec", &self.master_ns])
            .arg(python)
            .arg("-u")
            .arg(&script)
            .args(["--iface", &self.master_if])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run the script");
        (child, script)
    }

    /// Runs `python script args` in the master's namespace; its output is
    /// printed as it comes, the exit status returned (killed after
    /// [`SCRIPT_LIMIT`]).
    pub fn run(&self, python: &Path, script: &str, args: &[&str]) -> ExitStatus {
        self.run_lines(python, script, args).0
    }

    /// [`run`](Self::run), with the lines the script printed.
    pub fn run_lines(&self, python: &Path, script: &str, args: &[&str]) -> (ExitStatus, Vec<String>) {
        let (child, script) = self.spawn(python, script, args);
        // print line by line (println! goes through the test harness's capture)
        watch_script(child, &script, SCRIPT_LIMIT)
    }

    /// The process id of `serve` (`ip netns exec` execs it), while it runs.
    pub fn serve_pid(&self) -> Option<u32> {
        self.server.as_ref().map(Child::id)
    }

    /// Stops `serve` (SIGTERM: it prints its summary), waits up to 5 s.
    pub fn stop_server(&mut self) {
        if let Some(s) = self.server.take() {
            stop_server(s, Duration::from_secs(5));
        }
    }

    /// [`run`](Self::run)s `script` with `args`; its failure ends the test
    /// ([`fail_with`](Self::fail_with) "`script` through SOEM failed").
    pub fn run_passes(&self, python: &Path, script: &str, args: &[&str]) {
        let status = self.run(python, script, args);
        if !status.success() {
            self.fail_with(&format!("{script} through SOEM failed: {status}"));
        }
    }

    /// What `serve` printed (state changes of every drive, with AL codes).
    /// Ends a test with `what` and the last 60 lines serve printed.
    pub fn fail_with(&self, what: &str) -> ! {
        let serve = self.serve_output();
        let tail: Vec<&str> = serve.lines().rev().take(60).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        panic!(
            "{what}\n--- hil-sim serve ({}), last lines:\n{}\n(SOEM_PCAP=1 records serve's frames next to its log)",
            self.serve_log.display(),
            tail.join("\n")
        );
    }

    pub fn serve_output(&self) -> String {
        std::fs::read_to_string(&self.serve_log).unwrap_or_default()
    }
}

impl Drop for Line {
    fn drop(&mut self) {
        if let Some(s) = self.server.take() {
            stop_server(s, Duration::from_secs(2));
        }
        // deleting the namespaces deletes the veth pair
        for ns in [&self.master_ns, &self.sim_ns] {
            let _ = Command::new("ip").args(["netns", "del", ns]).status();
        }
    }
}
