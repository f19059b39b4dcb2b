//! `hil-sim demo`: a real EtherCAT master (ethercrab, in-process, simulated
//! time) brings one simulated drive to OP, enables axis A in csp, homes it on
//! its reference switch, runs a csp profile and writes a plot of the run.

use super::args::{create_output, plot_path_or, DemoArgs, Plant, DEFAULT_PLOT};
use super::print_new_changes;
use hil_sim::motor::PositionInput;
use hil_sim::sim::Simulation;
use nanos::Nanos;
use std::cell::RefCell;
use std::sync::atomic::Ordering;

/// Position of axis A's reference switch, increments (a quarter revolution).
const REFERENCE_SWITCH_INC: i64 = 1 << 18;
/// Master cycle of the demo (DC-style: one frame per cycle, clock advanced by it).
const MASTER_CYCLE: Nanos = Nanos::from_ms(1);
/// Increments per revolution.
const INC_PER_REV: f64 = 1_048_576.0;

type Group<'a> = ethercrab::SubDeviceGroup<4, 256, ethercrab::DefaultLock, ethercrab::subdevice_group::Op>;

/// Axis A's RxPDO (standard map): controlword @0, mode @2, target position @3.
fn write_outputs(
    group: &Group<'_>,
    md: &ethercrab::MainDevice<'_>,
    cw: u16,
    mode: i8,
    target: i32,
) -> Result<(), String> {
    let sd = group.subdevice(md, 0).map_err(|e| e.to_string())?;
    let mut o = sd.outputs_raw_mut();
    let out = o.get_mut(..7).ok_or("RxPDO shorter than 7 bytes")?;
    out[0..2].copy_from_slice(&cw.to_le_bytes());
    out[2] = mode as u8;
    out[3..7].copy_from_slice(&target.to_le_bytes());
    Ok(())
}

/// Axis A's TxPDO (standard map): statusword, mode display, position,
/// velocity, torque (0.1 %), following error.
#[derive(Debug, Clone, Copy, Default)]
struct Inputs {
    sw: u16,
    mode: i8,
    pos: i32,
    vel: i32,
    torque: i16,
    ferr: i32,
}

fn read_inputs(group: &Group<'_>, md: &ethercrab::MainDevice<'_>) -> Result<Inputs, String> {
    let sd = group.subdevice(md, 0).map_err(|e| e.to_string())?;
    let i = sd.inputs_raw();
    let b = i.get(..17).ok_or("TxPDO shorter than 17 bytes")?;
    let i32_at = |k: usize| i32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
    Ok(Inputs {
        sw: u16::from_le_bytes([b[0], b[1]]),
        mode: b[2] as i8,
        pos: i32_at(3),
        vel: i32_at(7),
        torque: i16::from_le_bytes([b[11], b[12]]),
        ferr: i32_at(13),
    })
}

/// Where in the drive's control cycle the master's frame arrives (a DC shift:
/// the frame lands mid-cycle, never on a cycle boundary).
const FRAME_PHASE: Nanos = Nanos::from_us(500);

/// One master cycle, DC-style: the clock advances to the next cycle start
/// (multiples of the master cycle plus a fixed phase, so master and drive
/// cycles never slip against each other), then one frame.
async fn cycle(
    group: &Group<'_>,
    md: &ethercrab::MainDevice<'_>,
    sim: &RefCell<Simulation>,
) -> Result<Inputs, String> {
    let now = sim.borrow().now();
    let k = now
        .saturating_sub(FRAME_PHASE)
        .checked_div_span(MASTER_CYCLE)
        .unwrap_or(0);
    let t = (k + 1) * MASTER_CYCLE + FRAME_PHASE;
    sim.borrow_mut().advance_to(t);
    group.tx_rx(md).await.map_err(|e| format!("cycle: {e}"))?;
    read_inputs(group, md)
}

/// The CiA 402 state name of a statusword, "?" for none.
fn state_name(sw: u16) -> &'static str {
    cia402::State::from_statusword(sw).map_or("?", cia402::State::name)
}

/// Runs master cycles with `cw` until `done(inputs)` or `max` cycles.
async fn until(
    group: &Group<'_>,
    md: &ethercrab::MainDevice<'_>,
    sim: &RefCell<Simulation>,
    (cw, mode, target): (u16, i8, i32),
    max: usize,
    done: impl Fn(&Inputs) -> bool,
) -> Result<Inputs, String> {
    for _ in 0..max {
        write_outputs(group, md, cw, mode, target)?;
        let i = cycle(group, md, sim).await?;
        if done(&i) {
            return Ok(i);
        }
    }
    Err(format!("controlword {cw:#06x}: no progress after {max} cycles"))
}

/// Enable in csp, home on the reference switch, run a csp profile from the master.
async fn motion_demo(
    md: &ethercrab::MainDevice<'_>,
    group: &Group<'_>,
    sim: &RefCell<Simulation>,
    printed: &mut Vec<usize>,
) -> Result<hil_sim::plot::Trace, String> {
    print_new_changes(&sim.borrow(), printed);
    let mut i = cycle(group, md, sim).await?;
    println!("  axis A: {} (statusword {:#06x})", state_name(i.sw), i.sw);
    // enable: Shutdown, Switch on, Enable operation, holding the actual position
    for (cw, want) in [(0x06u16, 0x21u16), (0x07, 0x23), (0x0F, 0x27)] {
        let hold = i.pos;
        i = until(group, md, sim, (cw, 8, hold), 200, |i| i.sw & 0x6F == want).await?;
        println!("  axis A: {} (statusword {:#06x})", state_name(i.sw), i.sw);
    }
    // homing on the reference switch (method 19: positive reference switch, falling edge)
    let sd = group.subdevice(md, 0).map_err(|e| e.to_string())?;
    let sdo = |e: ethercrab::error::Error| format!("SDO: {e}");
    sd.sdo_write(0x6098, 0, 19i8).await.map_err(sdo)?;
    sd.sdo_write(0x6099, 1, 2_000_000u32).await.map_err(sdo)?; // search for switch, inc/s
    sd.sdo_write(0x6099, 2, 200_000u32).await.map_err(sdo)?; // search for zero, inc/s
    sd.sdo_write(0x609A, 0, 20_000_000u32).await.map_err(sdo)?; // inc/s²
    until(group, md, sim, (0x0F, 6, i.pos), 50, |i| i.mode == 6).await?;
    i = until(group, md, sim, (0x1F, 6, i.pos), 10_000, |i| {
        i.sw & 0x3400 == 0x1400 || i.sw & 0x2000 != 0
    })
    .await?;
    if i.sw & 0x2000 != 0 {
        return Err(format!("homing error, statusword {:#06x}", i.sw));
    }
    println!(
        "  homing method 19 on the reference switch at {:.3} rev: attained, position now {} inc",
        REFERENCE_SWITCH_INC as f64 / INC_PER_REV,
        i.pos
    );
    // back to csp, holding the actual position
    let hold = i.pos;
    i = until(group, md, sim, (0x0F, 8, hold), 50, |i| i.mode == 8).await?;
    // the profile: 10 revolutions out and back, cosine S-curves of 1.5 s each
    let (p0, dist, t_move) = (i.pos, 10.0 * INC_PER_REV, 1500usize);
    let total = hil_sim::sim::profile::cycles(t_move);
    let bar = indicatif::ProgressBar::new(total as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("  csp profile [{bar:40}] {pos}/{len} cycles")
            .map_err(|e| e.to_string())?,
    );
    let mut trace = hil_sim::plot::Trace::default();
    for k in 0..total {
        let x = hil_sim::sim::profile::fraction(k, t_move);
        let target = p0.wrapping_add((x * dist).round() as i32);
        write_outputs(group, md, 0x0F, 8, target)?;
        i = cycle(group, md, sim).await?;
        trace.push(sim.borrow().now(), target, i.pos, i.vel, i.torque, i.ferr);
        if let Some(e) = sim.borrow_mut().drives_mut()[0].electrical(0) {
            let c = e.last();
            trace.push_currents(c.id_a, c.iq_a, c.iq_ref_a, c.phases_a);
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    // settled: where the axis stands against its final target (the start)
    for _ in 0..100 {
        write_outputs(group, md, 0x0F, 8, p0)?;
        i = cycle(group, md, sim).await?;
    }
    println!(
        "  at rest after the profile: position {} inc, target {p0} inc (error {} inc)",
        i.pos,
        i.pos.wrapping_sub(p0)
    );
    // Disable operation, then Shutdown
    until(group, md, sim, (0x06, 8, i.pos), 200, |i| i.sw & 0x6F == 0x21).await?;
    println!("  axis A: Ready to switch on again");
    Ok(trace)
}

/// Seed of the electrical plant's ADC noise.
const PLANT_SEED: u64 = 0x5eed_f0c0_0000_0034;

/// The current loop's figures over the whole run (axis A, gates on).
fn print_current_figures(e: &hil_sim::electrical::ElectricalAxis) {
    let s = e.stats();
    let kt = e.foc().gains().kt_nm_per_a;
    println!(
        "  current loop (axis A, {} PWM periods with the gates on): iq rms {:.3} A, max |iq| {:.3} A ({:.2} N·m at kt {kt:.3} N·m/A), max |id| {:.3} A measured, {:.3} A in the motor; voltage-limited in {} periods",
        s.enabled_periods,
        s.iq_mean_square().sqrt(),
        s.iq_max_abs,
        s.iq_max_abs * f64::from(kt),
        s.id_max_abs,
        s.id_true_max_abs,
        s.voltage_limited_periods,
    );
}

/// Runs the demo. Both output files are created before the run: a path that
/// cannot be written fails at once, never after the run claiming a file.
pub fn demo(args: &DemoArgs) -> Result<(), String> {
    if args.profinet_only() {
        return Err(
            "--self-tune, --plant-j-factor and --plant-friction-factor are PROFINET-only (--fieldbus profinet; \
             on EtherCAT: cargo bench -p hil-sim --bench selftune)"
                .into(),
        );
    }
    let sim = RefCell::new(Simulation::new(1));
    if let Some(p) = &args.pcap {
        sim.borrow_mut()
            .record_pcap(p)
            .map_err(|e| format!("cannot write the pcap file {}: {e}", p.display()))?;
        println!("recording frames to {}", p.display());
    }
    let plot_path = plot_path_or(&args.plot, DEFAULT_PLOT)?;
    let mut plot_file = Some(create_output(&plot_path, "plot")?);
    {
        // the reference switch of axis A, a quarter revolution out
        let mut s = sim.borrow_mut();
        s.drives_mut()[0].motors[0].switches_mut().reference = PositionInput::above(REFERENCE_SWITCH_INC);
        s.drives_mut()[0]
            .set_plant(args.plant().into(), PLANT_SEED)
            .map_err(|e| format!("the electrical plant's parameters: {e:?}"))?;
    }
    println!(
        "hil-sim demo: ethercrab (in-process) -> simulated ESC -> drive firmware -> {}",
        match args.plant() {
            Plant::Rigid => "simulated motor (rigid, torque in)",
            Plant::Electrical => "current loop (16 kHz) -> simulated PMSM and inverter",
        }
    );
    let mut printed = Vec::new();
    let result = hil_sim::master::run(&sim, hil_sim::master::in_process_timeouts(), async |md, clock| {
        let group = md
            .init_single_group::<4, 256>(|| clock.load(Ordering::Relaxed))
            .await
            .map_err(|e| format!("init: {e}"))?;
        println!("found {} slave(s)", group.len());
        for sd in group.iter(md) {
            let id = sd.identity();
            println!(
                "  {:#06x} \"{}\": vendor {:#010x}, product {:#010x}, revision {:#010x}, serial {:#010x}",
                sd.configured_address(),
                sd.name(),
                id.vendor_id,
                id.product_id,
                id.revision,
                id.serial
            );
        }
        print_new_changes(&sim.borrow(), &mut printed);
        let group = group
            .into_op(md)
            .await
            .map_err(|e| format!("PRE-OP -> OP: {e}"))?;
        print_new_changes(&sim.borrow(), &mut printed);
        for sd in group.iter(md) {
            let io = sd.io_raw();
            println!(
                "  process data: {} input bytes, {} output bytes",
                io.inputs().len(),
                io.outputs().len()
            );
        }
        let trace = motion_demo(md, &group, &sim, &mut printed).await?;
        let (max, rms) = trace.following_error_stats();
        println!(
            "  csp profile: {} cycles, following error max {max:.0} inc ({:.3}°), rms {rms:.1} inc",
            trace.len(),
            max / 1_048_576.0 * 360.0
        );
        if let Some(e) = sim.borrow().drives()[0].electrical(0) {
            print_current_figures(e);
        }
        if let Some(mut f) = plot_file.take() {
            if let Err(e) = trace.write_svg(&mut f, "hil-sim demo: csp profile from the master, axis A") {
                drop(f);
                let _ = std::fs::remove_file(&plot_path);
                return Err(format!("cannot write the plot {}: {e}", plot_path.display()));
            }
        }
        println!("  plot: {}", plot_path.display());
        let group = group
            .into_safe_op(md)
            .await
            .map_err(|e| format!("OP -> SAFE-OP: {e}"))?;
        let group = group
            .into_pre_op(md)
            .await
            .map_err(|e| format!("SAFE-OP -> PRE-OP: {e}"))?;
        let _group = group
            .into_init(md)
            .await
            .map_err(|e| format!("PRE-OP -> INIT: {e}"))?;
        print_new_changes(&sim.borrow(), &mut printed);
        Ok::<(), String>(())
    });
    if plot_file.is_some() {
        // the run failed before the plot: leave no empty file behind
        let _ = std::fs::remove_file(&plot_path);
    }
    let mut s = sim.borrow_mut();
    if let Some(p) = &args.pcap {
        s.flush()
            .map_err(|e| format!("the pcap file {} is incomplete: {e}", p.display()))?;
    }
    println!(
        "{} frames in {:.3} ms of simulated time",
        s.frames(),
        s.now().as_ns() as f64 / 1e6
    );
    result
}
