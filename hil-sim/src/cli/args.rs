//! The command line: `hil-sim [demo|serve|scope-plot] [OPTIONS]` (clap, derive). Every
//! subcommand has `--help`; unknown arguments are refused with exit code 2.

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::fs::File;
use std::path::{Path, PathBuf};

/// The simulated servo drive on a PC: a simulated ESC and motor running the
/// drive's firmware crates behind a real EtherCAT master.
#[derive(Debug, Parser)]
#[command(name = "hil-sim", version, propagate_version = true)]
pub struct Cli {
    /// What to run (default: `demo`).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// A real EtherCAT master (ethercrab, in-process, simulated time) drives
    /// one simulated drive: INIT -> OP, enable axis A in csp, home it, run a
    /// 10-revolution profile, write a plot of the run. With `--fieldbus
    /// profinet` a scripted IO controller with a model of the Example
    /// Function block runs its sequence instead: enable, home, positioning
    /// chain, speed, jog, PKW, fault and acknowledge.
    Demo(DemoArgs),
    /// The simulated line answers EtherCAT frames on a network interface (raw
    /// Ethernet, needs root or CAP_NET_RAW), so any master can drive it;
    /// with `--fieldbus profinet` a simulated PROFINET IO device answers
    /// instead, for any IO controller.
    Serve(ServeArgs),
    /// Plots a trace the drive's scope recorded (group T), as
    /// `hil-sim/tests/soem/scope.py` read it back through SOEM and wrote it
    /// as CSV: one panel per channel, SVG and (with `rsvg-convert` or
    /// ImageMagick's `convert`) PNG.
    ScopePlot(ScopePlotArgs),
}

/// Options of `scope-plot`.
#[derive(Debug, Clone, Args)]
pub struct ScopePlotArgs {
    /// The trace (CSV: time relative to the trigger in ms, then one column per channel).
    #[arg(value_name = "TRACE.csv")]
    pub csv: PathBuf,
    /// Where the SVG goes (default: beside the CSV, `.svg`).
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Where the PNG goes (default: beside the CSV, `.png`; skipped with a
    /// note when neither `rsvg-convert` nor `convert` runs).
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// The plot's title.
    #[arg(long, default_value = "Scope trace")]
    pub title: String,
}

/// Options of `demo`.
#[derive(Debug, Clone, Default, Args)]
pub struct DemoArgs {
    /// The fieldbus: EtherCAT (ethercrab, CiA 402 in csp) or PROFINET (a
    /// scripted IO controller in the process, the Example Function block's
    /// telegrams, 1 ms IO cycle).
    #[arg(long, value_enum, value_name = "BUS", default_value_t = Fieldbus::Ethercat)]
    pub fieldbus: Fieldbus,
    /// Record every frame (both directions) to this pcap file for Wireshark.
    #[arg(long, value_name = "FILE")]
    pub pcap: Option<PathBuf>,
    /// Write the plot of set and actual position, velocity, torque and
    /// following error here (PROFINET: also the ZSW1 state, phases marked)
    /// [default: target/hil-sim-demo.svg, PROFINET: target/hil-sim-demo-pn.svg].
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// The motor model. `electrical` (the default): the current loop at
    /// 16 kHz on a PMSM behind an inverter (on EtherCAT the summary adds
    /// current-loop figures, the plot id/iq and the phase currents);
    /// `rigid`: the same mechanics with the commanded torque acting one
    /// control cycle later (torque in, cheap) [default: electrical].
    #[arg(long, value_enum, value_name = "MODEL")]
    pub plant: Option<Plant>,
    /// PROFINET only: self-tune before the positioning moves, as a PLC
    /// would: B44 identify mechanics started through the telegram's PKW
    /// channel (A75 = 1Fh in ready to switch on, then drive_enable), A69
    /// polled until done, B45/B46/B47 read; the moves then run on the gains
    /// and feedforward B44 set.
    #[arg(long)]
    pub self_tune: bool,
    /// PROFINET only: the plant's inertia times this, a load the drive does
    /// not know [default: 1, the simulated servo its defaults are set for].
    #[arg(long, value_name = "FACTOR")]
    pub plant_j_factor: Option<f64>,
    /// PROFINET only: the plant's friction (Coulomb, breakaway, viscous)
    /// times this [default: 1].
    #[arg(long, value_name = "FACTOR")]
    pub plant_friction_factor: Option<f64>,
}

impl DemoArgs {
    /// The motor model the demo runs: `--plant`, else the electrical plant
    /// (both fieldbuses).
    pub fn plant(&self) -> Plant {
        self.plant.unwrap_or(Plant::Electrical)
    }

    /// The plant's inertia and friction factors (PROFINET), each finite
    /// and within 0.1 … 100.
    pub fn mechanics(&self) -> Result<(f64, f64), String> {
        let f = |v: Option<f64>, name: &str| match v {
            None => Ok(1.0),
            Some(x) if x.is_finite() && (0.1..=100.0).contains(&x) => Ok(x),
            Some(x) => Err(format!("--{name} {x}: a factor within 0.1 … 100")),
        };
        Ok((
            f(self.plant_j_factor, "plant-j-factor")?,
            f(self.plant_friction_factor, "plant-friction-factor")?,
        ))
    }

    /// Whether a PROFINET-only option is given.
    pub fn profinet_only(&self) -> bool {
        self.self_tune || self.plant_j_factor.is_some() || self.plant_friction_factor.is_some()
    }
}

/// A fault of the electrical plant (`serve --plant-fault`): of the power
/// stage, the DC link and the encoder (the protection trips), or of the
/// motor, its wiring and its brake (what the motor actions A75 find).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PlantFault {
    /// Leg a shorted to DC− through 1 Ω.
    Short,
    /// Leg a to DC− through 100 Ω (an earth fault).
    Earth,
    /// Leg b's current sensor reads zero.
    BrokenSensor,
    /// DC link 300 V (below 400 V).
    DcLow,
    /// DC link 850 V (above 800 V).
    DcHigh,
    /// The encoder lost.
    Encoder,
    /// Motor phases V and W wired to legs c and b (wrong phase order: B40
    /// fails with 7).
    SwappedPhases,
    /// Motor phase W's wire open (B40 and B43 fail with 2, no current).
    OpenPhase,
    /// Phase V's resistance 10 % high (an unbalanced winding: B43 fails
    /// with 6).
    UnbalancedWinding,
    /// The encoder counts the other way (B40 fails with 7).
    ReversedEncoder,
    /// The holding brake worn to 1.0 N·m, below the rated torque 1.3 N·m
    /// (B300 fails with 9).
    SlippingBrake,
    /// The holding brake stays closed whatever is commanded (B301 fails
    /// with 11).
    StuckBrake,
}

impl PlantFault {
    /// The holding torque of [`Self::SlippingBrake`], N·m: below the
    /// simulated servo's rated torque (1.3 N·m, B300's test torque).
    pub const WORN_BRAKE_NM: f64 = 1.0;

    /// Whether the fault is the holding brake's (the motor's mechanics, not
    /// the electrical plant).
    pub fn is_brake(self) -> bool {
        matches!(self, Self::SlippingBrake | Self::StuckBrake)
    }

    /// Applies the fault to an electrical axis' plant (the brake's: nothing,
    /// see [`Self::apply_to_motor`]).
    pub fn apply(self, el: &mut hil_sim::electrical::ElectricalAxis) {
        use plant::{FaultOptions, Phase};
        let f = FaultOptions::NONE;
        let pl = el.plant_mut();
        match self {
            Self::Short => pl.set_faults(FaultOptions {
                leg_to_dc_minus: Some((Phase::A, 1.0)),
                ..f
            }),
            Self::Earth => pl.set_faults(FaultOptions {
                leg_to_dc_minus: Some((Phase::A, 100.0)),
                ..f
            }),
            Self::BrokenSensor => pl.set_faults(FaultOptions {
                broken_sensor: Some(Phase::B),
                ..f
            }),
            Self::DcLow => pl.set_dc_link(300.0),
            Self::DcHigh => pl.set_dc_link(850.0),
            Self::Encoder => pl.set_faults(FaultOptions {
                encoder_lost: true,
                ..f
            }),
            Self::SwappedPhases => pl.set_faults(FaultOptions {
                swapped_bc: true,
                ..f
            }),
            Self::OpenPhase => pl.set_faults(FaultOptions {
                open_phase: Some(Phase::C),
                ..f
            }),
            Self::UnbalancedWinding => pl.set_faults(FaultOptions {
                r_scale: [1.0, 1.1, 1.0],
                ..f
            }),
            Self::ReversedEncoder => pl.set_faults(FaultOptions {
                encoder_reversed: true,
                ..f
            }),
            Self::SlippingBrake | Self::StuckBrake => {}
        }
    }

    /// Applies a fault of the holding brake to the motor's mechanics (the
    /// others: nothing, see [`Self::apply`]).
    pub fn apply_to_motor(self, m: &mut hil_sim::motor::MotorParams) {
        match self {
            Self::SlippingBrake => m.brake_holding_torque_nm = Self::WORN_BRAKE_NM,
            Self::StuckBrake => m.brake_stuck = true,
            _ => {}
        }
    }
}

/// The PWM rate of `serve --pwm-khz`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ValueEnum)]
pub enum PwmKhz {
    /// 16 kHz (the default).
    #[default]
    #[value(name = "16")]
    Sixteen,
    /// 8 kHz.
    #[value(name = "8")]
    Eight,
}

impl PwmKhz {
    /// The rate, Hz.
    pub fn hz(self) -> f32 {
        match self {
            Self::Sixteen => 16_000.0,
            Self::Eight => 8_000.0,
        }
    }
}

/// The motor model of `demo --plant` and `serve --plant`
/// (`hil_sim::electrical::PlantModel`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ValueEnum)]
pub enum Plant {
    /// The rigid rotor, torque in (where a test needs its speed).
    Rigid,
    /// The current loop on the PMSM plant (the default).
    #[default]
    Electrical,
}

impl From<Plant> for hil_sim::electrical::PlantModel {
    fn from(p: Plant) -> Self {
        match p {
            Plant::Rigid => Self::Rigid,
            Plant::Electrical => Self::Electrical,
        }
    }
}

/// The fieldbus `serve` and `demo` speak.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ValueEnum)]
pub enum Fieldbus {
    /// A line of simulated EtherCAT drives (simulated ESCs).
    #[default]
    Ethercat,
    /// One simulated drive as a PROFINET IO device (DCP, RPC, LLDP, RT_CLASS_1).
    Profinet,
}

/// Options of `serve`.
#[derive(Debug, Clone, Args)]
pub struct ServeArgs {
    /// Network interface to answer on (e.g. one end of a veth pair).
    #[arg(long, value_name = "IF")]
    pub iface: String,
    /// The fieldbus: a line of EtherCAT drives, or one PROFINET IO device
    /// (its interface MAC is the interface's own).
    #[arg(long, value_enum, value_name = "BUS", default_value_t = Fieldbus::Ethercat)]
    pub fieldbus: Fieldbus,
    /// PROFINET only: the stored name of station (default: none, as shipped;
    /// a controller names the device by DCP).
    #[arg(long, value_name = "NAME")]
    pub name: Option<String>,
    /// PROFINET only: the simulator's control channel, a FIFO created at
    /// this path (removed at the end) that takes one command per line:
    /// `fault A|B EVENT CAUSE` raises a drive event on an axis (as the power
    /// stage would), `reset A|B` acknowledges its fault (controlword bit 7,
    /// until the profile maps CW1), `status` prints the axes' state.
    #[arg(long, value_name = "PATH")]
    pub control: Option<PathBuf>,
    /// Drives on the simulated line (EtherCAT; PROFINET: IO devices), 1 to
    /// 128.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..=i64::from(MAX_SLAVES)))]
    pub slaves: u16,
    /// Axes per drive (EtherCAT only): 2 = the double-axis device (SC6A062,
    /// axis B's objects at +800h/+8000h), 1 = the single-axis device
    /// (SI6A061: its own identity, no axis-B objects or PDOs) [default: 2].
    #[arg(long, value_name = "1|2", value_parser = clap::value_parser!(u8).range(1..=2))]
    pub axes: Option<u8>,
    /// Record every frame (both directions, simulated time; PROFINET: time
    /// since the start) to this pcap file.
    #[arg(long, value_name = "FILE")]
    pub pcap: Option<PathBuf>,
    /// The motor model of every axis, both fieldbuses (`electrical`, the
    /// default: the current loop at 16 kHz on the PMSM plant, 6077h/6078h
    /// (PNU 1102) from the measured iq, about 36 ms of host time per moving
    /// axis and simulated second; `rigid`: torque in, cheap enough for 128
    /// moving drives).
    #[arg(long, value_enum, value_name = "MODEL", default_value_t = Plant::Electrical)]
    pub plant: Plant,
    /// With `--plant electrical`: the PWM and current-loop rate, 16 or 8
    /// kHz (issue 34; at 8 kHz the loop's delay doubles: B64 = 500 Hz keeps
    /// the 16 kHz step's overshoot).
    #[arg(long, value_enum, value_name = "KHZ", default_value_t = PwmKhz::Sixteen)]
    pub pwm_khz: PwmKhz,
    /// `--plant electrical` only: a fault of axis A's plant on
    /// every drive, from the start (the power stage shows it when its gates
    /// go on, or at once): `short` leg a shorted to the DC link's negative
    /// rail through 1 Ω (the over-current trip, event 33), `earth` the same
    /// through 100 Ω (the phase-sum trip, event 31), `broken-sensor` leg b's
    /// current sensor reads zero (phase sum), `dc-low` / `dc-high` a DC link
    /// of 300 V / 850 V (events 46 / 36), `encoder` the encoder lost (37);
    /// the others are faults of the motor, its wiring and its holding brake
    /// that the motor actions (A75, issue 35) find, each below with the
    /// action that fails and its result code (in B40, B43, B300, B301 sub 1).
    /// The brake's are not with `--flywheel` (it has no brake).
    #[arg(long, value_enum, value_name = "FAULT")]
    pub plant_fault: Option<PlantFault>,
    /// With `--plant electrical`: the plant motor's phase resistance, Ω, on
    /// every axis (default: the simulated servo's 3.6 Ω). The drive's motor
    /// data keep their own values (a motor it does not know: B42 measures it).
    #[arg(long, value_name = "OHM")]
    pub plant_r: Option<f64>,
    /// With `--plant electrical`: the plant motor's inductance Ld = Lq, H
    /// (default: 12 mH).
    #[arg(long, value_name = "H")]
    pub plant_l: Option<f64>,
    /// With `--plant electrical`: the mechanical angle (rad) at which the
    /// plant motor's d axis points along phase a, its commutation offset
    /// (default 0; the drive's B05 says 0 until B41 finds it).
    #[arg(long, value_name = "RAD")]
    pub plant_offset: Option<f64>,
    /// EtherCAT only: axis A of every drive drives a flywheel of this
    /// inertia, kg·m², frictionless and without a holding brake (a load the
    /// drive does not know: its motor data stay the servo's), e.g. to brake
    /// it into the DC link (issue 34, the brake chopper).
    #[arg(long, value_name = "KG_M2")]
    pub flywheel: Option<f64>,
    /// Stop after this many seconds (default: run until killed).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Do not try SCHED_FIFO (nor `--cpu`).
    #[arg(long)]
    pub no_rt: bool,
    /// Pin to this CPU (default: not pinned; on a shared machine another
    /// real-time process may hold any given CPU).
    #[arg(long, value_name = "N", conflicts_with = "no_rt")]
    pub cpu: Option<usize>,
    /// SCHED_FIFO priority to ask for.
    #[arg(long, value_name = "1..99", default_value_t = 20, value_parser = clap::value_parser!(i32).range(1..=99))]
    pub fifo_priority: i32,
    /// Spin on the socket instead of sleeping between frames (lowest
    /// latency; takes a whole CPU; runs without SCHED_FIFO, which the kernel
    /// would throttle).
    #[arg(long)]
    pub busy_poll: bool,
    /// Test only: hold each frame a seeded random 0..=MAX µs after its
    /// arrival before processing it (a loaded machine's scheduling delay).
    #[arg(long, value_name = "MAX", hide = true)]
    pub delay_us: Option<u64>,
    /// Test only: seed of `--delay-us`.
    #[arg(long, value_name = "SEED", hide = true, default_value_t = 1)]
    pub delay_seed: u64,
}

/// Most drives `serve --slaves` takes ([`hil_sim::sim::MAX_DRIVES`]).
pub const MAX_SLAVES: u16 = hil_sim::sim::MAX_DRIVES as u16;

/// The default plot path of `demo`.
pub const DEFAULT_PLOT: &str = "target/hil-sim-demo.svg";
/// The default plot path of `demo --fieldbus profinet`.
pub const DEFAULT_PLOT_PN: &str = "target/hil-sim-demo-pn.svg";

/// Creates (truncates) an output file before the run, so a path that cannot
/// be written fails at once with a message naming it. `what` names the file
/// in the message ("plot", "pcap file").
pub fn create_output(path: &Path, what: &str) -> Result<File, String> {
    File::create(path).map_err(|e| format!("cannot write the {what} {}: {e}", path.display()))
}

/// The plot's path: `given` (`--plot`), else `default` in cargo's target
/// directory, which is made if missing.
pub fn plot_path_or(given: &Option<PathBuf>, default: &str) -> Result<PathBuf, String> {
    if let Some(p) = given {
        return Ok(p.clone());
    }
    let p = PathBuf::from(default);
    if let Some(dir) = p.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}
