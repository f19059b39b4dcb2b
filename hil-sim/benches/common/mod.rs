//! What the `control` and `plant` benches share: the demo's csp profile and
//! how both axes are enabled and driven along it through the dictionary, as
//! a decoded RxPDO would write the set-points.

use hil_sim::sim::SimFlash;

/// The drive runtime on the simulated flash.
pub type SimDrive = drive_ecat::runtime::Drive<SimFlash>;

/// Increments per revolution.
pub const INC_PER_REV: f64 = 1_048_576.0;

/// The demo's profile: 10 revolutions out and back, cosine S-curves of
/// `t_move` cycles each, 150 cycles dwell between and after.
fn profile(k: usize, t_move: usize) -> f64 {
    let phase = |k: usize| (1.0 - (std::f64::consts::PI * k as f64 / t_move as f64).cos()) / 2.0;
    let x = if k < t_move {
        phase(k)
    } else if k < t_move + 150 {
        1.0
    } else if k < 2 * t_move + 150 {
        1.0 - phase(k - t_move - 150)
    } else {
        0.0
    };
    x * 10.0 * INC_PER_REV
}

/// Enables both axes in csp (mode 8 is the default) holding position 0:
/// each controlword for five cycles of `step`.
pub fn enable_csp(drive: &mut SimDrive, mut step: impl FnMut(&mut SimDrive)) {
    for cw in [0x06, 0x07, 0x0F, 0x0F, 0x0F] {
        for axis in 0..2u16 {
            drive.objects_mut().set(0x6040 + 0x800 * axis, 0, cw).unwrap();
            drive.objects_mut().set(0x607A + 0x800 * axis, 0, 0).unwrap();
        }
        for _ in 0..5 {
            step(drive);
        }
    }
}

/// Both axes along the profile with moves of `t_move` cycles, one `step` a
/// cycle; the following error of axis 0 (60F4h): its largest magnitude,
/// its sum of squares, and the number of cycles.
pub fn follow_profile(
    drive: &mut SimDrive,
    t_move: usize,
    mut step: impl FnMut(&mut SimDrive),
) -> (f64, f64, usize) {
    let total = 2 * t_move + 300;
    let (mut max, mut sq) = (0.0f64, 0.0f64);
    for k in 0..total {
        let target = profile(k, t_move).round() as i64;
        for axis in 0..2u16 {
            drive.objects_mut().set(0x607A + 0x800 * axis, 0, target).unwrap();
        }
        step(drive);
        let ferr = drive.objects().get(0x60F4, 0).unwrap() as f64;
        max = max.max(ferr.abs());
        sq += ferr * ferr;
    }
    (max, sq, total)
}
