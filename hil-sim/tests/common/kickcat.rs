//! KickCAT's line script (`hil-sim/tests/soem/kickcat_line.py`) on a line
//! of two drives: its arguments and the figures behind them, for the
//! KickCAT test (`tests/kickcat.rs`) and the start-up phase of the
//! `serve_rtt` bench.

/// Increments per revolution of the drive's position (6064h, 607Ah) with
/// the default scaling (`hil-sim/tests/soem/line.py` moves by the same).
pub const INC_PER_REV: u32 = 1 << 20;

/// I423 as KickCAT sets it by SDO before Op: the longest the drive
/// extrapolates a missing csp set-point (C-117). The default 10 ms is shorter
/// than the stalls of a Python master on a loaded machine (gaps of 20 to
/// 170 ms seen with a load of 12 on 2 cores: the drive faulted, rightly),
/// so the master sets what its own jitter needs.
pub const I423_MS: u16 = 500;

/// How far 6064h may be from the csp set-point sent in the same cycle during
/// the move (1/16 rev): the position loop's lag at the move's 0.79 rev/s and
/// the set-point's advance over one cycle of the master (the inputs of a
/// frame are read as its outputs are written). The script adds twice what
/// the drive's linear extrapolation (C-116) over the longest gap between the
/// master's cycles (g) misses of the curve, a/2 · g² with the curve's
/// largest acceleration a = π²/(2 T²) rev/s² (T = 2 s: 1/160 rev for
/// g = 100 ms).
pub const TOLERANCE_INC: u32 = INC_PER_REV / 16;

/// How far 6064h may end from the target once the move is over: the
/// drive's default position window I22 (1/360 rev, the window of "target
/// reached"), as `tests/tests/motion/drive_modes.rs` checks. At rest the axis hunts: the
/// velocity PI's integral part winds the torque up at a following error
/// until it passes the motor's breakaway friction (0.03 N·m), the rotor
/// slides against the lower Coulomb friction (0.02 N·m) past the target and
/// sticks on the other side, a stick-slip limit cycle whose steps scale as
/// (0.03 − 0.02) N·m over the cascade's stiffness Kp·Kv at the 1 ms cycle
/// (0.015 N·m·s/rad × 50 /s: 13 mrad, 2200 inc). `demo`'s 1 ms csp held 4 s
/// at its target sticks at +73, −1220, +441, −954, +608 inc on the rigid
/// model and at +76, −619, +391, −577, +472 inc on the electrical one. The
/// rigid model's run here ends 4 inc from the target only because it is
/// free of noise: it sticks that close after the move, and at 4 inc the
/// integral needs tens of seconds to break the rotor away; with the current
/// loop's ADC noise it sticks a few hundred inc off and hunts within the 8 s
/// (+472/−450, −613/+430 inc seen). 200 inc held only for that lucky run.
pub const END_TOLERANCE_INC: u32 = INC_PER_REV / 360;

/// `kickcat_line.py`'s arguments for a line of 2 drives run `seconds` long:
/// the names of 1018h and 6040h the script expects from SDO Info, I423 (at
/// [`I423_MS`]) that it raises by SDO, the csp move's [`TOLERANCE_INC`] and
/// [`END_TOLERANCE_INC`]; then `more`.
pub fn line_args(seconds: &str, more: &[&str]) -> Vec<String> {
    let od = drive_ecat::DriveObjects::default();
    let name = |index: u16| {
        use ecat::Dictionary;
        od.object(index).expect("declared").name.to_string()
    };
    let mut args: Vec<String> = [
        "--slaves".to_string(),
        "2".to_string(),
        "--seconds".to_string(),
        seconds.to_string(),
        "--name-1018".to_string(),
        name(0x1018),
        "--name-6040".to_string(),
        name(0x6040),
        "--i423-index".to_string(),
        format!("{:#06x}", drive_ecat::params::I423),
        "--i423-ms".to_string(),
        I423_MS.to_string(),
        "--tolerance".to_string(),
        TOLERANCE_INC.to_string(),
        "--end-tolerance".to_string(),
        END_TOLERANCE_INC.to_string(),
    ]
    .into();
    args.extend(more.iter().map(|a| a.to_string()));
    args
}
