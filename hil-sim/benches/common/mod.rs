//! What the `control` and `plant` benches share: how both axes are enabled
//! and driven along the demo's csp profile ([`hil_sim::sim::profile`]) through
//! the dictionary, as a decoded RxPDO would write the set-points.

use hil_sim::sim::SimFlash;

/// The drive runtime on the simulated flash.
pub type SimDrive = drive_ecat::runtime::Drive<SimFlash>;

/// Increments per revolution.
pub const INC_PER_REV: f64 = 1_048_576.0;

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
    let total = hil_sim::sim::profile::cycles(t_move);
    let (mut max, mut sq) = (0.0f64, 0.0f64);
    for k in 0..total {
        let target = (hil_sim::sim::profile::fraction(k, t_move) * 10.0 * INC_PER_REV).round() as i64;
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
