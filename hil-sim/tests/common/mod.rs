//! A private network namespace with one end of a veth pair and `hil-sim
//! serve` running inside it; the other end stays in this namespace for the
//! master. Everything is removed on drop. Needs root ([`is_root`]).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, dead_code)]

use std::process::{Child, Command, Stdio};
use std::time::Duration;

pub mod kickcat;
pub mod pn_line;
pub mod scope_check;
pub mod soem_line;

/// `fb_rig!(Rig)`: `struct Rig(FbRig)`, the FB rig
/// ([`hil_sim::fb::rig::FbRig`]) with a test's own steps, dereferencing to it.
#[allow(unused_macros)] // used by some of the tests that include this module
macro_rules! fb_rig {
    ($name:ident) => {
        /// The FB rig ([`FbRig`](hil_sim::fb::rig::FbRig)) with this test's steps.
        struct $name(hil_sim::fb::rig::FbRig);

        impl std::ops::Deref for $name {
            type Target = hil_sim::fb::rig::FbRig;
            fn deref(&self) -> &hil_sim::fb::rig::FbRig {
                &self.0
            }
        }

        impl std::ops::DerefMut for $name {
            fn deref_mut(&mut self) -> &mut hil_sim::fb::rig::FbRig {
                &mut self.0
            }
        }
    };
}
#[allow(unused_imports)]
pub(crate) use fb_rig;

/// This process runs as root (network namespaces and raw sockets work).
pub fn is_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    #[allow(unsafe_code)]
    unsafe {
        libc::geteuid() == 0
    }
}

/// The namespace, the veth pair and the server.
pub struct Netns {
    ns: String,
    /// The master's end of the veth pair (in this namespace).
    pub host_if: String,
    server: Option<Child>,
}

/// Runs `ip args`, failing the test when it fails.
pub fn ip(args: &[&str]) {
    let st = Command::new("ip").args(args).status().expect("run ip");
    assert!(st.success(), "ip {args:?} failed");
}

/// Deletes the network namespaces `names` where they exist (left by an
/// earlier run, or at the end), quietly.
pub fn netns_del<S: AsRef<str>>(names: &[S]) {
    for ns in names {
        let _ = Command::new("ip")
            .args(["netns", "del", ns.as_ref()])
            .stderr(Stdio::null())
            .status();
    }
}

/// Adds the network namespaces `names`, each with its loopback up.
pub fn netns_add<S: AsRef<str>>(names: &[S]) {
    for ns in names {
        ip(&["netns", "add", ns.as_ref()]);
        ip(&["-n", ns.as_ref(), "link", "set", "lo", "up"]);
    }
}

/// Stops a `serve` child: SIGTERM first (it flushes its recording and
/// prints its summary; `ip netns exec` execs serve, so the child's pid is
/// serve's), then SIGKILL if it is still there after `grace`.
pub fn stop_server(mut s: Child, grace: Duration) {
    if let Ok(pid) = i32::try_from(s.id()) {
        // SAFETY: kill has no memory preconditions; pid is our child.
        #[allow(unsafe_code)]
        unsafe {
            libc::kill(pid, libc::SIGTERM);
        }
    }
    let end = std::time::Instant::now() + grace;
    while std::time::Instant::now() < end {
        if let Ok(Some(_)) = s.try_wait() {
            return;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = s.kill();
    let _ = s.wait();
}

impl Netns {
    /// Builds the namespace (names from this process' id and `tag`, one
    /// letter) and starts `serve --iface <its end> <serve_args>` of `bin`.
    pub fn new(bin: &str, tag: char, serve_args: &[&str]) -> Self {
        let id = std::process::id() % 100_000;
        let ns = format!("hilsim{id}{tag}");
        let host_if = format!("hs{id}{tag}a");
        let sim_if = format!("hs{id}{tag}b");
        let _ = Command::new("ip")
            .args(["netns", "del", &ns])
            .stderr(Stdio::null())
            .status();
        ip(&["netns", "add", &ns]);
        ip(&["link", "add", &host_if, "type", "veth", "peer", "name", &sim_if]);
        ip(&["link", "set", &sim_if, "netns", &ns]);
        ip(&["link", "set", &host_if, "up"]);
        ip(&["-n", &ns, "link", "set", &sim_if, "up"]);
        let server = Command::new("ip")
            .args(["netns", "exec", &ns, bin, "serve", "--iface", &sim_if])
            .args(serve_args)
            .stdout(Stdio::inherit())
            .spawn()
            .expect("spawn hil-sim serve");
        std::thread::sleep(Duration::from_millis(300));
        Self {
            ns,
            host_if,
            server: Some(server),
        }
    }
}

impl Netns {
    /// Asks the server to stop (SIGTERM: it flushes its recording and prints
    /// its summary), waits up to 5 s for it, then kills it.
    pub fn stop_server(&mut self) {
        if let Some(s) = self.server.take() {
            stop_server(s, Duration::from_secs(5));
        }
    }
}

impl Drop for Netns {
    fn drop(&mut self) {
        self.stop_server();
        let _ = Command::new("ip")
            .args(["link", "del", &self.host_if])
            .stderr(Stdio::null())
            .status();
        let _ = Command::new("ip").args(["netns", "del", &self.ns]).status();
    }
}

/// Follows a test peer's script `child` (spawned with piped stdout and
/// stderr) to its end: prints its lines as they come (stderr prefixed),
/// kills it after `limit`; returns its exit status and its stdout lines.
pub fn watch_script(
    mut child: Child,
    script: &std::path::Path,
    limit: Duration,
) -> (std::process::ExitStatus, Vec<String>) {
    use std::io::BufRead;
    let out = child.stdout.take().expect("stdout");
    let err = child.stderr.take().expect("stderr");
    let t_out = std::thread::spawn(move || {
        let mut lines = Vec::new();
        for line in std::io::BufReader::new(out).lines().map_while(Result::ok) {
            println!("{line}");
            lines.push(line);
        }
        lines
    });
    let t_err = std::thread::spawn(move || {
        for line in std::io::BufReader::new(err).lines().map_while(Result::ok) {
            println!("stderr: {line}");
        }
    });
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().expect("wait") {
            break st;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let st = child.wait().expect("wait");
            println!("{} hung: killed after {limit:?}", script.display());
            break st;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let lines = t_out.join().unwrap_or_default();
    let _ = t_err.join();
    (status, lines)
}

/// A scratch directory for one test's files (under cargo's target tmp).
pub fn scratch(test: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(test);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// The peer's python, or `None` after saying on stderr that `test` is
/// skipped and why (the test then passes without running).
pub fn or_skip(python: Result<std::path::PathBuf, String>, test: &str) -> Option<std::path::PathBuf> {
    python.map_err(|why| eprintln!("{test}: skipped, {why}")).ok()
}

/// The python a peer written by others runs in, from the variable `var`
/// (`.ci/run` installs the peer into target/`venv` and sets `var` to
/// target/`venv`/bin/python), or why the test cannot run (not root, `var`
/// unset). `check` is python code that imports the peer and prints its
/// version (or nothing); a python it fails in fails the test. Prints
/// "`peer` version (python)".
pub fn peer_python(var: &str, peer: &str, check: &str, venv: &str) -> Result<std::path::PathBuf, String> {
    if !is_root() {
        return Err("needs root for network namespaces and raw sockets".into());
    }
    let py = std::env::var_os(var).ok_or(format!(
        "{var} is not set (`.ci/run` installs {peer} into target/{venv} and sets it to \
         target/{venv}/bin/python)"
    ))?;
    let show = std::path::Path::new(&py).display().to_string();
    let out = Command::new(&py)
        .args(["-c", check])
        .output()
        .unwrap_or_else(|e| panic!("{var}={show}: {e}"));
    assert!(
        out.status.success(),
        "{var}={show} cannot import {peer}: {}",
        String::from_utf8_lossy(&out.stderr).trim()
    );
    match String::from_utf8_lossy(&out.stdout).trim() {
        "" => println!("{peer} ({show})"),
        version => println!("{peer} {version} ({show})"),
    }
    Ok(std::path::PathBuf::from(py))
}

/// The python with profinet-py ([`peer_python`], `PROFINET_PY_PYTHON`).
pub fn profinet_py_python() -> Result<std::path::PathBuf, String> {
    peer_python(
        "PROFINET_PY_PYTHON",
        "profinet-py",
        "import profinet; print(profinet.__version__)",
        "profinet-venv",
    )
}
