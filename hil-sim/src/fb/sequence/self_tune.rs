//! The sequence's self-tuning phase (issue 35, `demo --fieldbus profinet
//! --self-tune`): B44 identify mechanics started and read the way a PLC
//! program does it, through the telegram's PKW channel (PNU = the object's
//! index; spec §9.8, E-140/E-141 on PROFINET):
//!
//! 1. the FB's `drive_enable` 0 and the program's CW1 OFF (0x0436): ZSW1
//!    ready to switch on (E48 = 2, B44's precondition);
//! 2. (with [`super::Options::bandwidth_hz`] first B48, the bandwidth the
//!    gains are chosen for;) PKW write A75 = Execute | 1111b << 1 (1Fh); A69 read: running;
//! 3. `drive_enable` 1: the FB's enable sequence, after which the drive
//!    runs its test move (12 rev forward, 1 back, and back to its start);
//! 4. A69 read every 50 ms until it leaves running; B44\[0\] (the result),
//!    B45 J, B46 Fc, B47 B and the gains it set, C31 Kp, C32 Ti, I20 Kv;
//! 5. PKW write A75 = 0 (Execute low): A69 idle; the axis is the FB's
//!    again, enabled.

use super::{Observer, Phase, Run, SelfTuneResult};
use crate::fb::pkw::{Access, Outcome};
use drive_ecat::actions::{A69, A75};
use drive_ecat::params::{B44, B45, B46, B47, B48, C31, C32, I20};

/// B44's selector (1111b) with Execute (bit 0).
pub const B44_EXECUTE: u32 = 0b1111 << 1 | 1;
/// A69's state field (bits 12…15): running, done.
const RUNNING: u32 = 1;
const DONE: u32 = 2;
/// How long the phase waits for B44 to end, ms (it takes about 5 s).
const B44_TIMEOUT_MS: u64 = 30_000;

impl<O: Observer> Run<'_, O> {
    /// A PKW read whose refusal is a deviation; the value, 0 if refused.
    fn pkw_value(&mut self, label: &str, index: u16, sub: u8) -> Result<u32, String> {
        Ok(match self.pkw_access(label, Access::Read { index, sub })? {
            Outcome::Done(v) => v,
            Outcome::Refused(e) => {
                self.deviation(format!(
                    "E-140: PKW read {index:04X}h.{sub} refused, error {e:#x}"
                ));
                0
            }
        })
    }

    /// A69 read through PKW (not recorded in the report's PKW list: the
    /// phase polls it).
    fn a69(&mut self) -> Result<u32, String> {
        self.pkw.start(Access::Read { index: A69, sub: 0 });
        for _ in 0..200 {
            self.cycle()?;
            if let Some(r) = self.pkw.take_result() {
                return Ok(match r {
                    Outcome::Done(v) => v,
                    Outcome::Refused(_) => u32::MAX,
                });
            }
        }
        Err("PKW read A69: no answer within 200 ms".into())
    }

    pub(super) fn self_tune(&mut self) -> Result<(), String> {
        self.begin(Phase::SelfTune);
        self.in_self_tune = true;
        self.i.drive_enable = false;
        self.hold_ready = true;
        self.line("drive_enable 0, CW1 OFF: B44 starts in ready to switch on (E-141)");
        let rtso = self.until(500, |o| o.zsw1 & 0x47 == 0x01)?;
        if !rtso {
            self.deviation("P-219: CW1 OFF did not bring ready to switch on within 500 ms".into());
        }
        if let Some(hz) = self.bandwidth_hz {
            self.pkw_access(
                "write B48 (speed loop bandwidth, Hz)",
                Access::Write {
                    index: B48,
                    sub: 0,
                    value: u32::from(hz),
                },
            )?;
        }
        let w = self.pkw_access(
            "write A75 = 1Fh (B44 identify mechanics, Execute)",
            Access::Write {
                index: A75,
                sub: 0,
                value: B44_EXECUTE,
            },
        )?;
        let started = self.a69()?;
        self.line(&format!("A69 {started:#06x}"));
        self.hold_ready = false;
        self.i.drive_enable = true;
        if !matches!(w, Outcome::Done(_)) || started >> 12 != RUNNING {
            self.deviation(format!(
                "E-140: B44 did not start through PKW: A69 {started:#06x}"
            ));
        }
        if !self.until(500, |o| o.drive_is_enabled)? {
            self.deviation("P-219: drive_is_enabled did not come for B44".into());
        }
        let t0 = self.ctl.now();
        let mut a69 = started;
        while a69 >> 12 == RUNNING && (self.ctl.now() - t0).as_ns() < B44_TIMEOUT_MS * 1_000_000 {
            self.wait_ms(50)?;
            a69 = self.a69()?;
        }
        let ms = (self.ctl.now() - t0).as_ns() / 1_000_000;
        self.line(&format!("A69 {a69:#06x} after {ms} ms"));
        let result = SelfTuneResult {
            a69,
            code: self.pkw_value("read B44[0] (result)", B44, 1)?,
            inertia: self.pkw_value("read B45 (J, 1e-7 kg m^2)", B45, 0)?,
            coulomb: self.pkw_value("read B46 (Fc, uN m)", B46, 0)?,
            viscous: self.pkw_value("read B47 (B, nN m s/rad)", B47, 0)?,
            gains: [
                self.pkw_value("read C31 (Kp, uN m s/rad)", C31, 0)?,
                self.pkw_value("read C32 (Ti, us)", C32, 0)?,
                self.pkw_value("read I20 (Kv, 0.1/s)", I20, 0)?,
            ],
            ms,
        };
        if a69 >> 12 != DONE || result.code != 0 {
            self.deviation(format!(
                "E-140: B44 did not end done: A69 {a69:#06x}, B44[0] {}",
                result.code
            ));
        }
        self.pkw_access(
            "write A75 = 0 (Execute low)",
            Access::Write {
                index: A75,
                sub: 0,
                value: 0,
            },
        )?;
        let idle = self.a69()?;
        if idle != 0 {
            self.deviation(format!("E-140: A69 {idle:#06x} after Execute low, not idle"));
        }
        self.in_self_tune = false;
        self.report.self_tune = Some(result);
        let summary = format!(
            "B44 {} in {ms} ms: J {:.4e} kg m^2, Fc {:.4} N m, B {:.3e} N m s/rad",
            if result.code == 0 { "done" } else { "failed" },
            f64::from(result.inertia) * 1e-7,
            f64::from(result.coulomb) * 1e-6,
            f64::from(result.viscous) * 1e-9
        );
        self.end(Phase::SelfTune, summary);
        Ok(())
    }
}
