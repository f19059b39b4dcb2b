//! Two private network namespaces joined by a veth pair, with `hil-sim
//! serve --fieldbus profinet --control FIFO` in the device's one and the
//! controller's end (192.168.0.10/24) in the other: the line the
//! profinet-py tests drive. Everything is removed on drop (also when the
//! test fails). Needs root.

use super::{ip, netns_add, netns_del, stop_server, watch_script};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// The arguments that tell a controller script the device: `--gsdml` (the
/// generated GSDML file), `--out-module` and `--in-module` (the manual's
/// example: slot 1 "18 Word Output Data", slot 2 "18 Word Input Data"),
/// then `more`.
pub fn module_args(more: &[impl AsRef<OsStr>]) -> Vec<std::ffi::OsString> {
    use profinet::model::{DataModule, Direction};
    let gsdml = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../gsdml")
        .join(gsdml::file_name());
    let module = |direction, words| gsdml::module_id(DataModule { direction, words });
    let mut args: Vec<std::ffi::OsString> = vec![
        "--gsdml".into(),
        gsdml.into_os_string(),
        "--out-module".into(),
        module(Direction::FromDrive, 18).into(),
        "--in-module".into(),
        module(Direction::ToDrive, 18).into(),
    ];
    args.extend(more.iter().map(|a| a.as_ref().to_os_string()));
    args
}

/// The controller's address (in its own namespace only).
pub const CONTROLLER_IP: &str = "192.168.0.10/24";

/// The line.
pub struct PnLine {
    /// The controller's namespace.
    pub ctl_ns: String,
    dev_ns: String,
    /// The controller's end of the veth pair.
    pub ctl_if: String,
    /// The device's interface MAC (serve's first drive has it).
    pub device_mac: String,
    server: Option<Child>,
    /// serve's output.
    pub serve_log: PathBuf,
    /// serve's control FIFO (`--control`).
    pub control: PathBuf,
}

impl PnLine {
    /// The line named after `prefix` (namespaces `{prefix}ctl<pid>` /
    /// `{prefix}dev<pid>`), serve started with `serve_args` besides the
    /// interface and the control FIFO; files in `dir`.
    pub fn new(prefix: &str, dir: &Path, serve_args: &[&OsStr]) -> PnLine {
        let id = std::process::id() % 100_000;
        let ctl_ns = format!("{prefix}ctl{id}");
        let dev_ns = format!("{prefix}dev{id}");
        let dev_if = format!("{prefix}{id}d");
        netns_del(&[&ctl_ns, &dev_ns]);
        // from here on Drop cleans up whatever was made
        let mut line = PnLine {
            ctl_ns,
            dev_ns,
            ctl_if: format!("{prefix}{id}c"),
            device_mac: String::new(),
            server: None,
            serve_log: dir.join(format!("serve-{prefix}.log")),
            control: dir.join(format!("control-{prefix}")),
        };
        let (c, d) = (line.ctl_ns.clone(), line.dev_ns.clone());
        netns_add(&[&c, &d]);
        ip(&[
            "link",
            "add",
            &line.ctl_if,
            "netns",
            &c,
            "type",
            "veth",
            "peer",
            "name",
            &dev_if,
            "netns",
            &d,
        ]);
        // no IPv6 chatter from either kernel in the recordings
        for (ns, ifc) in [(&c, &line.ctl_if), (&d, &dev_if)] {
            let _ = Command::new("ip")
                .args(["netns", "exec", ns, "sysctl", "-qw"])
                .arg(format!("net.ipv6.conf.{ifc}.disable_ipv6=1"))
                .status();
        }
        ip(&["-n", &c, "link", "set", &line.ctl_if, "up"]);
        ip(&["-n", &d, "link", "set", &dev_if, "up"]);
        ip(&["-n", &c, "addr", "add", CONTROLLER_IP, "dev", &line.ctl_if]);
        let mac = Command::new("ip")
            .args(["netns", "exec", &d, "cat"])
            .arg(format!("/sys/class/net/{dev_if}/address"))
            .output()
            .expect("read the device's MAC");
        assert!(mac.status.success(), "no MAC for {dev_if}");
        line.device_mac = String::from_utf8_lossy(&mac.stdout).trim().to_string();
        let log = std::fs::File::create(&line.serve_log).expect("serve log");
        line.server = Some(
            Command::new("ip")
                .args(["netns", "exec", &d, env!("CARGO_BIN_EXE_hil-sim"), "serve"])
                .args(["--fieldbus", "profinet", "--iface", &dev_if])
                .args(serve_args)
                .arg("--control")
                .arg(&line.control)
                .stdout(log.try_clone().expect("log"))
                .stderr(log)
                .spawn()
                .expect("spawn hil-sim serve"),
        );
        // serve prints its first line once its socket is open
        let until = Instant::now() + Duration::from_secs(10);
        while !line.serve_output().contains("hil-sim serve:") {
            assert!(
                Instant::now() < until,
                "serve did not start:\n{}",
                line.serve_output()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        line
    }

    /// Runs `script` with `python` in the controller's namespace with
    /// `--iface`, `--device-mac` and `args`; its lines are printed as they
    /// come and returned with the exit status (a time limit of `limit`).
    pub fn run(
        &self,
        python: &Path,
        script: &Path,
        args: &[impl AsRef<OsStr>],
        limit: Duration,
    ) -> (ExitStatus, Vec<String>) {
        let child = Command::new("ip")
            .args(["netns", "exec", &self.ctl_ns])
            .arg(python)
            .arg("-u")
            .arg(script)
            .args(["--iface", &self.ctl_if, "--device-mac", &self.device_mac])
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run the script");
        watch_script(child, script, limit)
    }

    /// Stops serve (SIGTERM: it flushes its recording and prints its
    /// summary).
    pub fn stop_server(&mut self) {
        if let Some(s) = self.server.take() {
            stop_server(s, Duration::from_secs(5));
        }
    }

    /// What serve printed so far.
    pub fn serve_output(&self) -> String {
        std::fs::read_to_string(&self.serve_log).unwrap_or_default()
    }
}

impl Drop for PnLine {
    fn drop(&mut self) {
        self.stop_server();
        // deleting the namespaces deletes the veth pair and the address
        netns_del(&[&self.ctl_ns, &self.dev_ns]);
    }
}
